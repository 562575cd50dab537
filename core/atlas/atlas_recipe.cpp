#include "core/atlas/atlas_recipe.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "core/bounded_yaml.h"
#include "core/errors.h"

namespace mmm::atlas {
namespace {

// Reading context: the file and the path of the current field, for messages.
class RecipeReader {
 public:
  explicit RecipeReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field,
                         const std::string& problem) const {
    std::ostringstream message;
    if (node.IsDefined() && node.Mark().line >= 0) {
      message << "line " << node.Mark().line + 1 << ":" << node.Mark().column + 1 << ": ";
    }
    message << field << ": " << problem;
    throw IoError(file_, message.str());
  }

  [[nodiscard]] YAML::Node required(const YAML::Node& map, const std::string& key,
                                    const std::string& field) const {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) fail(map, field + "." + key, "is required");
    return value;
  }

  [[nodiscard]] std::string text(const YAML::Node& map, const std::string& key,
                                 const std::string& field, bool needed = false) const {
    const YAML::Node value = needed ? required(map, key, field) : map[key];
    if (!value.IsDefined() || value.IsNull()) return {};
    if (!value.IsScalar()) fail(value, field + "." + key, "expects a string");
    return value.as<std::string>();
  }

  [[nodiscard]] double number(const YAML::Node& map, const std::string& key,
                              const std::string& field, double fallback, double low,
                              double high) const {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) return fallback;
    double result = 0;
    if (!value.IsScalar() || !YAML::convert<double>::decode(value, result) ||
        !std::isfinite(result)) {
      fail(value, field + "." + key, "expects a finite number, got '" + value.Scalar() + "'");
    }
    if (result < low || result > high) {
      std::ostringstream range;
      range << "is " << result << ", outside [" << low << ", " << high << "]";
      fail(value, field + "." + key, range.str());
    }
    return result;
  }

  [[nodiscard]] bool flag(const YAML::Node& map, const std::string& key, const std::string& field,
                          bool fallback) const {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) return fallback;
    bool result = false;
    if (!value.IsScalar() || !YAML::convert<bool>::decode(value, result)) {
      fail(value, field + "." + key, "expects true or false");
    }
    return result;
  }

  [[nodiscard]] std::vector<std::string> texts(const YAML::Node& map, const std::string& key,
                                               const std::string& field) const {
    const YAML::Node value = map[key];
    std::vector<std::string> result;
    if (!value.IsDefined() || value.IsNull()) return result;
    if (!value.IsSequence()) fail(value, field + "." + key, "expects a list of strings");
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (!value[i].IsScalar()) {
        std::string item = field;
        item += '.';
        item += key;
        item += '[';
        item += std::to_string(i);
        item += ']';
        fail(value[i], item, "expects a string");
      }
      result.push_back(value[i].as<std::string>());
    }
    return result;
  }

  // The items of a list field, each a mapping whose keys are all in `known`.
  [[nodiscard]] std::vector<YAML::Node> items(const YAML::Node& map, const std::string& key,
                                              const std::set<std::string>& known) const {
    const YAML::Node value = map[key];
    std::vector<YAML::Node> result;
    if (!value.IsDefined() || value.IsNull()) return result;
    if (!value.IsSequence()) fail(value, key, "expects a list");
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string field = key + "[" + std::to_string(i) + "]";
      if (!value[i].IsMap()) fail(value[i], field, "expects a mapping");
      check_keys(value[i], field, known);
      result.push_back(value[i]);
    }
    return result;
  }

  void check_keys(const YAML::Node& map, const std::string& field,
                  const std::set<std::string>& known) const {
    for (const auto& entry : map) {
      const auto name = entry.first.as<std::string>();
      if (!known.contains(name)) {
        std::string list;
        for (const std::string& k : known) {
          if (!list.empty()) list += ", ";
          list += k;
        }
        std::string message = "unknown field (expected one of: ";
        message += list;
        message += ')';
        std::string where = field;
        where += '.';
        where += name;
        fail(entry.first, where, message);
      }
    }
  }

 private:
  std::filesystem::path file_;
};

template <class T>
void check_unique(const RecipeReader& reader, const YAML::Node& root, const std::string& key,
                  const std::vector<T>& items) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!seen.insert(items[i].name).second) {
      reader.fail(root[key][i], key + "[" + std::to_string(i) + "].name",
                  "duplicate name '" + items[i].name + "'");
    }
  }
}

// Sides a wrap surface may name: atlas directions.
const std::set<std::string> kWrapSides{"anterior", "posterior", "superior",
                                       "inferior", "right",     "left"};

void read_wrap_surfaces(const RecipeReader& reader, const YAML::Node& root, AtlasRecipe& recipe) {
  std::set<std::string> lines;
  for (const RecipeMuscle& muscle : recipe.muscles) {
    lines.insert(muscle.action_lines.begin(), muscle.action_lines.end());
    if (!muscle.surface_line.empty()) lines.insert(muscle.name);
  }
  int index = 0;
  for (const YAML::Node& item :
       reader.items(root, "wrap_surfaces",
                    {"name", "bone", "shape", "around_joint", "around_point", "radius_mm", "side",
                     "axis_of_joint", "lines", "replaces", "clearance_mm", "offset_mm"})) {
    const std::string field = "wrap_surfaces[" + std::to_string(index++) + "]";
    RecipeWrapSurface surface;
    surface.name = reader.text(item, "name", field, true);
    surface.bone = reader.text(item, "bone", field, true);
    if (std::ranges::none_of(recipe.bones,
                             [&](const RecipeBone& bone) { return bone.name == surface.bone; })) {
      reader.fail(item["bone"], field + ".bone", "unknown bone '" + surface.bone + "'");
    }
    const std::string shape = reader.text(item, "shape", field, true);
    const auto parsed = wrap_shape_from_name(shape);
    if (!parsed) {
      reader.fail(item["shape"], field + ".shape",
                  "unknown shape '" + shape + "' (expected sphere, cylinder or ellipsoid)");
    }
    surface.shape = *parsed;
    surface.around_joint = reader.text(item, "around_joint", field);
    surface.around_point = reader.text(item, "around_point", field);
    if (surface.around_joint.empty() == surface.around_point.empty()) {
      reader.fail(item, field, "names its region's centre by around_joint or around_point (one)");
    }
    surface.radius_mm = reader.number(item, "radius_mm", field, 30.0, 5.0, 200.0);
    surface.side = reader.text(item, "side", field);
    if (!surface.side.empty() && !kWrapSides.contains(surface.side)) {
      reader.fail(item["side"], field + ".side",
                  "unknown side '" + surface.side +
                      "' (expected anterior, posterior, superior, inferior, right or left)");
    }
    surface.axis_of_joint = reader.text(item, "axis_of_joint", field);
    if (!surface.axis_of_joint.empty() && surface.shape != WrapShape::kCylinder) {
      reader.fail(item["axis_of_joint"], field + ".axis_of_joint", "is for cylinders only");
    }
    surface.lines = reader.texts(item, "lines", field);
    if (surface.lines.empty()) reader.fail(item, field + ".lines", "names at least one line");
    for (const std::string& line : surface.lines) {
      if (!lines.contains(line)) {
        reader.fail(item["lines"], field + ".lines",
                    "'" + line + "' is not an action line of any muscle of the recipe");
      }
    }
    surface.replaces = reader.texts(item, "replaces", field);
    surface.clearance_mm = reader.number(item, "clearance_mm", field, 2.0, 0.0, 20.0);
    surface.offset_mm = reader.number(item, "offset_mm", field, 0.0, 0.0, 50.0);
    recipe.wrap_surfaces.push_back(std::move(surface));
  }
  check_unique(reader, root, "wrap_surfaces", recipe.wrap_surfaces);
}

}  // namespace

AtlasRecipe read_atlas_recipe(const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = load_yaml_file(file);
  } catch (const YAML::BadFile&) {
    throw IoError(file, "cannot open the recipe (check the path)");
  } catch (const YAML::Exception& error) {
    throw IoError(file,
                  "line " + std::to_string(error.mark.line + 1) + ": malformed YAML: " + error.msg);
  }
  const RecipeReader reader(file);
  if (!root.IsMap()) reader.fail(root, "(top)", "expects a mapping holding mmm_atlas_recipe: 1");
  reader.check_keys(
      root, "(top)",
      {"mmm_atlas_recipe", "name", "description", "frame", "opensim", "midline", "lod_faces",
       "penetration_tolerance_mm", "attachment_distance_mm", "attachment_radius_mm", "regions",
       "bones", "registration", "muscles", "structures", "landmarks", "wrap_surfaces"});
  AtlasRecipe recipe;
  recipe.source = file;
  const double format = reader.number(root, "mmm_atlas_recipe", "(top)", -1, -1e9, 1e9);
  if (format != kRecipeFormat) {
    reader.fail(root["mmm_atlas_recipe"], "mmm_atlas_recipe",
                "this mmm reads recipe format " + std::to_string(kRecipeFormat) +
                    " (write `mmm_atlas_recipe: 1` at the top)");
  }
  recipe.name = reader.text(root, "name", "(top)", true);
  recipe.description = reader.text(root, "description", "(top)");
  recipe.frame_description = reader.text(root, "frame", "(top)");
  const YAML::Node opensim = reader.required(root, "opensim", "(top)");
  reader.check_keys(opensim, "opensim", {"model", "geometry", "marker_set"});
  recipe.opensim.model = reader.text(opensim, "model", "opensim", true);
  recipe.opensim.geometry = reader.text(opensim, "geometry", "opensim", true);
  recipe.opensim.marker_set = reader.text(opensim, "marker_set", "opensim");
  recipe.midline_bone = reader.text(root, "midline", "(top)", true);
  if (const YAML::Node lods = root["lod_faces"]; lods.IsDefined()) {
    if (!lods.IsSequence()) reader.fail(lods, "lod_faces", "expects a list of face counts");
    for (std::size_t i = 0; i < lods.size(); ++i) {
      double faces = 0;
      if (!YAML::convert<double>::decode(lods[i], faces) || faces < 100 || faces > 1e7 ||
          faces != std::floor(faces)) {
        reader.fail(lods[i], "lod_faces[" + std::to_string(i) + "]",
                    "expects a whole number of faces in [100, 1e7]");
      }
      if (!recipe.lod_faces.empty() && faces >= recipe.lod_faces.back()) {
        reader.fail(lods[i], "lod_faces[" + std::to_string(i) + "]",
                    "levels must get coarser (decreasing face counts)");
      }
      recipe.lod_faces.push_back(static_cast<int>(faces));
    }
  }
  recipe.penetration_tolerance_mm =
      reader.number(root, "penetration_tolerance_mm", "(top)", 0.5, 0.0, 5.0);
  recipe.attachment_distance_mm =
      reader.number(root, "attachment_distance_mm", "(top)", 3.0, 0.1, 20.0);
  recipe.attachment_radius_mm =
      reader.number(root, "attachment_radius_mm", "(top)", 30.0, 1.0, 200.0);

  for (const YAML::Node& item : reader.items(root, "regions", {"name", "tags"})) {
    recipe.regions.push_back(
        {reader.text(item, "name", "regions[]", true), reader.texts(item, "tags", "regions[]")});
  }
  check_unique(reader, root, "regions", recipe.regions);

  std::set<std::string> region_names;
  for (const RecipeRegion& region : recipe.regions) region_names.insert(region.name);
  const auto check_region = [&](const YAML::Node& item, const std::string& field,
                                const std::string& region) {
    if (!region.empty() && !region_names.contains(region)) {
      reader.fail(item["region"], field + ".region",
                  "unknown region '" + region + "' (declare it under regions:)");
    }
  };

  int index = 0;
  for (const YAML::Node& item : reader.items(root, "bones",
                                             {"name", "body", "file", "mirror", "opensim_meshes",
                                              "remesh_edge_mm", "region", "tags"})) {
    const std::string field = "bones[" + std::to_string(index++) + "]";
    RecipeBone bone;
    bone.name = reader.text(item, "name", field, true);
    bone.body = reader.text(item, "body", field, true);
    bone.file = reader.text(item, "file", field);
    bone.mirror = reader.flag(item, "mirror", field, false);
    bone.opensim_meshes = reader.texts(item, "opensim_meshes", field);
    bone.remesh_edge_mm = reader.number(item, "remesh_edge_mm", field, 0.0, 0.0, 50.0);
    bone.region = reader.text(item, "region", field);
    bone.tags = reader.texts(item, "tags", field);
    if (bone.file.empty() == bone.opensim_meshes.empty()) {
      reader.fail(item, field,
                  "give either `file` (a surface in the atlas frame) or "
                  "`opensim_meshes` (meshes of the OpenSim body), not both or none");
    }
    check_region(item, field, bone.region);
    recipe.bones.push_back(std::move(bone));
  }
  check_unique(reader, root, "bones", recipe.bones);
  const auto has_bone = [&](const std::string& name) {
    return std::ranges::any_of(recipe.bones,
                               [&](const RecipeBone& bone) { return bone.name == name; });
  };
  if (!has_bone(recipe.midline_bone)) {
    reader.fail(root["midline"], "midline", "unknown bone '" + recipe.midline_bone + "'");
  }

  const YAML::Node registration = root["registration"];
  if (!registration.IsMap()) {
    reader.fail(root, "registration", "expects a mapping: OpenSim body -> {method, ...}");
  }
  for (const auto& entry : registration) {
    RecipeRegistration reg;
    reg.body = entry.first.as<std::string>();
    const std::string field = "registration." + reg.body;
    const YAML::Node& spec = entry.second;
    if (!spec.IsMap()) reader.fail(spec, field, "expects a mapping {method: ...}");
    reader.check_keys(spec, field,
                      {"method", "meshes", "targets", "joint_anchor", "joint", "head", "condyles",
                       "acetabulum", "sacrum", "follow", "anisotropic"});
    reg.method = reader.text(spec, "method", field, true);
    reg.meshes = reader.texts(spec, "meshes", field);
    reg.targets = reader.texts(spec, "targets", field);
    reg.joint_anchor = reader.text(spec, "joint_anchor", field);
    reg.joint = reader.text(spec, "joint", field);
    reg.head = reader.text(spec, "head", field);
    reg.condyles = reader.text(spec, "condyles", field);
    reg.acetabulum = reader.text(spec, "acetabulum", field);
    reg.sacrum = reader.text(spec, "sacrum", field);
    reg.follow = reader.text(spec, "follow", field);
    reg.anisotropic = reader.flag(spec, "anisotropic", field, true);
    const auto need = [&](const std::string& value, const char* key) {
      if (value.empty())
        reader.fail(spec, field + "." + key, "is required by method " + reg.method);
    };
    if (reg.method != "follow" && reg.meshes.empty()) {
      reader.fail(spec, field + ".meshes",
                  "is required by method " + reg.method + " (the OpenSim meshes to fit)");
    }
    if (reg.method == "surface" || reg.method == "joint") {
      if (reg.method == "joint") need(reg.joint, "joint");
      if (reg.targets.empty())
        reader.fail(spec, field + ".targets", "is required by method surface");
      for (const std::string& target : reg.targets) {
        if (!has_bone(target)) {
          reader.fail(spec["targets"], field + ".targets", "unknown bone '" + target + "'");
        }
      }
    } else if (reg.method == "head_and_condyles") {
      need(reg.head, "head");
      need(reg.condyles, "condyles");
    } else if (reg.method == "hip_and_sacrum") {
      need(reg.acetabulum, "acetabulum");
      need(reg.sacrum, "sacrum");
      if (!has_bone(reg.sacrum)) reader.fail(spec["sacrum"], field + ".sacrum", "unknown bone");
    } else if (reg.method == "follow") {
      need(reg.follow, "follow");
    } else {
      reader.fail(spec["method"], field + ".method",
                  "unknown method '" + reg.method +
                      "' (expected surface, joint, head_and_condyles, hip_and_sacrum or follow)");
    }
    recipe.registrations.push_back(std::move(reg));
  }
  for (std::size_t i = 0; i < recipe.bones.size(); ++i) {
    const std::string& body = recipe.bones[i].body;
    if (std::ranges::none_of(recipe.registrations,
                             [&](const RecipeRegistration& r) { return r.body == body; })) {
      reader.fail(root["bones"][i]["body"], "bones[" + std::to_string(i) + "].body",
                  "body '" + body + "' has no entry under registration:");
    }
  }

  index = 0;
  for (const YAML::Node& item : reader.items(root, "muscles",
                                             {"name", "file", "mirror", "action_lines",
                                              "surface_line", "architecture", "region", "tags"})) {
    const std::string field = "muscles[" + std::to_string(index++) + "]";
    RecipeMuscle muscle;
    muscle.name = reader.text(item, "name", field, true);
    muscle.file = reader.text(item, "file", field, true);
    muscle.mirror = reader.flag(item, "mirror", field, false);
    muscle.action_lines = reader.texts(item, "action_lines", field);
    muscle.surface_line = reader.texts(item, "surface_line", field);
    if (!muscle.surface_line.empty()) {
      if (muscle.surface_line.size() != 2) {
        reader.fail(item["surface_line"], field + ".surface_line",
                    "expects two bones: [origin bone, insertion bone]");
      }
      for (const std::string& bone : muscle.surface_line) {
        if (!has_bone(bone)) {
          reader.fail(item["surface_line"], field + ".surface_line", "unknown bone '" + bone + "'");
        }
      }
      if (!muscle.action_lines.empty()) {
        reader.fail(item["surface_line"], field + ".surface_line",
                    "a muscle has either action_lines (OpenSim paths) or a surface_line");
      }
    }
    const std::string architecture = reader.text(item, "architecture", field);
    if (!architecture.empty()) {
      const auto parsed = fibre_architecture_from_name(architecture);
      if (!parsed) {
        reader.fail(item["architecture"], field + ".architecture",
                    "unknown architecture '" + architecture +
                        "' (expected parallel, pennate, fanned or curved)");
      }
      muscle.architecture = *parsed;
    }
    muscle.region = reader.text(item, "region", field);
    muscle.tags = reader.texts(item, "tags", field);
    check_region(item, field, muscle.region);
    recipe.muscles.push_back(std::move(muscle));
  }
  check_unique(reader, root, "muscles", recipe.muscles);

  index = 0;
  for (const YAML::Node& item :
       reader.items(root, "structures",
                    {"name", "kind", "file", "bones", "region", "tags", "muscle_ends_clear_mm"})) {
    const std::string field = "structures[" + std::to_string(index++) + "]";
    RecipeStructure structure;
    structure.name = reader.text(item, "name", field, true);
    const std::string kind = reader.text(item, "kind", field, true);
    const auto parsed = structure_kind_from_name(kind);
    if (!parsed) {
      reader.fail(item["kind"], field + ".kind",
                  "unknown kind '" + kind + "' (expected cartilage or ligament)");
    }
    structure.kind = *parsed;
    structure.file = reader.text(item, "file", field, true);
    structure.bones = reader.texts(item, "bones", field);
    const std::size_t wanted = structure.kind == StructureKind::kCartilage ? 1 : 2;
    if (structure.bones.size() != wanted ||
        (wanted == 2 && structure.bones[0] == structure.bones[1])) {
      reader.fail(item["bones"].IsDefined() ? item["bones"] : item, field + ".bones",
                  wanted == 1 ? "a cartilage names the one bone it covers: [bone]"
                              : "a ligament names the two different bones it joins: [from, to]");
    }
    for (const std::string& bone : structure.bones) {
      if (!has_bone(bone)) {
        reader.fail(item["bones"], field + ".bones", "unknown bone '" + bone + "'");
      }
    }
    const auto clashes = [&](const auto& list) {
      return std::ranges::any_of(list, [&](const auto& e) { return e.name == structure.name; });
    };
    if (clashes(recipe.bones) || clashes(recipe.muscles)) {
      reader.fail(item["name"], field + ".name",
                  "'" + structure.name + "' is already the name of a bone or muscle");
    }
    structure.region = reader.text(item, "region", field);
    structure.tags = reader.texts(item, "tags", field);
    structure.muscle_ends_clear_mm =
        reader.number(item, "muscle_ends_clear_mm", field, 0.0, 0.0, 20.0);
    if (structure.muscle_ends_clear_mm > 0 && structure.kind != StructureKind::kCartilage) {
      reader.fail(item["muscle_ends_clear_mm"], field + ".muscle_ends_clear_mm",
                  "is for cartilages only");
    }
    check_region(item, field, structure.region);
    recipe.structures.push_back(std::move(structure));
  }
  check_unique(reader, root, "structures", recipe.structures);

  index = 0;
  for (const YAML::Node& item :
       reader.items(root, "landmarks",
                    {"name", "bone", "method", "file", "joint", "marker", "tags", "description"})) {
    const std::string field = "landmarks[" + std::to_string(index++) + "]";
    RecipeLandmark landmark;
    landmark.name = reader.text(item, "name", field, true);
    landmark.bone = reader.text(item, "bone", field, true);
    landmark.method = reader.text(item, "method", field, true);
    landmark.file = reader.text(item, "file", field);
    landmark.joint = reader.text(item, "joint", field);
    landmark.marker = reader.text(item, "marker", field);
    landmark.tags = reader.texts(item, "tags", field);
    landmark.description = reader.text(item, "description", field);
    if (!has_bone(landmark.bone)) {
      reader.fail(item["bone"], field + ".bone", "unknown bone '" + landmark.bone + "'");
    }
    const std::set<std::string> methods{"sphere_centre", "centroid", "joint_centre",
                                        "marker_on_bone"};
    if (!methods.contains(landmark.method)) {
      reader.fail(item["method"], field + ".method",
                  "unknown method '" + landmark.method +
                      "' (expected sphere_centre, centroid, joint_centre or marker_on_bone)");
    }
    if (landmark.method == "sphere_centre" && landmark.file.empty()) {
      reader.fail(item, field + ".file", "is required by sphere_centre");
    }
    if (landmark.method == "joint_centre" && landmark.joint.empty()) {
      reader.fail(item, field + ".joint", "is required by joint_centre");
    }
    if (landmark.method == "marker_on_bone" && landmark.marker.empty()) {
      reader.fail(item, field + ".marker", "is required by marker_on_bone");
    }
    recipe.landmarks.push_back(std::move(landmark));
  }
  check_unique(reader, root, "landmarks", recipe.landmarks);
  read_wrap_surfaces(reader, root, recipe);
  return recipe;
}

}  // namespace mmm::atlas
