#include "core/landmarks/landmark_labels.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

namespace mmm::landmarks {

namespace {

// The side words a label of `side` may carry before or after its stem.
std::vector<std::string> side_words(const std::string& side) {
  if (side == "right") return {"r", "right", "rt"};
  if (side == "left") return {"l", "left", "lt"};
  return {};
}

std::vector<LandmarkLabels> make_table() {
  return {
      {"femoral_head_centre_r",
       "Femoral head centre: the centre of the sphere that best fits the articular surface of the "
       "right femoral head, the hip joint's centre of rotation.",
       "right",
       {"Femoral Head", "Femoral Head Centre", "Hip Centre", "Hip Joint Centre", "HJC", "FHC",
        "Hip"}},
      {"patella_centre_r",
       "Patella centre: the centroid of the right patella, midway between its base and apex and "
       "between its medial and lateral borders.",
       "right",
       {"Patella", "Patella Centre", "Patellar Centre", "PAT"}},
      {"ankle_centre_r",
       "Ankle centre: the centre of the right talocrural joint, on the axis of the talar dome "
       "midway between the tips of the medial and lateral malleoli.",
       "right",
       {"Ankle", "Ankle Centre", "Ankle Joint Centre", "AJC"}},
      {"knee_centre_r",
       "Knee centre: the centre of the right tibiofemoral joint, on the flexion axis midway "
       "between the femoral epicondyles.",
       "right",
       {"Knee", "Knee Centre", "Knee Joint Centre", "KJC"}},
      {"acetabulum_centre_r",
       "Acetabulum centre: the centre of the sphere that best fits the articular (lunate) surface "
       "of the right acetabulum.",
       "right",
       {"Acetabulum", "Acetabulum Centre", "Acetabular Centre"}},
      {"asis_r",
       "Right anterior superior iliac spine (ASIS): the most anterior point of the anterior end "
       "of the right iliac crest, palpable at the front of the hip.",
       "right",
       {"ASIS", "Anterior Superior Iliac Spine"}},
      {"asis_l",
       "Left anterior superior iliac spine (ASIS): the most anterior point of the anterior end of "
       "the left iliac crest, palpable at the front of the hip.",
       "left",
       {"ASIS", "Anterior Superior Iliac Spine"}},
      {"sacral_point",
       "Sacral point: the posterior surface of the sacrum in the midline, midway between the two "
       "posterior superior iliac spines (PSIS), at about the second sacral segment.",
       "",
       {"Sacrum", "Sacral", "V Sacral", "Sacral Point", "Mid PSIS", "PSIS Midpoint"}},
      {"lateral_epicondyle_r",
       "Lateral femoral epicondyle: the most prominent point of the lateral condyle's outer "
       "surface, where the lateral collateral ligament attaches; palpable on the outside of the "
       "knee.",
       "right",
       {"Lateral Epicondyle", "Lateral Femoral Epicondyle", "Lat Epicondyle", "LE", "LFE",
        "Knee Lat", "Lateral Knee"}},
      {"medial_epicondyle_r",
       "Medial femoral epicondyle: the most prominent point of the medial condyle's inner "
       "surface, below the adductor tubercle, where the medial collateral ligament attaches; "
       "palpable on the inside of the knee.",
       "right",
       {"Medial Epicondyle", "Medial Femoral Epicondyle", "Med Epicondyle", "ME", "MFE", "Knee Med",
        "Medial Knee"}},
      {"lateral_malleolus_r",
       "Lateral malleolus: the most lateral point of the distal fibula's malleolus, on the "
       "outside of the ankle.",
       "right",
       {"Lateral Malleolus", "Lat Malleolus", "LM", "Ankle Lat", "Lateral Ankle"}},
      {"medial_malleolus_r",
       "Medial malleolus: the most medial point of the distal tibia's malleolus, on the inside of "
       "the ankle.",
       "right",
       {"Medial Malleolus", "Med Malleolus", "MM", "Ankle Med", "Medial Ankle"}},
      {"heel_r",
       "Heel: the most posterior point of the calcaneal tuberosity, at the height of the Achilles "
       "tendon's insertion.",
       "right",
       {"Heel", "Calcaneus", "Calcaneal Tuberosity", "Posterior Calcaneus", "CAL", "HEE"}},
  };
}

const std::vector<LandmarkLabels>& table() {
  static const std::vector<LandmarkLabels> entries = make_table();
  return entries;
}

// Normalised label -> atlas name, over the whole table.
const std::map<std::string, std::string>& label_index() {
  static const std::map<std::string, std::string> index = [] {
    std::map<std::string, std::string> out;
    for (const LandmarkLabels& entry : table()) {
      for (const std::string& label : normalised_labels(entry)) out.emplace(label, entry.name);
    }
    return out;
  }();
  return index;
}

}  // namespace

std::span<const LandmarkLabels> landmark_label_table() { return table(); }

const LandmarkLabels* find_landmark_labels(std::string_view name) {
  const auto it = std::ranges::find(table(), name, &LandmarkLabels::name);
  return it == table().end() ? nullptr : &*it;
}

std::string landmark_definition(std::string_view name) {
  if (const LandmarkLabels* entry = find_landmark_labels(name)) return entry->definition;
  // A left-leg landmark: its right twin's definition, mirrored in words.
  if (name.ends_with("_l")) {
    const std::string twin = std::string(name.substr(0, name.size() - 2)) + "_r";
    if (const LandmarkLabels* entry = find_landmark_labels(twin)) {
      std::string text = entry->definition;
      for (std::size_t at = text.find("right"); at != std::string::npos;
           at = text.find("right", at + 4)) {
        text.replace(at, 5, "left");
      }
      return text;
    }
  }
  return {};
}

std::string normalise_label(std::string_view label) {
  std::string out;
  for (const char c : label) {
    if (c == ' ' || c == '-' || c == '_' || c == '.' || c == '\t') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  for (std::size_t at = out.find("center"); at != std::string::npos; at = out.find("center")) {
    out.replace(at, 6, "centre");
  }
  return out;
}

std::vector<std::string> normalised_labels(const LandmarkLabels& entry) {
  std::set<std::string> out = {normalise_label(entry.name)};
  const std::vector<std::string> sides = side_words(entry.side);
  for (const std::string& label : entry.labels) {
    const std::string stem = normalise_label(label);
    // Side-less leg labels mean the right leg; the ASIS need their side.
    const bool sideless_ok =
        entry.side.empty() || (entry.side == "right" && entry.name != "asis_r");
    if (sideless_ok) out.insert(stem);
    for (const std::string& side : sides) {
      out.insert(side + stem);
      out.insert(stem + side);
    }
  }
  return {out.begin(), out.end()};
}

std::string landmark_for_label(std::string_view label) {
  const std::string key = normalise_label(label);
  if (key.empty()) return {};
  const auto it = label_index().find(key);
  return it == label_index().end() ? std::string() : it->second;
}

std::string landmark_label_table_text() {
  std::string out;
  for (const LandmarkLabels& entry : table()) {
    std::string examples;
    const std::string side = entry.side == "right" ? "R" : entry.side == "left" ? "L" : "";
    for (const std::string& label : entry.labels) {
      if (!examples.empty()) examples += ", ";
      if (!side.empty()) examples.append(side).append(" ");
      examples += label;
    }
    out += "  " + entry.name + " (" + examples + "): " + entry.definition + "\n";
  }
  return out;
}

}  // namespace mmm::landmarks
