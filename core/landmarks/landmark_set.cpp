#include "core/landmarks/landmark_set.h"

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <string_view>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/landmarks/message_text.h"

namespace mmm::landmarks {

using Json = nlohmann::json;

namespace {

constexpr const char* kFormat = "mmm-landmark-set";
constexpr int kVersion = 1;

using detail::concat;
using detail::describe_json;

std::string landmark_label(std::size_t index, std::string_view name) {
  std::string label = "landmarks[" + std::to_string(index) + "]";
  if (!name.empty()) label += " ('" + std::string(name) + "')";
  return label;
}

// Reads and checks one JSON document; every failure names `what` and the field.
class Reader {
 public:
  explicit Reader(std::string_view what) : what_(what) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw InvalidInputError(what_ + ": " + (where.empty() ? "" : where + ": ") + problem);
  }

  const Json& field(const Json& object, const std::string& where, const char* key) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(where, std::string("field '") + key + "' is missing");
    return *it;
  }

  std::string text_field(const Json& object, const std::string& where, const char* key) const {
    const Json& value = field(object, where, key);
    if (!value.is_string()) {
      fail(where, std::string("field '") + key + "' must be a string, got " + describe_json(value));
    }
    return value.get<std::string>();
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const Json& value, const std::string& where,
                                     const std::string& field_name) const {
    const auto bad = [&] {
      fail(where, "field '" + field_name + "' must be " + std::to_string(N) +
                      " finite numbers, got " + describe_json(value));
    };
    if (!value.is_array() || value.size() != static_cast<std::size_t>(N)) bad();
    Eigen::Matrix<double, N, 1> out;
    for (int i = 0; i < N; ++i) {
      const Json& entry = value[static_cast<std::size_t>(i)];
      if (!entry.is_number()) bad();
      out(i) = entry.get<double>();
      if (!std::isfinite(out(i))) bad();
    }
    return out;
  }

  Landmark landmark(const Json& entry, std::size_t index) const {
    std::string where = landmark_label(index, "");
    if (!entry.is_object()) fail(where, "must be a JSON object, got " + describe_json(entry));
    Landmark landmark;
    landmark.name = text_field(entry, where, "name");
    if (landmark.name.empty()) fail(where, "field 'name' is empty");
    where = landmark_label(index, landmark.name);
    landmark.position_mm = vector<3>(field(entry, where, "position_mm"), where, "position_mm");
    if (const auto pixels = entry.find("pixels"); pixels != entry.end()) {
      if (!pixels->is_object()) {
        fail(where, "field 'pixels' must map view names to [u, v], got " + describe_json(*pixels));
      }
      for (const auto& [view, pixel] : pixels->items()) {
        if (view.empty()) fail(where, "field 'pixels' has an empty view name");
        landmark.pixels[view] = vector<2>(pixel, where, "pixels." + view);
      }
    }
    if (const auto errors = entry.find("reprojection_error_mm"); errors != entry.end()) {
      if (!errors->is_object()) {
        fail(where, "field 'reprojection_error_mm' must map view names to mm, got " +
                        describe_json(*errors));
      }
      for (const auto& [view, error] : errors->items()) {
        if (view.empty()) fail(where, "field 'reprojection_error_mm' has an empty view name");
        if (!error.is_number() || !std::isfinite(error.get<double>()) || error.get<double>() < 0) {
          fail(where, "field 'reprojection_error_mm." + view +
                          "' must be a finite number >= 0, got " + describe_json(error));
        }
        landmark.reprojection_error_mm[view] = error.get<double>();
      }
    }
    return landmark;
  }

  LandmarkSet set(const Json& root) const {
    if (!root.is_object()) fail("", "must be a JSON object, got " + describe_json(root));
    const Json& format = field(root, "", "format");
    if (!format.is_string() || format.get<std::string>() != kFormat) {
      fail("",
           std::string("field 'format' must be \"") + kFormat + "\", got " + describe_json(format));
    }
    const Json& version = field(root, "", "version");
    if (!version.is_number_integer() || version.get<std::int64_t>() != kVersion) {
      fail("", "field 'version' must be " + std::to_string(kVersion) + ", got " +
                   describe_json(version) + " (written by a newer mmm?)");
    }
    LandmarkSet set;
    set.frame = text_field(root, "", "frame");
    if (set.frame.empty()) fail("", R"(field 'frame' is empty; hint: "patient" or "lab")");
    set.source = text_field(root, "", "source");
    const Json& list = field(root, "", "landmarks");
    if (!list.is_array())
      fail("", "field 'landmarks' must be an array, got " + describe_json(list));
    std::map<std::string, std::size_t> first_index;
    for (std::size_t i = 0; i < list.size(); ++i) {
      set.landmarks.push_back(landmark(list[i], i));
      const auto [it, inserted] = first_index.emplace(set.landmarks.back().name, i);
      if (!inserted) {
        fail(landmark_label(i, it->first),
             "name used twice (first at landmarks[" + std::to_string(it->second) + "])");
      }
    }
    return set;
  }

 private:
  std::string what_;
};

Json vector_json(const auto& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

}  // namespace

std::string detail::describe_json(const Json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

const Landmark* LandmarkSet::find(std::string_view name) const {
  for (const Landmark& landmark : landmarks) {
    if (landmark.name == name) return &landmark;
  }
  return nullptr;
}

std::vector<std::string> LandmarkSet::names() const {
  std::vector<std::string> out;
  out.reserve(landmarks.size());
  for (const Landmark& landmark : landmarks) out.push_back(landmark.name);
  return out;
}

void validate_landmark_set(const LandmarkSet& set) {
  if (set.frame.empty()) {
    throw InvalidInputError(R"(landmark set: frame is empty; hint: "patient" or "lab")");
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < set.landmarks.size(); ++i) {
    const Landmark& landmark = set.landmarks[i];
    const std::string where = "landmark set: " + landmark_label(i, landmark.name) + ": ";
    if (landmark.name.empty()) throw InvalidInputError(where + "name is empty");
    if (!seen.insert(landmark.name).second) throw InvalidInputError(where + "name used twice");
    if (!landmark.position_mm.allFinite()) {
      throw InvalidInputError(where + "position_mm must be 3 finite numbers");
    }
    for (const auto& [view, pixel] : landmark.pixels) {
      if (view.empty()) throw InvalidInputError(where + "pixels has an empty view name");
      if (!pixel.allFinite()) {
        throw InvalidInputError(concat({where, "pixels.", view, " must be 2 finite numbers"}));
      }
    }
    for (const auto& [view, error] : landmark.reprojection_error_mm) {
      if (view.empty()) {
        throw InvalidInputError(where + "reprojection_error_mm has an empty view name");
      }
      if (!std::isfinite(error) || error < 0) {
        throw InvalidInputError(
            concat({where, "reprojection_error_mm.", view, " must be a finite number >= 0"}));
      }
    }
  }
}

void to_json(Json& json, const LandmarkSet& set) {
  validate_landmark_set(set);
  json = Json::object();
  json["format"] = kFormat;
  json["version"] = kVersion;
  json["frame"] = set.frame;
  json["source"] = set.source;
  Json list = Json::array();
  for (const Landmark& landmark : set.landmarks) {
    Json entry;
    entry["name"] = landmark.name;
    entry["position_mm"] = vector_json(landmark.position_mm);
    if (!landmark.pixels.empty()) {
      Json pixels = Json::object();
      for (const auto& [view, pixel] : landmark.pixels) pixels[view] = vector_json(pixel);
      entry["pixels"] = pixels;
    }
    if (!landmark.reprojection_error_mm.empty()) {
      entry["reprojection_error_mm"] = landmark.reprojection_error_mm;
    }
    list.push_back(std::move(entry));
  }
  json["landmarks"] = std::move(list);
}

void from_json(const Json& json, LandmarkSet& set) {
  set = landmark_set_from_json(json, "landmark set");
}

std::string landmark_set_to_json_text(const LandmarkSet& set) {
  Json json;
  to_json(json, set);
  return json.dump(2) + "\n";
}

LandmarkSet landmark_set_from_json(const Json& json, std::string_view what) {
  return Reader(what).set(json);
}

LandmarkSet landmark_set_from_json_text(std::string_view text, std::string_view what) {
  const Reader reader(what);
  Json root;
  try {
    root = parse_json(text);
  } catch (const Json::parse_error& error) {
    reader.fail(
        "", std::string("not valid JSON (NaN and Infinity are not JSON numbers): ") + error.what());
  }
  return reader.set(root);
}

}  // namespace mmm::landmarks
