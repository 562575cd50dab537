#include "core/image/outline_corrections.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <tuple>
#include <utility>

#include "core/bounded_json.h"
#include "core/errors.h"

namespace mmm::image {
namespace {

constexpr const char* kCorrectionsFormat = "mmm-outline-corrections";
constexpr int kCorrectionsVersion = 1;

std::string short_json(const nlohmann::json& value) {
  std::string text = value.dump();
  constexpr std::size_t kMax = 60;
  if (text.size() > kMax) text = text.substr(0, kMax) + "...";
  return text;
}

bool is_artifact_hash(const std::string& text) {
  return text.size() == 64 && std::ranges::all_of(text, [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

// Reads the JSON of the file comment; every failure names the field.
class CorrectionsReader {
 public:
  explicit CorrectionsReader(std::string_view source) : source_(source) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw InvalidInputError(source_ + ": " + (where.empty() ? "" : where + ": ") + problem);
  }

  void only_fields(const nlohmann::json& object, const std::string& where,
                   std::initializer_list<const char*> known) const {
    for (auto it = object.begin(); it != object.end(); ++it) {
      const std::string& key = it.key();
      if (std::ranges::none_of(known, [&](const char* name) { return key == name; })) {
        std::string problem = "unknown field '" + key + "'; hint: the fields are ";
        for (const char* name : known) {
          if (problem.back() != ' ') problem += ", ";
          problem += name;
        }
        fail(where, problem);
      }
    }
  }

  const nlohmann::json& field(const nlohmann::json& object, const std::string& where,
                              const char* key) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(where, std::string("field '") + key + "' is missing");
    return *it;
  }

  std::string text(const nlohmann::json& object, const std::string& where, const char* key) const {
    const nlohmann::json& value = field(object, where, key);
    if (!value.is_string() || value.get<std::string>().empty()) {
      fail(where,
           std::string("field '") + key + "' must be a non-empty string, got " + short_json(value));
    }
    return value.get<std::string>();
  }

  std::string hash(const nlohmann::json& object, const char* key) const {
    std::string value = text(object, "", key);
    if (!is_artifact_hash(value)) {
      fail(key, "must be an artifact hash (64 lowercase hex digits), got '" + value + "'");
    }
    return value;
  }

  OutlineCorrection correction(const nlohmann::json& entry, const std::string& where) const {
    if (!entry.is_object()) fail(where, "must be an object {bone, view, points_px}");
    only_fields(entry, where, {"bone", "view", "points_px"});
    OutlineCorrection out;
    out.bone = text(entry, where, "bone");
    out.view = text(entry, where, "view");
    const nlohmann::json& points = field(entry, where, "points_px");
    if (!points.is_array() || points.empty()) {
      fail(where + ".points_px", "must be a non-empty list of [u, v] pixel positions");
    }
    if (points.size() > kMaxPointsPerCorrection) {
      fail(where + ".points_px", "holds " + std::to_string(points.size()) + " points, at most " +
                                     std::to_string(kMaxPointsPerCorrection) + " are allowed");
    }
    for (std::size_t k = 0; k < points.size(); ++k) {
      const nlohmann::json& uv = points[k];
      const bool pair = uv.is_array() && uv.size() == 2 && uv[0].is_number() && uv[1].is_number();
      const Eigen::Vector2d p = pair ? Eigen::Vector2d(uv[0].get<double>(), uv[1].get<double>())
                                     : Eigen::Vector2d::Zero();
      if (!pair || !p.allFinite()) {
        fail(where + ".points_px[" + std::to_string(k) + "]",
             "must be [u, v], two finite numbers (pixels), got " + short_json(uv));
      }
      out.points_px.push_back(p);
    }
    return out;
  }

  OutlineCorrections corrections(const nlohmann::json& root) const {
    if (!root.is_object()) fail("", "must be a JSON object");
    only_fields(root, "", {"format", "version", "decision", "corrections", "radiographs", "atlas"});
    const nlohmann::json& format = field(root, "", "format");
    if (format != kCorrectionsFormat) {
      fail("format",
           std::string("must be \"") + kCorrectionsFormat + "\", got " + short_json(format));
    }
    const nlohmann::json& version = field(root, "", "version");
    if (!version.is_number_integer() || version.get<std::int64_t>() != kCorrectionsVersion) {
      fail("version", "must be 1 (this mmm reads version 1), got " + short_json(version));
    }
    OutlineCorrections out;
    const std::string decision = text(root, "", "decision");
    if (decision == "accept") {
      out.decision = OutlineDecision::kAccept;
    } else if (decision == "correct") {
      out.decision = OutlineDecision::kCorrect;
    } else {
      fail("decision", R"(must be "accept" or "correct", got ")" + decision + "\"");
    }
    const nlohmann::json& list = field(root, "", "corrections");
    if (!list.is_array()) fail("corrections", "must be a list, got " + short_json(list));
    std::size_t total = 0;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string where = "corrections[" + std::to_string(k) + "]";
      out.corrections.push_back(correction(list[k], where));
      total += out.corrections.back().points_px.size();
      if (k > 0) {
        const OutlineCorrection& a = out.corrections[k - 1];
        const OutlineCorrection& b = out.corrections[k];
        if (std::tie(a.bone, a.view) >= std::tie(b.bone, b.view)) {
          fail(where, "('" + b.bone + "', '" + b.view +
                          "') repeats or comes before the entry above it; hint: one entry per "
                          "(bone, view), sorted by bone, then view");
        }
      }
    }
    if (total > kMaxCorrectionPoints) {
      fail("corrections", "hold " + std::to_string(total) + " points in all, at most " +
                              std::to_string(kMaxCorrectionPoints) + " are allowed");
    }
    if (out.decision == OutlineDecision::kAccept && !out.corrections.empty()) {
      fail("corrections", "must be empty when the decision is \"accept\"");
    }
    if (out.decision == OutlineDecision::kCorrect && out.corrections.empty()) {
      fail("corrections", "must not be empty when the decision is \"correct\"");
    }
    out.radiographs = hash(root, "radiographs");
    out.atlas = hash(root, "atlas");
    return out;
  }

 private:
  std::string source_;
};

}  // namespace

void sort_outline_corrections(OutlineCorrections& corrections) {
  std::ranges::stable_sort(corrections.corrections,
                           [](const OutlineCorrection& a, const OutlineCorrection& b) {
                             return std::tie(a.bone, a.view) < std::tie(b.bone, b.view);
                           });
}

std::string outline_corrections_to_json_text(const OutlineCorrections& corrections) {
  nlohmann::json list = nlohmann::json::array();
  for (const OutlineCorrection& correction : corrections.corrections) {
    nlohmann::json points = nlohmann::json::array();
    for (const Eigen::Vector2d& p : correction.points_px) points.push_back({p.x(), p.y()});
    list.push_back({{"bone", correction.bone}, {"view", correction.view}, {"points_px", points}});
  }
  const nlohmann::json root = {
      {"format", kCorrectionsFormat},
      {"version", kCorrectionsVersion},
      {"decision", corrections.decision == OutlineDecision::kAccept ? "accept" : "correct"},
      {"corrections", list},
      {"radiographs", corrections.radiographs},
      {"atlas", corrections.atlas}};
  std::string text = root.dump(2) + "\n";
  (void)read_outline_corrections(text, "outline corrections being written");
  return text;
}

OutlineCorrections read_outline_corrections(std::string_view text, std::string_view source) {
  const CorrectionsReader reader(source);
  nlohmann::json root;
  try {
    root = parse_json(text);
  } catch (const nlohmann::json::parse_error& error) {
    reader.fail(
        "", std::string("not valid JSON (NaN and Infinity are not JSON numbers): ") + error.what());
  }
  return reader.corrections(root);
}

}  // namespace mmm::image
