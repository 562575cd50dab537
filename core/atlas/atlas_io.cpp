// The atlas manifest (atlas.yaml) and its meshes.
//
// Writing: a YAML::Emitter walks the Atlas; every double is written as the
// shortest text that reads back as the same double (std::to_chars), strings
// that YAML would take for a number, a boolean or null are quoted. The text is
// then read back with the reader below before it replaces the old manifest,
// so a manifest this program writes is always one it reads.
//
// Reading: one pass over the YAML tree builds the Atlas and collects every
// problem with its line, column and element path instead of stopping at the
// first: missing, ill-typed and unknown keys, unknown enum values, non-finite
// numbers, duplicate names, rotations that are not rotations. References
// between elements (bones, joints, muscles, coordinates) are recorded while
// reading and resolved at the end, when every name is known.

#include "core/atlas/atlas_io.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

#include "core/bounded_yaml.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/suggest.h"

namespace mmm::atlas {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Names, hints, enum tables
// ---------------------------------------------------------------------------

// The hint after an unknown name: a close match, else the list when short.
std::string unknown_hint(std::string_view name, const std::vector<std::string>& candidates,
                         std::string_view plural) {
  std::string hint = did_you_mean(name, candidates);
  constexpr std::size_t kMaxListed = 12;
  if (hint.empty() && candidates.size() <= kMaxListed) {
    hint = " (" + std::string(plural) + ": " + join_names(candidates) + ")";
  }
  return hint;
}

template <class Enum>
using NameTable = std::vector<std::pair<Enum, std::string>>;

const NameTable<CoordinateKind>& coordinate_kinds() {
  static const NameTable<CoordinateKind> table = {{CoordinateKind::kRotational, "rotational"},
                                                  {CoordinateKind::kTranslational, "translational"},
                                                  {CoordinateKind::kCoupled, "coupled"}};
  return table;
}

const NameTable<PathPointKind>& path_point_kinds() {
  static const NameTable<PathPointKind> table = {{PathPointKind::kFixed, "fixed"},
                                                 {PathPointKind::kConditional, "conditional"},
                                                 {PathPointKind::kMoving, "moving"},
                                                 {PathPointKind::kFollowsLine, "follows_line"}};
  return table;
}

template <class Enum>
std::string name_in(const NameTable<Enum>& table, Enum value) {
  for (const auto& [candidate, text] : table) {
    if (candidate == value) return text;
  }
  return "unknown";
}

template <class Enum>
std::vector<std::string> names_of(const NameTable<Enum>& table) {
  std::vector<std::string> names;
  for (const auto& entry : table) names.push_back(entry.second);
  return names;
}

std::vector<std::string> joint_type_names() {
  std::vector<std::string> names;
  for (const JointType type :
       {JointType::kWeld, JointType::kPin, JointType::kBall, JointType::kCustom}) {
    names.emplace_back(joint_type_name(type));
  }
  return names;
}

std::vector<std::string> wrap_shape_names() {
  std::vector<std::string> names;
  for (const WrapShape shape : {WrapShape::kSphere, WrapShape::kCylinder, WrapShape::kEllipsoid}) {
    names.emplace_back(wrap_shape_name(shape));
  }
  return names;
}

std::vector<std::string> architecture_names() {
  std::vector<std::string> names;
  for (const FibreArchitecture architecture :
       {FibreArchitecture::kParallel, FibreArchitecture::kPennate, FibreArchitecture::kFanned,
        FibreArchitecture::kCurved}) {
    names.emplace_back(fibre_architecture_name(architecture));
  }
  return names;
}

// The sides a path may wrap on (OpenSim's WrapObject quadrant).
const std::vector<std::string> kQuadrants = {"all", "x",  "y",  "z",  "+x",
                                             "-x",  "+y", "-y", "+z", "-z"};

// The tags of opensim::Function kinds in the manifest.
const std::vector<std::string> kFunctionKinds = {"constant",    "linear",           "polynomial",
                                                 "simm_spline", "piecewise_linear", "multiplier"};

// Joint types whose coordinates are fixed in number (custom joints have any).
std::optional<std::size_t> coordinate_count(JointType type) {
  switch (type) {
    case JointType::kWeld:
      return 0;
    case JointType::kPin:
      return 1;
    case JointType::kBall:
      return 3;
    case JointType::kCustom:
      break;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// Scalars as text
// ---------------------------------------------------------------------------

// The shortest text that reads back as exactly `value`; YAML's .inf/.nan for
// the non-finite ones.
std::string number_text(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  std::array<char, 32> buffer{};
  const auto [end, error] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return error == std::errc() ? std::string(buffer.data(), end) : std::string(".nan");
}

bool is_non_finite_word(std::string_view text) {
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) text.remove_prefix(1);
  return text == ".inf" || text == ".Inf" || text == ".INF" || text == ".nan" || text == ".NaN" ||
         text == ".NAN";
}

enum class NumberParse { kOk, kNotANumber, kNotFinite };

// A plain YAML scalar as a double (YAML 1.2 core schema forms).
NumberParse parse_number(std::string_view text, double& value) {
  if (is_non_finite_word(text)) return NumberParse::kNotFinite;
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string_view::npos) {
    return NumberParse::kNotANumber;
  }
  if (text.front() == '+') text.remove_prefix(1);
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (end != text.data() + text.size()) return NumberParse::kNotANumber;
  if (error == std::errc::result_out_of_range) return NumberParse::kNotFinite;
  if (error != std::errc()) return NumberParse::kNotANumber;
  return std::isfinite(value) ? NumberParse::kOk : NumberParse::kNotFinite;
}

bool parse_integer(std::string_view text, long long& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// Whether a plain scalar `text` would be read as something other than this
// string: null, a boolean (YAML 1.2, and 1.1's yes/no/on/off for other
// readers), a number. Such strings are written quoted.
bool needs_quotes(const std::string& text) {
  static const std::set<std::string> kWords = {
      "~",     "null", "Null", "NULL", "true", "True", "TRUE", "false", "False",
      "FALSE", "yes",  "Yes",  "YES",  "no",   "No",   "NO",   "on",    "On",
      "ON",    "off",  "Off",  "OFF",  "y",    "Y",    "n",    "N"};
  if (text.empty() || kWords.contains(text) || is_non_finite_word(text)) return true;
  std::string_view rest = text;
  if (rest.front() == '+' || rest.front() == '-') rest.remove_prefix(1);
  return !rest.empty() &&
         (std::isdigit(static_cast<unsigned char>(rest.front())) != 0 || rest.front() == '.');
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

class ManifestWriter {
 public:
  std::string write(const Atlas& atlas) {
    out_ << YAML::BeginMap;
    key("mmm_atlas");
    out_ << kAtlasFormat;
    key("name");
    text(atlas.name);
    key("description");
    text(atlas.description);
    key("frame_description");
    text(atlas.frame_description);
    key("provenance");
    block_texts(atlas.provenance);

    key("regions");
    block_list(atlas.regions, [&](const Region& region) { write_region(region); });
    key("bones");
    block_list(atlas.bones, [&](const Bone& bone) { write_bone(bone); });
    key("joints");
    block_list(atlas.joints, [&](const Joint& joint) { write_joint(joint); });
    key("muscles");
    block_list(atlas.muscles, [&](const Muscle& muscle) { write_muscle(muscle); });
    if (!atlas.structures.empty()) {
      key("structures");
      block_list(atlas.structures, [&](const Structure& structure) { write_structure(structure); });
    }
    key("landmarks");
    block_list(atlas.landmarks, [&](const Landmark& landmark) { write_landmark(landmark); });
    key("markers");
    block_list(atlas.markers, [&](const Marker& marker) { write_marker(marker); });
    out_ << YAML::EndMap;
    if (!out_.good()) throw std::logic_error("atlas manifest emitter: " + out_.GetLastError());
    return "# mmm atlas manifest: structure in schemas/atlas.schema.yaml; atlas frame, mm, rad\n" +
           std::string(out_.c_str()) + "\n";
  }

 private:
  void key(const char* name) { out_ << YAML::Key << name << YAML::Value; }

  // A list of elements, one per line; an empty one as [].
  void begin_list(bool empty) { out_ << (empty ? YAML::Flow : YAML::Block) << YAML::BeginSeq; }

  void text(const std::string& value) {
    if (needs_quotes(value)) out_ << YAML::DoubleQuoted;
    out_ << value;
  }

  void number(double value) { out_ << number_text(value); }

  template <class T, class WriteItem>
  void block_list(const std::vector<T>& items, WriteItem write_item) {
    begin_list(items.empty());
    for (const T& item : items) write_item(item);
    out_ << YAML::EndSeq;
  }

  void block_texts(const std::vector<std::string>& values) {
    begin_list(values.empty());
    for (const std::string& value : values) text(value);
    out_ << YAML::EndSeq;
  }

  void texts(const std::vector<std::string>& values) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (const std::string& value : values) text(value);
    out_ << YAML::EndSeq;
  }

  void numbers(const std::vector<double>& values) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (const double value : values) number(value);
    out_ << YAML::EndSeq;
  }

  void range(const std::array<double, 2>& values) {
    out_ << YAML::Flow << YAML::BeginSeq;
    number(values[0]);
    number(values[1]);
    out_ << YAML::EndSeq;
  }

  void vector3(const Eigen::Vector3d& v) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (int i = 0; i < 3; ++i) number(v[i]);
    out_ << YAML::EndSeq;
  }

  void frame(const Eigen::Isometry3d& pose) {
    out_ << YAML::Flow << YAML::BeginMap;
    key("origin");
    vector3(pose.translation());
    key("rotation");
    out_ << YAML::Flow << YAML::BeginSeq;
    for (int row = 0; row < 3; ++row) vector3(pose.linear().row(row).transpose());
    out_ << YAML::EndSeq << YAML::EndMap;
  }

  void function(const opensim::Function& f) {
    out_ << YAML::Flow << YAML::BeginMap;
    std::visit(
        [&](const auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, opensim::Constant>) {
            key("kind");
            out_ << "constant";
            key("value");
            number(g.value);
          } else if constexpr (std::is_same_v<T, opensim::LinearFunction>) {
            key("kind");
            out_ << "linear";
            key("slope");
            number(g.slope);
            key("intercept");
            number(g.intercept);
          } else if constexpr (std::is_same_v<T, opensim::PolynomialFunction>) {
            key("kind");
            out_ << "polynomial";
            key("coefficients");
            numbers(g.coefficients);
          } else if constexpr (std::is_same_v<T, opensim::SimmSpline> ||
                               std::is_same_v<T, opensim::PiecewiseLinearFunction>) {
            key("kind");
            out_ << (std::is_same_v<T, opensim::SimmSpline> ? "simm_spline" : "piecewise_linear");
            key("x");
            numbers(g.x());
            key("y");
            numbers(g.y());
          } else {
            static_assert(std::is_same_v<T, opensim::MultiplierFunction>);
            key("kind");
            out_ << "multiplier";
            key("scale");
            number(g.scale());
            key("function");
            function(g.function());
          }
        },
        f.variant());
    out_ << YAML::EndMap;
  }

  void mesh_levels(const std::vector<MeshLevel>& levels) {
    begin_list(levels.empty());
    for (const MeshLevel& level : levels) {
      out_ << YAML::Flow << YAML::BeginMap;
      key("level");
      text(level.level);
      key("file");
      text(level.file);
      key("faces");
      out_ << level.faces;
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }

  void write_region(const Region& region) {
    out_ << YAML::BeginMap;
    key("name");
    text(region.name);
    key("tags");
    texts(region.tags);
    key("bones");
    texts(region.bones);
    key("muscles");
    texts(region.muscles);
    if (!region.structures.empty()) {
      key("structures");
      texts(region.structures);
    }
    out_ << YAML::EndMap;
  }

  void write_structure(const Structure& structure) {
    out_ << YAML::BeginMap;
    key("name");
    text(structure.name);
    key("kind");
    out_ << std::string(structure_kind_name(structure.kind));
    key("tags");
    texts(structure.tags);
    key("bones");
    texts(structure.bones);
    key("meshes");
    mesh_levels(structure.meshes);
    out_ << YAML::EndMap;
  }

  void write_bone(const Bone& bone) {
    out_ << YAML::BeginMap;
    key("name");
    text(bone.name);
    key("tags");
    texts(bone.tags);
    key("meshes");
    mesh_levels(bone.meshes);
    key("frame");
    frame(bone.frame);
    if (!bone.parent_joint.empty()) {
      key("parent_joint");
      text(bone.parent_joint);
    }
    out_ << YAML::EndMap;
  }

  void write_joint(const Joint& joint) {
    out_ << YAML::BeginMap;
    key("name");
    text(joint.name);
    key("type");
    out_ << std::string(joint_type_name(joint.type));
    key("parent");
    text(joint.parent);
    key("child");
    text(joint.child);
    key("parent_frame");
    frame(joint.parent_frame);
    key("child_frame");
    frame(joint.child_frame);
    key("coordinates");
    begin_list(joint.coordinates.empty());
    for (const Coordinate& coordinate : joint.coordinates) {
      out_ << YAML::Flow << YAML::BeginMap;
      key("name");
      text(coordinate.name);
      key("kind");
      out_ << name_in(coordinate_kinds(), coordinate.kind);
      key("range");
      range(coordinate.range);
      key("rest_value");
      number(coordinate.rest_value);
      key("default_value");
      number(coordinate.default_value);
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
    if (joint.type == JointType::kCustom || !joint.axes.empty()) {
      key("axes");
      begin_list(joint.axes.empty());
      for (const TransformAxis& axis : joint.axes) {
        out_ << YAML::Flow << YAML::BeginMap;
        key("kind");
        out_ << (axis.rotation ? "rotation" : "translation");
        key("axis");
        vector3(axis.axis);
        if (!axis.coordinate.empty()) {
          key("coordinate");
          text(axis.coordinate);
        }
        key("function");
        function(axis.function);
        out_ << YAML::EndMap;
      }
      out_ << YAML::EndSeq;
    }
    out_ << YAML::EndMap;
  }

  // Fixed and conditional points on one line each; moving ones as a block.
  void write_point(const PathPoint& point) {
    if (point.kind != PathPointKind::kMoving) out_ << YAML::Flow;
    out_ << YAML::BeginMap;
    if (!point.name.empty()) {
      key("name");
      text(point.name);
    }
    key("bone");
    text(point.bone);
    key("position");
    vector3(point.position);
    key("kind");
    out_ << name_in(path_point_kinds(), point.kind);
    if (point.kind == PathPointKind::kConditional) {
      key("coordinate");
      text(point.coordinate);
      key("range");
      range(point.range);
    }
    if (point.kind == PathPointKind::kMoving) {
      key("moving");
      out_ << YAML::BeginMap;
      for (std::size_t i = 0; i < 3; ++i) {
        key(std::array{"x", "y", "z"}[i]);
        out_ << YAML::Flow << YAML::BeginMap;
        if (!point.moving_coordinates[i].empty()) {
          key("coordinate");
          text(point.moving_coordinates[i]);
        }
        key("function");
        function(point.moving_functions[i]);
        out_ << YAML::EndMap;
      }
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndMap;
  }

  void attachment_areas(const std::vector<AttachmentArea>& areas) {
    begin_list(areas.empty());
    for (const AttachmentArea& area : areas) {
      out_ << YAML::BeginMap;
      key("bone");
      text(area.bone);
      key("area_mm2");
      number(area.area_mm2);
      key("centroid");
      vector3(area.centroid);
      key("faces");
      out_ << YAML::Flow << YAML::BeginSeq;
      for (const int face : area.faces) out_ << face;
      out_ << YAML::EndSeq;
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }

  void write_muscle(const Muscle& muscle) {
    out_ << YAML::BeginMap;
    key("name");
    text(muscle.name);
    key("tags");
    texts(muscle.tags);
    key("meshes");
    mesh_levels(muscle.meshes);
    key("architecture");
    out_ << std::string(fibre_architecture_name(muscle.architecture));
    key("max_isometric_force_n");
    number(muscle.max_isometric_force_n);
    key("optimal_fibre_length_mm");
    number(muscle.optimal_fibre_length_mm);
    key("tendon_slack_length_mm");
    number(muscle.tendon_slack_length_mm);
    key("pennation_angle_rad");
    number(muscle.pennation_angle_rad);
    key("wrap_obstacles");
    begin_list(muscle.wrap_obstacles.empty());
    for (const WrapObstacle& obstacle : muscle.wrap_obstacles) {
      out_ << YAML::BeginMap;
      key("name");
      text(obstacle.name);
      key("shape");
      out_ << std::string(wrap_shape_name(obstacle.shape));
      key("bone");
      text(obstacle.bone);
      key("pose");
      frame(obstacle.pose);
      key("radii");
      vector3(obstacle.radii);
      key("quadrant");
      text(obstacle.quadrant);
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
    key("action_lines");
    begin_list(muscle.action_lines.empty());
    for (const ActionLine& line : muscle.action_lines) {
      out_ << YAML::BeginMap;
      key("name");
      text(line.name);
      key("wrap_obstacles");
      texts(line.wrap_obstacles);
      key("points");
      block_list(line.points, [&](const PathPoint& point) { write_point(point); });
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
    key("origins");
    attachment_areas(muscle.origins);
    key("insertions");
    attachment_areas(muscle.insertions);
    out_ << YAML::EndMap;
  }

  void write_landmark(const Landmark& landmark) {
    out_ << YAML::Flow << YAML::BeginMap;
    key("name");
    text(landmark.name);
    key("bone");
    text(landmark.bone);
    key("position");
    vector3(landmark.position);
    key("tags");
    texts(landmark.tags);
    if (!landmark.description.empty()) {
      key("description");
      text(landmark.description);
    }
    out_ << YAML::EndMap;
  }

  void write_marker(const Marker& marker) {
    out_ << YAML::Flow << YAML::BeginMap;
    key("name");
    text(marker.name);
    key("bone");
    text(marker.bone);
    key("position");
    vector3(marker.position);
    key("fixed");
    out_ << (marker.fixed ? "true" : "false");
    out_ << YAML::EndMap;
  }

  YAML::Emitter out_;
};

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

struct Problem {
  int line = -1;  // 0-based, as yaml-cpp marks; -1 when unknown
  int column = -1;
  std::string path;  // element path, "top level" for the root
  std::string message;

  [[nodiscard]] std::string text() const {
    std::string out;
    if (line >= 0) {
      out = "line " + std::to_string(line + 1) + ", column " + std::to_string(column + 1) + ": ";
    }
    return out + path + ": " + message;
  }
};

// A value in the document: the node, where it is (the key's position when the
// value is empty) and its element path.
struct Value {
  YAML::Node node;
  YAML::Mark mark;
  std::string path;
};

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing (null)";
  if (node.IsMap()) return "a mapping";
  if (node.IsSequence()) return "a list";
  return "'" + node.Scalar() + "'";
}

std::string item_path(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

enum class RefKind { kBone, kJoint, kMuscle, kCoordinate, kStructure };

struct Reference {
  RefKind kind;
  std::string name;
  YAML::Mark mark;
  std::string path;
};

// Face indices of an attachment area, checked against the bone's full mesh
// once every bone is known.
struct FaceCheck {
  std::string bone;
  int max_face = -1;
  YAML::Mark mark;
  std::string path;
};

class AtlasReader {
 public:
  void report(const YAML::Mark& mark, const std::string& path, const std::string& message) {
    problems_.push_back({mark.line, mark.column, path.empty() ? "top level" : path, message});
  }
  void report(const Value& value, const std::string& message) {
    report(value.mark, value.path, message);
  }

  void refer(RefKind kind, const std::string& name, const Value& where) {
    references_.push_back({kind, name, where.mark, where.path});
  }

  // Records the name of a `what` ("bone", "action line", ...) that must be
  // unique within `scope` (the atlas when empty, else e.g. "muscle 'x'");
  // reports a second definition.
  void declare(const std::string& what, const std::string& name, const Value& where,
               const std::string& scope = {}) {
    const auto [it, inserted] = declared_[what + "/" + scope].try_emplace(name, where);
    if (!inserted) {
      const Value& first = it->second;
      report(where, "duplicate " + what + " name '" + name + "'" +
                        (scope.empty() ? "" : " in " + scope) + " (first defined at " + first.path +
                        ", line " + std::to_string(first.mark.line + 1) + ")");
    }
  }

  void check_faces(FaceCheck check) { face_checks_.push_back(std::move(check)); }

  // Resolves the recorded references against the atlas read.
  void resolve(const Atlas& atlas) {
    std::map<RefKind, std::vector<std::string>> names;
    for (const Bone& bone : atlas.bones) names[RefKind::kBone].push_back(bone.name);
    for (const Joint& joint : atlas.joints) {
      names[RefKind::kJoint].push_back(joint.name);
      for (const Coordinate& c : joint.coordinates) names[RefKind::kCoordinate].push_back(c.name);
    }
    for (const Muscle& muscle : atlas.muscles) names[RefKind::kMuscle].push_back(muscle.name);
    for (const Structure& structure : atlas.structures) {
      names[RefKind::kStructure].push_back(structure.name);
    }
    static const std::map<RefKind, std::pair<std::string, std::string>> kWords = {
        {RefKind::kBone, {"bone", "bones"}},
        {RefKind::kJoint, {"joint", "joints"}},
        {RefKind::kMuscle, {"muscle", "muscles"}},
        {RefKind::kStructure, {"structure", "structures"}},
        {RefKind::kCoordinate, {"coordinate", "coordinates"}}};
    for (const Reference& ref : references_) {
      const std::vector<std::string>& candidates = names[ref.kind];
      if (std::ranges::find(candidates, ref.name) != candidates.end()) continue;
      const auto& [word, plural] = kWords.at(ref.kind);
      report(
          ref.mark, ref.path,
          "unknown " + word + " '" + ref.name + "'" + unknown_hint(ref.name, candidates, plural));
    }
    for (const FaceCheck& check : face_checks_) {
      const Bone* bone = atlas.find_bone(check.bone);
      if (bone == nullptr) continue;  // reported as an unknown bone
      const auto full = std::ranges::find(bone->meshes, std::string("full"), &MeshLevel::level);
      if (full == bone->meshes.end() || full->faces <= 0) continue;  // nothing to check against
      if (check.max_face >= full->faces) {
        report(check.mark, check.path,
               "face index " + std::to_string(check.max_face) + " is out of range: bone '" +
                   check.bone + "' has " + std::to_string(full->faces) + " faces in its full mesh");
      }
    }
  }

  [[nodiscard]] std::vector<Problem> problems() const {
    std::vector<Problem> sorted = problems_;
    std::ranges::stable_sort(sorted, [](const Problem& a, const Problem& b) {
      return std::pair(a.line, a.column) < std::pair(b.line, b.column);
    });
    return sorted;
  }

 private:
  std::vector<Problem> problems_;
  std::vector<Reference> references_;
  std::vector<FaceCheck> face_checks_;
  std::map<std::string, std::map<std::string, Value>> declared_;
};

enum class Need { kOptional, kRequired };

// Scalar conversions; each reports its own problem and returns nullopt.

std::optional<std::string> read_text(AtlasReader& r, const Value& v) {
  if (!v.node.IsScalar()) {
    r.report(v, "expected a string, got " + describe(v.node));
    return std::nullopt;
  }
  return v.node.Scalar();
}

std::optional<std::string> read_name(AtlasReader& r, const Value& v) {
  std::optional<std::string> name = read_text(r, v);
  if (name && name->empty()) {
    r.report(v, "must not be empty");
    return std::nullopt;
  }
  return name;
}

std::optional<double> read_number(AtlasReader& r, const Value& v) {
  double value = 0.0;
  // A quoted scalar is a string, whatever it looks like (YAML 1.2).
  const bool plain = v.node.IsScalar() && v.node.Tag() != "!";
  const NumberParse parsed =
      plain ? parse_number(v.node.Scalar(), value) : NumberParse::kNotANumber;
  if (parsed == NumberParse::kOk) return value;
  if (parsed == NumberParse::kNotFinite) {
    r.report(v, "expected a finite number, got '" + v.node.Scalar() + "'");
  } else {
    r.report(v, "expected a number, got " + describe(v.node));
  }
  return std::nullopt;
}

std::optional<int> read_integer(AtlasReader& r, const Value& v) {
  long long value = 0;
  if (v.node.IsScalar() && v.node.Tag() != "!" && parse_integer(v.node.Scalar(), value)) {
    if (value >= std::numeric_limits<int>::min() && value <= std::numeric_limits<int>::max()) {
      return static_cast<int>(value);
    }
    r.report(v, "integer " + v.node.Scalar() + " is out of range");
    return std::nullopt;
  }
  r.report(v, "expected an integer, got " + describe(v.node));
  return std::nullopt;
}

std::optional<bool> read_boolean(AtlasReader& r, const Value& v) {
  if (v.node.IsScalar() && v.node.Tag() != "!") {
    const std::string& text = v.node.Scalar();
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
  }
  r.report(v, "expected true or false, got " + describe(v.node));
  return std::nullopt;
}

// The items of a list value, each with its position and path.
std::optional<std::vector<Value>> read_items(AtlasReader& r, const Value& v) {
  if (!v.node.IsSequence()) {
    r.report(v, "expected a list, got " + describe(v.node));
    return std::nullopt;
  }
  std::vector<Value> items;
  items.reserve(v.node.size());
  for (std::size_t i = 0; i < v.node.size(); ++i) {
    const YAML::Node item = v.node[i];
    const YAML::Mark mark = item.Mark().line >= 0 ? item.Mark() : v.mark;
    items.push_back({item, mark, item_path(v.path, i)});
  }
  return items;
}

std::optional<std::vector<double>> read_numbers(AtlasReader& r, const Value& v,
                                                std::optional<std::size_t> count = {}) {
  const std::optional<std::vector<Value>> items = read_items(r, v);
  if (!items) return std::nullopt;
  if (count && items->size() != *count) {
    r.report(
        v, "expected " + std::to_string(*count) + " numbers, got " + std::to_string(items->size()));
    return std::nullopt;
  }
  std::vector<double> values;
  bool ok = true;
  for (const Value& item : *items) {
    const std::optional<double> value = read_number(r, item);
    ok = ok && value.has_value();
    values.push_back(value.value_or(0.0));
  }
  return ok ? std::optional(values) : std::nullopt;
}

std::optional<Eigen::Vector3d> read_vector3(AtlasReader& r, const Value& v) {
  const std::optional<std::vector<double>> values = read_numbers(r, v, 3);
  if (!values) return std::nullopt;
  return Eigen::Vector3d((*values)[0], (*values)[1], (*values)[2]);
}

std::optional<std::array<double, 2>> read_range(AtlasReader& r, const Value& v) {
  const std::optional<std::vector<double>> values = read_numbers(r, v, 2);
  if (!values) return std::nullopt;
  if ((*values)[0] > (*values)[1]) {
    r.report(v, "range [" + number_text((*values)[0]) + ", " + number_text((*values)[1]) +
                    "] is empty: the minimum comes first");
    return std::nullopt;
  }
  return std::array<double, 2>{(*values)[0], (*values)[1]};
}

std::optional<std::vector<std::string>> read_texts(AtlasReader& r, const Value& v) {
  const std::optional<std::vector<Value>> items = read_items(r, v);
  if (!items) return std::nullopt;
  std::vector<std::string> values;
  for (const Value& item : *items) {
    if (std::optional<std::string> value = read_name(r, item)) values.push_back(std::move(*value));
  }
  return values;
}

// A mapping being read: hands out its values by key and remembers which keys
// were asked for, so that finish() can report the others (a misspelt optional
// key must not be silently ignored).
class MapReader {
 public:
  MapReader(AtlasReader& r, const Value& v) : reader_(r), value_(v) {
    if (!v.node.IsMap()) {
      r.report(v, "expected a mapping, got " + describe(v.node));
      return;
    }
    valid_ = true;
    for (const auto& entry : v.node) {
      const YAML::Node& key = entry.first;
      if (!key.IsScalar()) {
        r.report(key.Mark(), v.path, "keys must be plain strings, got " + describe(key));
        continue;
      }
      const YAML::Mark value_mark =
          entry.second.IsNull() || entry.second.Mark().line < 0 ? key.Mark() : entry.second.Mark();
      if (!entries_.try_emplace(key.Scalar(), Entry{entry.second, key.Mark(), value_mark}).second) {
        r.report(key.Mark(), v.path, "duplicate key '" + key.Scalar() + "'");
      }
    }
  }

  [[nodiscard]] bool valid() const { return valid_; }
  [[nodiscard]] const std::string& path() const { return value_.path; }
  [[nodiscard]] const Value& value() const { return value_; }

  // The value of `key`; nullopt when absent (a problem when required).
  std::optional<Value> get(const std::string& key, Need need) {
    known_.push_back(key);
    const auto it = entries_.find(key);
    if (it == entries_.end()) {
      if (need == Need::kRequired) {
        reader_.report(value_, "missing required key '" + key + "'");
      }
      return std::nullopt;
    }
    it->second.used = true;
    return Value{it->second.node, it->second.value_mark, child(key)};
  }

  // A key that must not be here, with the reason.
  void forbid(const std::string& key, const std::string& reason) {
    known_.push_back(key);
    const auto it = entries_.find(key);
    if (it == entries_.end()) return;
    it->second.used = true;
    reader_.report(it->second.key_mark, child(key), reason);
  }

  // Typed fields: the target keeps its value when the key is absent or bad.
  std::optional<Value> text(const std::string& key, std::string& target, Need need) {
    return assign(key, need, target, read_text);
  }
  std::optional<Value> name(const std::string& key, std::string& target, Need need) {
    return assign(key, need, target, read_name);
  }
  std::optional<Value> number(const std::string& key, double& target, Need need) {
    return assign(key, need, target, read_number);
  }
  // A number that may not be negative.
  std::optional<Value> amount(const std::string& key, double& target, Need need) {
    std::optional<Value> v = number(key, target, need);
    if (v && target < 0) {
      reader_.report(*v, "must not be negative, got " + number_text(target));
      return std::nullopt;
    }
    return v;
  }
  std::optional<Value> integer(const std::string& key, int& target, Need need) {
    return assign(key, need, target, read_integer);
  }
  std::optional<Value> boolean(const std::string& key, bool& target, Need need) {
    return assign(key, need, target, read_boolean);
  }
  std::optional<Value> vector3(const std::string& key, Eigen::Vector3d& target, Need need) {
    return assign(key, need, target, read_vector3);
  }
  std::optional<Value> range(const std::string& key, std::array<double, 2>& target, Need need) {
    return assign(key, need, target, read_range);
  }
  std::optional<Value> texts(const std::string& key, std::vector<std::string>& target, Need need) {
    return assign(key, need, target, read_texts);
  }
  // An enum by name, from `names` (the value's index in it).
  std::optional<std::size_t> choice(const std::string& key, const std::vector<std::string>& names,
                                    std::string_view what, Need need) {
    std::string word;
    const std::optional<Value> v = name(key, word, need);
    if (!v) return std::nullopt;
    const auto it = std::ranges::find(names, word);
    if (it == names.end()) {
      std::string message = "unknown " + std::string(what) + " '" + word + "'";
      const std::string close = did_you_mean(word, names);
      message += close.empty() ? " (expected one of: " + join_names(names) + ")"
                               : close + " (expected one of: " + join_names(names) + ")";
      reader_.report(*v, message);
      return std::nullopt;
    }
    return static_cast<std::size_t>(it - names.begin());
  }

  // Reports the keys nobody asked for.
  void finish() {
    if (!valid_) return;
    for (const auto& [key, entry] : entries_) {
      if (entry.used) continue;
      reader_.report(entry.key_mark, value_.path,
                     "unknown key '" + key + "'" + did_you_mean(key, known_) +
                         " (allowed: " + join_names(known_) + ")");
    }
  }

 private:
  struct Entry {
    YAML::Node node;
    YAML::Mark key_mark;
    YAML::Mark value_mark;
    bool used = false;
  };

  [[nodiscard]] std::string child(const std::string& key) const {
    return value_.path.empty() ? key : value_.path + "." + key;
  }

  template <class T, class Read>
  std::optional<Value> assign(const std::string& key, Need need, T& target, Read read) {
    std::optional<Value> v = get(key, need);
    if (!v) return std::nullopt;
    auto parsed = read(reader_, *v);
    if (!parsed) return std::nullopt;
    target = std::move(*parsed);
    return v;
  }

  AtlasReader& reader_;
  Value value_;
  bool valid_ = false;
  std::map<std::string, Entry> entries_;
  std::vector<std::string> known_;
};

// Calls read_item for each item of the list at `key` (absent: nothing).
template <class T, class ReadItem>
void read_list(AtlasReader& r, MapReader& m, const std::string& key, std::vector<T>& target,
               Need need, ReadItem read_item) {
  const std::optional<Value> v = m.get(key, need);
  if (!v) return;
  const std::optional<std::vector<Value>> items = read_items(r, *v);
  if (!items) return;
  for (const Value& item : *items) target.push_back(read_item(item));
}

// {origin: [x, y, z], rotation: [[r00, r01, r02], [...], [...]]}, rows of the
// rotation; the rotation must be orthonormal within 1e-6 and proper. It is
// kept as written (not re-orthonormalised), so write -> read is exact.
std::optional<Eigen::Isometry3d> read_frame(AtlasReader& r, const Value& v) {
  MapReader m(r, v);
  if (!m.valid()) return std::nullopt;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  bool ok = m.vector3("origin", origin, Need::kRequired).has_value();
  pose.translation() = origin;
  if (const std::optional<Value> rotation = m.get("rotation", Need::kRequired)) {
    const std::optional<std::vector<Value>> rows = read_items(r, *rotation);
    if (rows && rows->size() != 3) {
      r.report(*rotation,
               "expected 3 rows of 3 numbers, got " + std::to_string(rows->size()) + " rows");
      ok = false;
    } else if (rows) {
      Eigen::Matrix3d matrix;
      for (int i = 0; i < 3; ++i) {
        const std::optional<Eigen::Vector3d> row =
            read_vector3(r, (*rows)[static_cast<std::size_t>(i)]);
        ok = ok && row.has_value();
        if (row) matrix.row(i) = row->transpose();
      }
      if (ok) {
        // 1e-6: rotations are written with 17 digits; anything further off
        // than that was not a rotation to begin with.
        constexpr double kTolerance = 1e-6;
        const double error =
            (matrix.transpose() * matrix - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
        if (!(error <= kTolerance)) {
          r.report(*rotation,
                   "not a rotation: its rows are not orthonormal (R^T R differs from "
                   "the identity by " +
                       number_text(error) + ", at most 1e-06 allowed)");
          ok = false;
        } else if (matrix.determinant() < 0) {
          r.report(*rotation, "not a rotation: it is a reflection (determinant -1)");
          ok = false;
        }
        pose.linear() = matrix;
      }
    } else {
      ok = false;
    }
  } else {
    ok = false;
  }
  m.finish();
  return ok ? std::optional(pose) : std::nullopt;
}

std::optional<opensim::Function> read_function(AtlasReader& r, const Value& v) {
  MapReader m(r, v);
  if (!m.valid()) return std::nullopt;
  const std::optional<std::size_t> kind =
      m.choice("kind", kFunctionKinds, "function kind", Need::kRequired);
  if (!kind) return std::nullopt;  // other keys are meaningless without a kind
  const std::string& name = kFunctionKinds[*kind];
  std::optional<opensim::Function> result;
  if (name == "constant") {
    double value = 0.0;
    if (m.number("value", value, Need::kRequired)) result = opensim::Constant{value};
  } else if (name == "linear") {
    opensim::LinearFunction f;
    const bool slope = m.number("slope", f.slope, Need::kRequired).has_value();
    const bool intercept = m.number("intercept", f.intercept, Need::kRequired).has_value();
    if (slope && intercept) result = f;
  } else if (name == "polynomial") {
    if (const std::optional<Value> c = m.get("coefficients", Need::kRequired)) {
      if (std::optional<std::vector<double>> coefficients = read_numbers(r, *c)) {
        result = opensim::PolynomialFunction{std::move(*coefficients)};
      }
    }
  } else if (name == "simm_spline" || name == "piecewise_linear") {
    std::optional<std::vector<double>> x;
    std::optional<std::vector<double>> y;
    if (const std::optional<Value> xv = m.get("x", Need::kRequired)) x = read_numbers(r, *xv);
    if (const std::optional<Value> yv = m.get("y", Need::kRequired)) y = read_numbers(r, *yv);
    if (x && y) {
      try {
        if (name == "simm_spline") {
          result = opensim::SimmSpline(std::move(*x), std::move(*y));
        } else {
          result = opensim::PiecewiseLinearFunction(std::move(*x), std::move(*y));
        }
      } catch (const InvalidInputError& e) {
        r.report(v, e.what());
      }
    }
  } else {  // multiplier
    double scale = 1.0;
    const bool has_scale = m.number("scale", scale, Need::kRequired).has_value();
    std::optional<opensim::Function> inner;
    if (const std::optional<Value> f = m.get("function", Need::kRequired)) {
      inner = read_function(r, *f);
    }
    if (has_scale && inner) result = opensim::MultiplierFunction(std::move(*inner), scale);
  }
  m.finish();
  return result;
}

// [{level, file, faces}, ...]
std::vector<MeshLevel> read_mesh_levels(AtlasReader& r, MapReader& element) {
  std::vector<MeshLevel> levels;
  read_list(r, element, "meshes", levels, Need::kOptional, [&](const Value& item) {
    MeshLevel level;
    MapReader m(r, item);
    if (!m.valid()) return level;
    if (const std::optional<Value> v = m.name("level", level.level, Need::kRequired)) {
      r.declare("mesh level", level.level, *v, element.path());
    }
    if (const std::optional<Value> v = m.name("file", level.file, Need::kRequired)) {
      const fs::path file(level.file);
      if (file.is_absolute() || std::ranges::find(file, fs::path("..")) != file.end()) {
        r.report(*v, "'" + level.file +
                         "' must be a relative path inside the atlas folder (no leading / and "
                         "no ..)");
      }
    }
    if (const std::optional<Value> v = m.integer("faces", level.faces, Need::kOptional)) {
      if (level.faces < 0) r.report(*v, "must not be negative");
    }
    m.finish();
    return level;
  });
  return levels;
}

// Reads `key` as a frame into `target` (identity when absent).
void read_frame_field(AtlasReader& r, MapReader& m, const std::string& key,
                      Eigen::Isometry3d& target) {
  if (const std::optional<Value> v = m.get(key, Need::kOptional)) {
    if (std::optional<Eigen::Isometry3d> pose = read_frame(r, *v)) target = *pose;
  }
}

// A name that refers to an element of another kind.
void refer(AtlasReader& r, MapReader& m, const std::string& key, std::string& target, RefKind kind,
           Need need) {
  if (const std::optional<Value> v = m.name(key, target, need)) r.refer(kind, target, *v);
}

// A list of names that refer to elements of another kind.
void refer_all(AtlasReader& r, MapReader& m, const std::string& key,
               std::vector<std::string>& target, RefKind kind) {
  const std::optional<Value> v = m.get(key, Need::kOptional);
  if (!v) return;
  const std::optional<std::vector<Value>> items = read_items(r, *v);
  if (!items) return;
  for (const Value& item : *items) {
    if (std::optional<std::string> name = read_name(r, item)) {
      r.refer(kind, *name, item);
      target.push_back(std::move(*name));
    }
  }
}

Region read_region(AtlasReader& r, const Value& v) {
  Region region;
  MapReader m(r, v);
  if (!m.valid()) return region;
  if (const std::optional<Value> name = m.name("name", region.name, Need::kRequired)) {
    r.declare("region", region.name, *name);
  }
  m.texts("tags", region.tags, Need::kOptional);
  refer_all(r, m, "bones", region.bones, RefKind::kBone);
  refer_all(r, m, "muscles", region.muscles, RefKind::kMuscle);
  refer_all(r, m, "structures", region.structures, RefKind::kStructure);
  m.finish();
  return region;
}

Bone read_bone(AtlasReader& r, const Value& v) {
  Bone bone;
  MapReader m(r, v);
  if (!m.valid()) return bone;
  if (const std::optional<Value> name = m.name("name", bone.name, Need::kRequired)) {
    r.declare("bone", bone.name, *name);
  }
  m.texts("tags", bone.tags, Need::kOptional);
  bone.meshes = read_mesh_levels(r, m);
  read_frame_field(r, m, "frame", bone.frame);
  refer(r, m, "parent_joint", bone.parent_joint, RefKind::kJoint, Need::kOptional);
  m.finish();
  return bone;
}

Coordinate read_coordinate(AtlasReader& r, const Value& v) {
  Coordinate coordinate;
  MapReader m(r, v);
  if (!m.valid()) return coordinate;
  if (const std::optional<Value> name = m.name("name", coordinate.name, Need::kRequired)) {
    // OpenSim coordinate names are unique across the whole model.
    r.declare("coordinate", coordinate.name, *name);
  }
  if (const auto kind =
          m.choice("kind", names_of(coordinate_kinds()), "coordinate kind", Need::kOptional)) {
    coordinate.kind = coordinate_kinds()[*kind].first;
  }
  m.range("range", coordinate.range, Need::kRequired);
  m.number("rest_value", coordinate.rest_value, Need::kOptional);
  m.number("default_value", coordinate.default_value, Need::kOptional);
  m.finish();
  return coordinate;
}

TransformAxis read_axis(AtlasReader& r, const Value& v, const Joint& joint) {
  TransformAxis axis;
  MapReader m(r, v);
  if (!m.valid()) return axis;
  if (const auto kind =
          m.choice("kind", {"rotation", "translation"}, "axis kind", Need::kRequired)) {
    axis.rotation = *kind == 0;
  }
  if (const std::optional<Value> a = m.vector3("axis", axis.axis, Need::kRequired)) {
    if (axis.axis.norm() == 0) r.report(*a, "the axis must not be the zero vector");
  }
  if (const std::optional<Value> c = m.name("coordinate", axis.coordinate, Need::kOptional)) {
    std::vector<std::string> own;
    for (const Coordinate& coordinate : joint.coordinates) own.push_back(coordinate.name);
    if (std::ranges::find(own, axis.coordinate) == own.end()) {
      r.report(*c, "unknown coordinate '" + axis.coordinate + "' (the axes of joint '" +
                       joint.name + "' may use its own coordinates: " + join_names(own) + ")" +
                       did_you_mean(axis.coordinate, own));
    }
  }
  if (const std::optional<Value> f = m.get("function", Need::kRequired)) {
    if (std::optional<opensim::Function> function = read_function(r, *f)) axis.function = *function;
  }
  m.finish();
  return axis;
}

Joint read_joint(AtlasReader& r, const Value& v) {
  Joint joint;
  MapReader m(r, v);
  if (!m.valid()) return joint;
  if (const std::optional<Value> name = m.name("name", joint.name, Need::kRequired)) {
    r.declare("joint", joint.name, *name);
  }
  const std::optional<std::size_t> type =
      m.choice("type", joint_type_names(), "joint type", Need::kRequired);
  if (type) joint.type = *joint_type_from_name(joint_type_names()[*type]);
  refer(r, m, "parent", joint.parent, RefKind::kBone, Need::kRequired);
  const std::optional<Value> child = m.name("child", joint.child, Need::kRequired);
  if (child) {
    r.refer(RefKind::kBone, joint.child, *child);
    if (joint.child == joint.parent) r.report(*child, "a joint cannot connect a bone to itself");
  }
  read_frame_field(r, m, "parent_frame", joint.parent_frame);
  read_frame_field(r, m, "child_frame", joint.child_frame);
  const std::optional<Value> coordinates = m.get("coordinates", Need::kOptional);
  if (coordinates) {
    if (const auto items = read_items(r, *coordinates)) {
      for (const Value& item : *items) joint.coordinates.push_back(read_coordinate(r, item));
    }
  }
  if (type) {
    const std::optional<std::size_t> expected = coordinate_count(joint.type);
    if (expected && joint.coordinates.size() != *expected) {
      r.report(coordinates ? *coordinates : m.value(),
               "a " + std::string(joint_type_name(joint.type)) + " joint has " +
                   std::to_string(*expected) + " coordinate(s), got " +
                   std::to_string(joint.coordinates.size()));
    }
  }
  if (!type || joint.type == JointType::kCustom) {
    const std::optional<Value> axes = m.get("axes", type ? Need::kRequired : Need::kOptional);
    if (axes) {
      if (const auto items = read_items(r, *axes)) {
        for (const Value& item : *items) joint.axes.push_back(read_axis(r, item, joint));
        if (type && items->size() != 6) {
          r.report(*axes, "a custom joint has 6 axes (rotation 1..3, then translation 1..3), got " +
                              std::to_string(items->size()));
        } else if (type) {
          for (std::size_t i = 0; i < 6; ++i) {
            if (joint.axes[i].rotation != (i < 3)) {
              r.report((*items)[i], std::string("axis ") + std::to_string(i + 1) + " must be a " +
                                        (i < 3 ? "rotation" : "translation") +
                                        " (rotation 1..3 come first, then translation 1..3)");
            }
          }
        }
      }
    }
  } else {
    m.forbid("axes", "only custom joints have axes (this joint is " +
                         std::string(joint_type_name(joint.type)) + ")");
  }
  m.finish();
  return joint;
}

PathPoint read_point(AtlasReader& r, const Value& v) {
  PathPoint point;
  MapReader m(r, v);
  if (!m.valid()) return point;
  m.text("name", point.name, Need::kOptional);
  refer(r, m, "bone", point.bone, RefKind::kBone, Need::kRequired);
  m.vector3("position", point.position, Need::kRequired);
  if (const auto kind =
          m.choice("kind", names_of(path_point_kinds()), "path point kind", Need::kOptional)) {
    point.kind = path_point_kinds()[*kind].first;
  }
  if (point.kind == PathPointKind::kConditional) {
    refer(r, m, "coordinate", point.coordinate, RefKind::kCoordinate, Need::kRequired);
    m.range("range", point.range, Need::kRequired);
  } else {
    m.forbid("coordinate", "only conditional points have a coordinate");
    m.forbid("range", "only conditional points have a range");
  }
  if (point.kind == PathPointKind::kMoving) {
    if (const std::optional<Value> moving = m.get("moving", Need::kRequired)) {
      MapReader axes(r, *moving);
      if (axes.valid()) {
        for (std::size_t i = 0; i < 3; ++i) {
          const std::optional<Value> axis = axes.get(std::array{"x", "y", "z"}[i], Need::kRequired);
          if (!axis) continue;
          MapReader a(r, *axis);
          if (!a.valid()) continue;
          refer(r, a, "coordinate", point.moving_coordinates[i], RefKind::kCoordinate,
                Need::kOptional);
          if (const std::optional<Value> f = a.get("function", Need::kRequired)) {
            if (auto function = read_function(r, *f)) point.moving_functions[i] = *function;
          }
          a.finish();
        }
      }
      axes.finish();
    }
  } else {
    m.forbid("moving", "only moving points have moving functions");
  }
  m.finish();
  return point;
}

ActionLine read_action_line(AtlasReader& r, const Value& v, const Muscle& muscle) {
  ActionLine line;
  MapReader m(r, v);
  if (!m.valid()) return line;
  if (const std::optional<Value> name = m.name("name", line.name, Need::kRequired)) {
    r.declare("action line", line.name, *name, "muscle '" + muscle.name + "'");
  }
  if (const std::optional<Value> wraps = m.get("wrap_obstacles", Need::kOptional)) {
    std::vector<std::string> own;
    for (const WrapObstacle& obstacle : muscle.wrap_obstacles) own.push_back(obstacle.name);
    if (const auto items = read_items(r, *wraps)) {
      for (const Value& item : *items) {
        std::optional<std::string> name = read_name(r, item);
        if (!name) continue;
        if (std::ranges::find(own, *name) == own.end()) {
          r.report(item, "unknown wrap obstacle '" + *name + "'" +
                             unknown_hint(*name, own, "wrap obstacles of this muscle"));
        }
        line.wrap_obstacles.push_back(std::move(*name));
      }
    }
  }
  if (const std::optional<Value> points = m.get("points", Need::kRequired)) {
    if (const auto items = read_items(r, *points)) {
      for (const Value& item : *items) line.points.push_back(read_point(r, item));
      if (items->size() < 2) {
        r.report(*points, "an action line needs at least 2 points (origin and insertion), got " +
                              std::to_string(items->size()));
      }
    }
  }
  m.finish();
  return line;
}

AttachmentArea read_area(AtlasReader& r, const Value& v) {
  AttachmentArea area;
  MapReader m(r, v);
  if (!m.valid()) return area;
  refer(r, m, "bone", area.bone, RefKind::kBone, Need::kRequired);
  m.amount("area_mm2", area.area_mm2, Need::kOptional);
  m.vector3("centroid", area.centroid, Need::kOptional);
  if (const std::optional<Value> faces = m.get("faces", Need::kRequired)) {
    if (faces->node.IsSequence()) {
      area.faces.reserve(faces->node.size());
      int max_face = -1;
      for (std::size_t i = 0; i < faces->node.size(); ++i) {
        const YAML::Node item = faces->node[i];
        long long index = -1;
        if (item.IsScalar() && item.Tag() != "!" && parse_integer(item.Scalar(), index) &&
            index >= 0 && index <= std::numeric_limits<int>::max()) {
          area.faces.push_back(static_cast<int>(index));
          max_face = std::max(max_face, static_cast<int>(index));
          continue;
        }
        const Value where{item, item.Mark().line >= 0 ? item.Mark() : faces->mark,
                          item_path(faces->path, i)};
        if (item.IsScalar() && item.Tag() != "!" && parse_integer(item.Scalar(), index)) {
          r.report(where, "face index " + item.Scalar() + " is negative or too large");
        } else {
          r.report(where, "expected a face index (an integer), got " + describe(item));
        }
      }
      if (!area.bone.empty()) r.check_faces({area.bone, max_face, faces->mark, faces->path});
    } else {
      r.report(*faces, "expected a list, got " + describe(faces->node));
    }
  }
  m.finish();
  return area;
}

WrapObstacle read_wrap_obstacle(AtlasReader& r, const Value& v, const std::string& scope) {
  WrapObstacle obstacle;
  MapReader m(r, v);
  if (!m.valid()) return obstacle;
  if (const std::optional<Value> name = m.name("name", obstacle.name, Need::kRequired)) {
    r.declare("wrap obstacle", obstacle.name, *name, scope);
  }
  const std::vector<std::string> shapes = wrap_shape_names();
  const std::optional<std::size_t> shape =
      m.choice("shape", shapes, "wrap obstacle shape", Need::kRequired);
  if (shape) obstacle.shape = *wrap_shape_from_name(shapes[*shape]);
  refer(r, m, "bone", obstacle.bone, RefKind::kBone, Need::kRequired);
  read_frame_field(r, m, "pose", obstacle.pose);
  if (const std::optional<Value> radii = m.vector3("radii", obstacle.radii, Need::kRequired)) {
    const Eigen::Vector3d& d = obstacle.radii;
    if (d.minCoeff() < 0) {
      r.report(*radii, "radii must not be negative");
    } else if (shape) {
      const bool ok = obstacle.shape == WrapShape::kSphere     ? d.x() > 0
                      : obstacle.shape == WrapShape::kCylinder ? d.x() > 0 && d.z() > 0
                                                               : d.minCoeff() > 0;
      if (!ok) {
        r.report(*radii, obstacle.shape == WrapShape::kSphere ? "a sphere needs radius x > 0"
                         : obstacle.shape == WrapShape::kCylinder
                             ? "a cylinder needs radius x > 0 and length z > 0"
                             : "an ellipsoid needs three positive semi-axes");
      }
    }
  }
  if (const auto quadrant = m.choice("quadrant", kQuadrants, "quadrant", Need::kOptional)) {
    obstacle.quadrant = kQuadrants[*quadrant];
  }
  m.finish();
  return obstacle;
}

Muscle read_muscle(AtlasReader& r, const Value& v) {
  Muscle muscle;
  MapReader m(r, v);
  if (!m.valid()) return muscle;
  if (const std::optional<Value> name = m.name("name", muscle.name, Need::kRequired)) {
    r.declare("muscle", muscle.name, *name);
  }
  m.texts("tags", muscle.tags, Need::kOptional);
  muscle.meshes = read_mesh_levels(r, m);
  const std::vector<std::string> architectures = architecture_names();
  if (const auto architecture =
          m.choice("architecture", architectures, "fibre architecture", Need::kOptional)) {
    muscle.architecture = *fibre_architecture_from_name(architectures[*architecture]);
  }
  m.amount("max_isometric_force_n", muscle.max_isometric_force_n, Need::kOptional);
  m.amount("optimal_fibre_length_mm", muscle.optimal_fibre_length_mm, Need::kOptional);
  m.amount("tendon_slack_length_mm", muscle.tendon_slack_length_mm, Need::kOptional);
  if (const auto pennation =
          m.amount("pennation_angle_rad", muscle.pennation_angle_rad, Need::kOptional)) {
    if (muscle.pennation_angle_rad >= std::numbers::pi / 2) {
      r.report(*pennation, "a pennation angle is below pi/2 rad, got " +
                               number_text(muscle.pennation_angle_rad));
    }
  }
  // Wrap obstacles first: the action lines name them.
  const std::string scope = "muscle '" + muscle.name + "'";
  read_list(r, m, "wrap_obstacles", muscle.wrap_obstacles, Need::kOptional,
            [&](const Value& item) { return read_wrap_obstacle(r, item, scope); });
  read_list(r, m, "action_lines", muscle.action_lines, Need::kOptional,
            [&](const Value& item) { return read_action_line(r, item, muscle); });
  read_list(r, m, "origins", muscle.origins, Need::kOptional,
            [&](const Value& item) { return read_area(r, item); });
  read_list(r, m, "insertions", muscle.insertions, Need::kOptional,
            [&](const Value& item) { return read_area(r, item); });
  m.finish();
  return muscle;
}

Structure read_structure(AtlasReader& r, const Value& v) {
  Structure structure;
  MapReader m(r, v);
  if (!m.valid()) return structure;
  if (const std::optional<Value> name = m.name("name", structure.name, Need::kRequired)) {
    r.declare("structure", structure.name, *name);
  }
  const std::vector<std::string> kinds = {"cartilage", "ligament"};
  const auto kind = m.choice("kind", kinds, "structure kind", Need::kRequired);
  if (kind) structure.kind = *structure_kind_from_name(kinds[*kind]);
  m.texts("tags", structure.tags, Need::kOptional);
  const std::optional<Value> bones = m.get("bones", Need::kRequired);
  refer_all(r, m, "bones", structure.bones, RefKind::kBone);
  if (bones && kind) {
    const std::size_t wanted = structure.kind == StructureKind::kCartilage ? 1 : 2;
    if (structure.bones.size() != wanted) {
      r.report(*bones, structure.kind == StructureKind::kCartilage
                           ? "a cartilage names the one bone it covers"
                           : "a ligament names the two bones it joins, [from, to]");
    } else if (wanted == 2 && structure.bones[0] == structure.bones[1]) {
      r.report(*bones, "a ligament joins two different bones");
    }
  }
  structure.meshes = read_mesh_levels(r, m);
  m.finish();
  return structure;
}

Landmark read_landmark(AtlasReader& r, const Value& v) {
  Landmark landmark;
  MapReader m(r, v);
  if (!m.valid()) return landmark;
  if (const std::optional<Value> name = m.name("name", landmark.name, Need::kRequired)) {
    r.declare("landmark", landmark.name, *name);
  }
  refer(r, m, "bone", landmark.bone, RefKind::kBone, Need::kRequired);
  m.vector3("position", landmark.position, Need::kRequired);
  m.texts("tags", landmark.tags, Need::kOptional);
  m.text("description", landmark.description, Need::kOptional);
  m.finish();
  return landmark;
}

Marker read_marker(AtlasReader& r, const Value& v) {
  Marker marker;
  MapReader m(r, v);
  if (!m.valid()) return marker;
  if (const std::optional<Value> name = m.name("name", marker.name, Need::kRequired)) {
    r.declare("marker", marker.name, *name);
  }
  refer(r, m, "bone", marker.bone, RefKind::kBone, Need::kRequired);
  m.vector3("position", marker.position, Need::kRequired);
  m.boolean("fixed", marker.fixed, Need::kOptional);
  m.finish();
  return marker;
}

// Parent joints and joint children must agree: bone B names joint J as its
// parent_joint exactly when J's child is B.
void check_tree(AtlasReader& r, const Atlas& atlas, const std::vector<Value>& bone_items,
                const std::vector<Value>& joint_items) {
  for (std::size_t i = 0; i < atlas.bones.size() && i < bone_items.size(); ++i) {
    const Bone& bone = atlas.bones[i];
    if (bone.parent_joint.empty()) continue;
    const Joint* joint = atlas.find_joint(bone.parent_joint);
    if (joint != nullptr && !joint->child.empty() && joint->child != bone.name) {
      r.report(
          bone_items[i].node["parent_joint"].Mark(), bone_items[i].path + ".parent_joint",
          "joint '" + joint->name + "' moves bone '" + joint->child + "', not '" + bone.name + "'");
    }
  }
  for (std::size_t i = 0; i < atlas.joints.size() && i < joint_items.size(); ++i) {
    const Joint& joint = atlas.joints[i];
    const Bone* child = atlas.find_bone(joint.child);
    if (child != nullptr && child->parent_joint.empty()) {
      r.report(joint_items[i].node["child"].Mark(), joint_items[i].path + ".child",
               "bone '" + child->name +
                   "' has no parent_joint, but this joint moves it (set its "
                   "parent_joint to '" +
                   joint.name + "')");
    }
  }
}

// Reads the manifest text into `atlas`; returns the problems (empty: valid).
std::vector<Problem> parse_manifest(const std::string& text, Atlas& atlas) {
  AtlasReader r;
  YAML::Node root;
  try {
    const std::vector<YAML::Node> documents = load_all_yaml(text);
    if (documents.size() > 1) {
      r.report(documents[1].Mark(), "top level",
               "holds " + std::to_string(documents.size()) +
                   " YAML documents; an atlas manifest is one");
      return r.problems();
    }
    if (!documents.empty()) root = documents.front();
  } catch (const YAML::ParserException& e) {
    r.report(e.mark, "top level", "malformed YAML: " + e.msg);
    return r.problems();
  }
  const Value top{root, root.Mark(), ""};
  if (!root.IsDefined() || root.IsNull()) {
    r.report(YAML::Mark::null_mark(), "top level",
             "the manifest is empty (expected a mapping with keys "
             "mmm_atlas, name, bones, joints, muscles, ...)");
    return r.problems();
  }
  MapReader m(r, top);
  if (!m.valid()) return r.problems();

  // The format version first: a manifest of another version is not read further.
  int format = 0;
  const std::optional<Value> version = m.get("mmm_atlas", Need::kOptional);
  if (!version) {
    r.report(top,
             "missing required key 'mmm_atlas' (the atlas format version; this program "
             "reads version " +
                 std::to_string(kAtlasFormat) + ")");
    return r.problems();
  }
  if (const std::optional<int> v = read_integer(r, *version)) format = *v;
  if (format != kAtlasFormat) {
    if (!r.problems().empty()) return r.problems();
    r.report(*version, "atlas format version " + std::to_string(format) +
                           " is not supported (this program reads version " +
                           std::to_string(kAtlasFormat) + ")");
    return r.problems();
  }

  m.name("name", atlas.name, Need::kRequired);
  m.text("description", atlas.description, Need::kOptional);
  m.text("frame_description", atlas.frame_description, Need::kOptional);
  if (const std::optional<Value> v = m.get("provenance", Need::kOptional)) {
    if (const auto items = read_items(r, *v)) {
      for (const Value& item : *items) {
        if (auto line = read_text(r, item)) atlas.provenance.push_back(std::move(*line));
      }
    }
  }
  std::vector<Value> bone_items;
  std::vector<Value> joint_items;
  read_list(r, m, "regions", atlas.regions, Need::kOptional,
            [&](const Value& item) { return read_region(r, item); });
  read_list(r, m, "bones", atlas.bones, Need::kOptional, [&](const Value& item) {
    bone_items.push_back(item);
    return read_bone(r, item);
  });
  read_list(r, m, "joints", atlas.joints, Need::kOptional, [&](const Value& item) {
    joint_items.push_back(item);
    return read_joint(r, item);
  });
  read_list(r, m, "muscles", atlas.muscles, Need::kOptional,
            [&](const Value& item) { return read_muscle(r, item); });
  std::vector<Value> structure_items;
  read_list(r, m, "structures", atlas.structures, Need::kOptional, [&](const Value& item) {
    structure_items.push_back(item);
    return read_structure(r, item);
  });
  read_list(r, m, "landmarks", atlas.landmarks, Need::kOptional,
            [&](const Value& item) { return read_landmark(r, item); });
  read_list(r, m, "markers", atlas.markers, Need::kOptional,
            [&](const Value& item) { return read_marker(r, item); });
  m.finish();
  r.resolve(atlas);
  check_tree(r, atlas, bone_items, joint_items);
  // Meshes are kept per element name: a structure is named unlike any bone or muscle.
  for (std::size_t i = 0; i < atlas.structures.size() && i < structure_items.size(); ++i) {
    const std::string& name = atlas.structures[i].name;
    if (atlas.find_bone(name) != nullptr || atlas.find_muscle(name) != nullptr) {
      r.report(structure_items[i].node["name"].Mark(), structure_items[i].path + ".name",
               "'" + name + "' is already the name of a bone or muscle");
    }
  }
  return r.problems();
}

// The IoError message for a list of problems.
std::string problems_text(const std::vector<Problem>& problems) {
  if (problems.size() == 1) return problems.front().text();
  std::string out = std::to_string(problems.size()) + " problems:";
  for (const Problem& problem : problems) out += "\n  " + problem.text();
  return out;
}

}  // namespace

void write_atlas_manifest(const Atlas& atlas, const std::filesystem::path& dir) {
  const fs::path file = dir / kManifestFile;
  if (!fs::is_directory(dir)) throw IoError(file, "cannot write: no such folder");
  const std::string text = ManifestWriter().write(atlas);
  // Never write a manifest that read_atlas would reject.
  Atlas check;
  const std::vector<Problem> problems = parse_manifest(text, check);
  if (!problems.empty()) {
    throw IoError(file, "not written, the atlas is invalid: " + problems_text(problems));
  }
  fs::path temporary = file;
  temporary += ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(file, "cannot write (cannot create " + temporary.string() + ")");
    out << text;
    out.close();
    if (!out) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw IoError(file, "cannot write (write failed)");
    }
  }
  std::error_code error;
  fs::rename(temporary, file, error);
  if (error) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw IoError(file, "cannot write: " + error.message());
  }
}

Atlas read_atlas(const std::filesystem::path& dir) {
  const fs::path file = dir / kManifestFile;
  std::error_code error;
  if (!fs::exists(file, error)) {
    throw IoError(file, fs::is_directory(dir, error)
                            ? "no such file (an atlas folder holds atlas.yaml beside its meshes)"
                            : "no such file (the atlas folder does not exist)");
  }
  if (fs::is_directory(file, error)) throw IoError(file, "is a directory, not an atlas manifest");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot read");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  Atlas atlas;
  const std::vector<Problem> problems = parse_manifest(text, atlas);
  if (!problems.empty()) throw IoError(file, problems_text(problems));
  return atlas;
}

mesh::IndexedMesh load_mesh(const std::filesystem::path& dir, const std::vector<MeshLevel>& meshes,
                            const std::string& level) {
  const std::string wanted = level.empty() ? "full" : level;
  const auto it = std::ranges::find(meshes, wanted, &MeshLevel::level);
  if (it == meshes.end()) {
    std::vector<std::string> levels;
    levels.reserve(meshes.size());
    for (const MeshLevel& m : meshes) levels.push_back(m.level);
    throw IoError(dir / kManifestFile,
                  "no mesh level '" + wanted + "' (levels: " + join_names(levels) + ")");
  }
  const fs::path file = dir / it->file;
  mesh::IndexedMesh surface = mesh::read_mesh(file);
  if (it->faces > 0 && surface.num_faces() != it->faces) {
    throw IoError(file, "has " + std::to_string(surface.num_faces()) +
                            " triangles, but the atlas manifest says " + std::to_string(it->faces) +
                            " (level '" + wanted + "')");
  }
  return surface;
}

}  // namespace mmm::atlas
