// mmm atlas build|check: the command-line face of core/atlas.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands/commands.h"
#include "core/atlas/atlas_builder.h"
#include "core/atlas/atlas_check.h"
#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_recipe.h"
#include "core/image/mesh_render.h"
#include "core/image/png.h"
#include "core/landmarks/landmark_labels.h"

namespace mmm::app {
namespace {

struct BuildArgs {
  std::string recipe;
  std::string out;
  std::string data = MMM_DEFAULT_DATA_DIR;
  bool json = false;
};

nlohmann::json build_json(const atlas::AtlasBuildReport& report) {
  nlohmann::json json;
  json["seconds"] = report.seconds;
  nlohmann::json registrations = nlohmann::json::array();
  for (const atlas::BodyRegistrationReport& r : report.registrations) {
    nlohmann::json anchors = nlohmann::json::object();
    for (const auto& [name, residual] : r.anchor_residuals_mm) anchors[name] = residual;
    registrations.push_back({{"body", r.body},
                             {"method", r.method},
                             {"scale", r.scale},
                             {"surface_rms_mm", r.rms_mm},
                             {"surface_mean_mm", r.mean_distance_mm},
                             {"surface_pairs", r.pairs},
                             {"anchor_residuals_mm", anchors}});
  }
  json["registrations"] = registrations;
  nlohmann::json joints = nlohmann::json::array();
  for (const atlas::JointBuildReport& j : report.joints) {
    nlohmann::json rest = nlohmann::json::object();
    for (const auto& [name, value] : j.rest_values) rest[name] = value;
    joints.push_back({{"joint", j.name},
                      {"rest_values", rest},
                      {"frame_mismatch_mm", j.frame_mismatch_mm},
                      {"frame_mismatch_deg", j.frame_mismatch_deg}});
  }
  json["joints"] = joints;
  nlohmann::json muscles = nlohmann::json::array();
  for (const atlas::MuscleBuildReport& m : report.muscles) {
    muscles.push_back({{"name", m.name},
                       {"faces", m.faces},
                       {"volume_mm3", m.volume_mm3},
                       {"max_penetration_before_mm", m.max_penetration_before_mm},
                       {"vertices_moved", m.vertices_moved},
                       {"volume_change_percent", m.volume_change_percent}});
  }
  json["muscles"] = muscles;
  nlohmann::json lines = nlohmann::json::array();
  for (const atlas::ActionLineBuildReport& l : report.action_lines) {
    lines.push_back({{"muscle", l.muscle},
                     {"line", l.line},
                     {"inside_before", l.inside_before},
                     {"inside_after", l.inside_after},
                     {"points_added", l.points_added},
                     {"origin_on_contact", l.origin_on_contact},
                     {"insertion_on_contact", l.insertion_on_contact}});
  }
  json["action_lines"] = lines;
  nlohmann::json surfaces = nlohmann::json::array();
  for (const atlas::WrapSurfaceFitReport& w : report.wrap_surfaces) {
    surfaces.push_back({{"name", w.name},
                        {"bone", w.bone},
                        {"shape", std::string(atlas::wrap_shape_name(w.shape))},
                        {"region_vertices", w.vertices},
                        {"fit_rms_mm", w.rms_mm},
                        {"shrink", w.shrink},
                        {"shrunk_by", w.shrunk_by},
                        {"radii_mm", {w.radii.x(), w.radii.y(), w.radii.z()}}});
  }
  json["wrap_surfaces"] = surfaces;
  nlohmann::json structures = nlohmann::json::array();
  for (const atlas::StructureBuildReport& s : report.structures) {
    nlohmann::json gaps = nlohmann::json::object();
    nlohmann::json overlaps = nlohmann::json::object();
    for (const auto& [bone, gap] : s.gap_mm) gaps[bone] = gap;
    for (const auto& [bone, overlap] : s.overlap_mm) overlaps[bone] = overlap;
    structures.push_back({{"name", s.name},
                          {"kind", s.kind},
                          {"faces", s.faces},
                          {"volume_mm3", s.volume_mm3},
                          {"gap_to_bone_mm", gaps},
                          {"overlap_with_bone_mm", overlaps}});
  }
  json["structures"] = structures;
  json["notes"] = report.notes;
  return json;
}

void print_build(const atlas::AtlasBuildReport& report) {
  std::cout << std::fixed << std::setprecision(2);
  std::cout << "registration of the OpenSim bodies (surface RMS, anchors in mm):\n";
  for (const atlas::BodyRegistrationReport& r : report.registrations) {
    std::cout << "  " << std::left << std::setw(10) << r.body << std::setw(20) << r.method
              << " scale " << std::setprecision(3) << r.scale << std::setprecision(2) << "  rms "
              << r.rms_mm << " mm (" << r.pairs << " pairs)";
    for (const auto& [name, residual] : r.anchor_residuals_mm) {
      std::cout << "  " << name << " " << residual;
    }
    std::cout << '\n';
  }
  std::cout << "joints at rest (mismatch of the mapped frames):\n";
  for (const atlas::JointBuildReport& j : report.joints) {
    std::cout << "  " << std::left << std::setw(12) << j.name << j.frame_mismatch_mm << " mm "
              << j.frame_mismatch_deg << " deg:";
    for (const auto& [name, value] : j.rest_values) std::cout << " " << name << "=" << value;
    std::cout << '\n';
  }
  std::cout << "muscles cleaned of bone penetration:\n";
  for (const atlas::MuscleBuildReport& m : report.muscles) {
    std::cout << "  " << std::left << std::setw(30) << m.name << std::right << " deepest before "
              << std::setw(6) << m.max_penetration_before_mm << " mm, " << std::setw(5)
              << m.vertices_moved << " vertices moved, volume " << std::showpos
              << m.volume_change_percent << std::noshowpos << "%\n";
  }
  std::cout << "action lines fitted into their muscles (inside fraction before -> after):\n";
  for (const atlas::ActionLineBuildReport& l : report.action_lines) {
    std::cout << "  " << std::left << std::setw(30) << l.muscle << std::setw(14) << l.line
              << std::right << std::setprecision(1) << std::setw(6) << 100 * l.inside_before
              << "% -> " << std::setw(5) << 100 * l.inside_after << "%, " << l.points_added
              << " point(s) added" << (l.origin_on_contact ? ", origin on contact" : "")
              << (l.insertion_on_contact ? ", insertion on contact" : "") << '\n';
  }
  std::cout << std::setprecision(2);
  if (!report.wrap_surfaces.empty()) {
    std::cout << "wrap surfaces fitted to the bones (fit RMS; shrunk to keep the lines' points "
                 "outside):\n";
  }
  for (const atlas::WrapSurfaceFitReport& w : report.wrap_surfaces) {
    std::cout << "  " << std::left << std::setw(30) << w.name << std::setw(9)
              << atlas::wrap_shape_name(w.shape) << " on " << std::setw(8) << w.bone << std::right
              << " radii " << w.radii.x() << " " << w.radii.y() << " " << w.radii.z() << " mm, rms "
              << w.rms_mm << " mm over " << w.vertices << " vertices, x" << w.shrink
              << (w.shrunk_by.empty() ? "" : " (" + w.shrunk_by + ")") << '\n';
  }
  if (!report.structures.empty()) {
    std::cout << "cartilages and ligaments (gap to / overlap with their bones):\n";
  }
  for (const atlas::StructureBuildReport& s : report.structures) {
    std::cout << "  " << std::left << std::setw(30) << s.name << std::setw(10) << s.kind
              << std::right;
    for (std::size_t i = 0; i < s.gap_mm.size(); ++i) {
      std::cout << "  " << s.gap_mm[i].first << " " << s.gap_mm[i].second << " / "
                << s.overlap_mm[i].second << " mm";
    }
    std::cout << '\n';
  }
  for (const std::string& note : report.notes) std::cout << "note: " << note << '\n';
  std::cout << "built in " << report.seconds << " s\n";
}

void run_build(const BuildArgs& args) {
  const atlas::AtlasRecipe recipe = atlas::read_atlas_recipe(args.recipe);
  atlas::AtlasBuildOptions options;
  options.data_dir = args.data;
  const atlas::AtlasBuildReport report = atlas::build_atlas(recipe, options, args.out);
  const nlohmann::json json = build_json(report);
  {
    std::ofstream file(std::filesystem::path(args.out) / "build_report.json");
    file << json.dump(2) << '\n';
  }
  if (args.json) {
    std::cout << json.dump(2) << '\n';
  } else {
    print_build(report);
    std::cout << "atlas written to " << args.out << " (check it with: mmm atlas check " << args.out
              << ")\n";
  }
}

struct ShowArgs {
  std::string dir;
  std::string png;
  std::string level = "lod1";
  int width = 500;
};

// Front and side views with the muscles, then the same without them (the
// skeleton), side by side.
void run_show(const ShowArgs& args) {
  const atlas::Atlas model = atlas::read_atlas(args.dir);
  std::vector<mesh::IndexedMesh> surfaces;
  surfaces.reserve(model.bones.size() + model.muscles.size() + model.structures.size());
  std::vector<image::RenderItem> bones;
  std::vector<image::RenderItem> everything;
  const auto level_of = [&](const std::vector<atlas::MeshLevel>& levels) {
    const bool has = std::ranges::any_of(
        levels, [&](const atlas::MeshLevel& level) { return level.level == args.level; });
    return has ? args.level : std::string("full");
  };
  for (const atlas::Bone& bone : model.bones) {
    surfaces.push_back(atlas::load_mesh(args.dir, bone.meshes, level_of(bone.meshes)));
  }
  for (const atlas::Muscle& muscle : model.muscles) {
    surfaces.push_back(atlas::load_mesh(args.dir, muscle.meshes, level_of(muscle.meshes)));
  }
  for (const atlas::Structure& structure : model.structures) {
    surfaces.push_back(atlas::load_mesh(args.dir, structure.meshes, level_of(structure.meshes)));
  }
  for (std::size_t i = 0; i < model.bones.size(); ++i) {
    bones.push_back({&surfaces[i], {235, 226, 200}});
  }
  // Cartilages light blue, ligaments ochre, drawn with the bones (the muscles hide most of them).
  for (std::size_t i = 0; i < model.structures.size(); ++i) {
    const bool cartilage = model.structures[i].kind == atlas::StructureKind::kCartilage;
    bones.push_back({&surfaces[model.bones.size() + model.muscles.size() + i],
                     cartilage ? image::Rgb8{150, 200, 235} : image::Rgb8{205, 160, 60}});
  }
  everything = bones;
  for (std::size_t i = 0; i < model.muscles.size(); ++i) {
    // Muscles in reds that differ slightly from one to the next.
    const auto shade = static_cast<std::uint8_t>(40 + (i * 37) % 70);
    everything.push_back({&surfaces[model.bones.size() + i],
                          {static_cast<std::uint8_t>(190 + (i * 23) % 50), shade, shade}});
  }
  // One scale for every panel: the widest extent (x or y) fills a panel.
  Eigen::AlignedBox3d box;
  for (const mesh::IndexedMesh& surface : surfaces) {
    for (Eigen::Index v = 0; v < surface.V.rows(); ++v) {
      box.extend(Eigen::Vector3d(surface.V.row(v).transpose()));
    }
  }
  image::RenderOptions front;
  front.pixels_per_mm = (args.width - 2.0 * front.margin_px) /
                        std::max(1.0, std::max(box.sizes().x(), box.sizes().y()));
  image::RenderOptions side = front;
  side.view_direction = Eigen::Vector3d(-1, 0, 0);
  const std::vector<image::RgbImage8> panels = {
      image::render_meshes(everything, front), image::render_meshes(everything, side),
      image::render_meshes(bones, front), image::render_meshes(bones, side)};
  image::write_png(image::side_by_side(panels), args.png);
  std::cout << "wrote " << args.png << ": front and side views with muscles, then bones only ("
            << model.bones.size() << " bones, " << model.muscles.size() << " muscles, "
            << model.structures.size() << " cartilages and ligaments)\n";
  // The landmarks with their anatomical definitions (the manifest's).
  std::cout << "landmarks (" << model.landmarks.size() << "):\n";
  for (const atlas::Landmark& landmark : model.landmarks) {
    std::string tags;
    for (const std::string& tag : landmark.tags) tags += (tags.empty() ? "" : ", ") + tag;
    std::cout << "  " << landmark.name << " on " << landmark.bone << " [" << tags << "]"
              << (landmark.description.empty() ? "" : ": " + landmark.description) << '\n';
  }
}

struct CheckArgs {
  std::string dir;
  bool json = false;
  double max_penetration_mm = 1.0;
  double min_inside = 0.8;
  atlas::AnatomyLimits anatomy;
};

nlohmann::json check_json(const atlas::AtlasCheckReport& report) {
  nlohmann::json json;
  json["passed"] = report.passed();
  json["problems"] = report.problems;
  nlohmann::json muscles = nlohmann::json::array();
  for (const atlas::MuscleCheck& m : report.muscles) {
    muscles.push_back({{"name", m.name},
                       {"volume_mm3", m.volume_mm3},
                       {"faces", m.faces},
                       {"max_penetration_mm", m.max_penetration_mm},
                       {"deepest_bone", m.deepest_bone},
                       {"min_fibre_part_inside_fraction", m.min_inside_fraction},
                       {"min_action_line_inside_fraction", m.min_line_inside_fraction}});
  }
  json["muscles"] = muscles;
  nlohmann::json lines = nlohmann::json::array();
  for (const atlas::ActionLineCheck& l : report.action_lines) {
    lines.push_back({{"muscle", l.muscle},
                     {"line", l.line},
                     {"length_mm", l.length_mm},
                     {"inside_fraction", l.inside_fraction},
                     {"tendon_mm", l.tendon_mm},
                     {"fibre_part_inside_fraction", l.fibre_part_inside_fraction}});
  }
  json["action_lines"] = lines;
  nlohmann::json meshes = nlohmann::json::array();
  for (const atlas::MeshHealth& h : report.meshes) {
    meshes.push_back({{"element", h.element},
                      {"level", h.level},
                      {"faces", h.faces},
                      {"closed", h.closed},
                      {"manifold", h.manifold},
                      {"outward", h.oriented},
                      {"volume_mm3", h.volume_mm3}});
  }
  json["meshes"] = meshes;
  nlohmann::json anatomy;
  nlohmann::json articulations = nlohmann::json::array();
  for (const atlas::Articulation& a : report.anatomy.articulations) {
    articulations.push_back({{"name", a.name},
                             {"bones", {a.a, a.b}},
                             {"gap_mm", a.gap_mm},
                             {"overlap_mm", a.overlap_mm}});
  }
  anatomy["articulations"] = articulations;
  nlohmann::json cartilages = nlohmann::json::array();
  for (const atlas::CartilageContact& c : report.anatomy.cartilage_contacts) {
    cartilages.push_back({{"articulation", c.articulation},
                          {"cartilages", {c.a, c.b}},
                          {"gap_mm", c.gap_mm},
                          {"overlap_mm", c.overlap_mm}});
  }
  anatomy["cartilage_contacts"] = cartilages;
  nlohmann::json attached = nlohmann::json::array();
  for (const atlas::StructureAttachment& a : report.anatomy.structure_attachments) {
    attached.push_back({{"structure", a.structure}, {"bone", a.bone}, {"gap_mm", a.gap_mm}});
  }
  anatomy["structures_on_bones"] = attached;
  nlohmann::json contacts = nlohmann::json::array();
  for (const atlas::BoneContact& c : report.anatomy.contacts) {
    contacts.push_back({{"bones", {c.a, c.b}},
                        {"gap_mm", c.gap_mm},
                        {"overlap_mm", c.overlap_mm},
                        {"entering", c.entering}});
  }
  anatomy["bone_contacts"] = contacts;
  nlohmann::json nearest = nlohmann::json::object();
  for (const auto& [bone, gap] : report.anatomy.nearest_neighbour_gap_mm) {
    nearest[bone] = std::isfinite(gap) ? nlohmann::json(gap) : nlohmann::json(nullptr);
  }
  anatomy["nearest_neighbour_gap_mm"] = nearest;
  anatomy["hip_centre_offset_mm"] = report.anatomy.hip_centre_offset_mm >= 0
                                        ? nlohmann::json(report.anatomy.hip_centre_offset_mm)
                                        : nlohmann::json(nullptr);
  json["anatomy"] = anatomy;
  return json;
}

void print_check(const atlas::AtlasCheckReport& report) {
  std::cout << std::left << std::setw(34) << "muscle" << std::right << std::setw(14)
            << "volume mm^3" << std::setw(9) << "faces" << std::setw(16) << "penetration mm"
            << std::setw(13) << "line inside" << std::setw(13) << "fibres in" << '\n';
  std::cout << std::fixed;
  for (const atlas::MuscleCheck& m : report.muscles) {
    std::cout << std::left << std::setw(34) << m.name << std::right << std::setw(14)
              << std::setprecision(0) << m.volume_mm3 << std::setw(9) << m.faces << std::setw(16)
              << std::setprecision(2) << m.max_penetration_mm << std::setw(12)
              << std::setprecision(1) << 100 * m.min_line_inside_fraction << "%" << std::setw(12)
              << 100 * m.min_inside_fraction << "%\n";
  }
  std::cout << '\n'
            << std::left << std::setw(22) << "articulation" << std::setw(40) << "bones"
            << std::right << std::setw(10) << "gap mm" << std::setw(14) << "overlap mm" << '\n';
  for (const atlas::Articulation& a : report.anatomy.articulations) {
    std::cout << std::left << std::setw(22) << a.name << std::setw(40) << (a.a + " - " + a.b)
              << std::right << std::setw(10) << std::setprecision(2) << a.gap_mm << std::setw(14)
              << a.overlap_mm << '\n';
  }
  if (!report.anatomy.cartilage_contacts.empty()) {
    std::cout << '\n'
              << std::left << std::setw(22) << "cartilage contact" << std::setw(58) << "cartilages"
              << std::right << std::setw(10) << "gap mm" << std::setw(14) << "overlap mm" << '\n';
  }
  for (const atlas::CartilageContact& c : report.anatomy.cartilage_contacts) {
    std::cout << std::left << std::setw(22) << c.articulation << std::setw(58)
              << (c.a + " - " + c.b) << std::right << std::setw(10) << std::setprecision(2)
              << c.gap_mm << std::setw(14) << c.overlap_mm << '\n';
  }
  double deepest = 0.0;
  std::string deepest_pair = "none";
  for (const atlas::BoneContact& c : report.anatomy.contacts) {
    if (c.overlap_mm > deepest) {
      deepest = c.overlap_mm;
      deepest_pair = c.entering + " in " + (c.entering == c.a ? c.b : c.a);
    }
  }
  std::cout << "deepest bone in bone: " << std::setprecision(2) << deepest << " mm ("
            << deepest_pair << ")\n";
  if (report.anatomy.hip_centre_offset_mm >= 0) {
    std::cout << "femoral head centre to acetabulum centre: " << std::setprecision(2)
              << report.anatomy.hip_centre_offset_mm << " mm\n";
  }
  std::cout << report.meshes.size() << " meshes checked\n";
  for (const std::string& problem : report.problems) std::cerr << "problem: " << problem << '\n';
  std::cout << (report.passed() ? "atlas check passed\n" : "atlas check FAILED\n");
}

void run_check(const CheckArgs& args) {
  atlas::AtlasCheckOptions options;
  options.max_penetration_mm = args.max_penetration_mm;
  options.min_inside_fraction = args.min_inside;
  options.anatomy = args.anatomy;
  const atlas::AtlasCheckReport report = atlas::check_atlas(args.dir, options);
  if (args.json) {
    std::cout << check_json(report).dump(2) << '\n';
  } else {
    print_check(report);
  }
  if (!report.passed()) set_exit_code(kExitFailed);
}

}  // namespace

void register_atlas_commands(CLI::App& app) {
  auto* atlas = app.add_subcommand("atlas", "Build, check and look at musculoskeletal atlases");
  atlas->require_subcommand(1);

  auto build_args = std::make_shared<BuildArgs>();
  auto* build = atlas->add_subcommand(
      "build",
      "Build an atlas folder from a recipe (schemas/recipes/vhf_right_leg.yaml is the "
      "default atlas) and the real data");
  build->add_option("RECIPE", build_args->recipe, "Recipe file (YAML)")->required();
  build->add_option("-o,--out", build_args->out, "Atlas folder to write")->required();
  build->add_option("--data", build_args->data,
                    "Folder the recipe's data paths are relative to (default: the shared data "
                    "this mmm was built with)");
  build->add_flag("--json", build_args->json, "Print the build report as JSON");
  build->callback([build_args] { run_build(*build_args); });

  auto show_args = std::make_shared<ShowArgs>();
  auto* show = atlas->add_subcommand(
      "show", "Picture of an atlas: front and side views with muscles, then bones only (PNG)");
  show->add_option("DIR", show_args->dir, "Atlas folder")->required();
  show->add_option("--png", show_args->png, "PNG file to write")->required();
  show->add_option("--level", show_args->level, "Mesh level to draw (full, lod1, ...)");
  show->add_option("--width", show_args->width, "Width of each panel (pixels)")
      ->check(CLI::Range(100, 4000));
  show->callback([show_args] { run_show(*show_args); });

  auto* labels = atlas->add_subcommand(
      "labels",
      "Landmark labels that import_markups understands (3D Slicer point lists), with each "
      "landmark's anatomical definition");
  labels->callback([] {
    std::cout << "atlas landmark (labels, case, spaces and '_' ignored; R/L before or after): "
                 "definition\n"
              << landmarks::landmark_label_table_text();
  });

  auto check_args = std::make_shared<CheckArgs>();
  auto* check = atlas->add_subcommand(
      "check",
      "Check an atlas: closed meshes, no muscle in bone, action lines inside muscles, bones "
      "that fit together (no overlap, no floating bone, closed joints, head in acetabulum), "
      "required landmarks; prints each muscle's volume and triangles and each joint's gap");
  check->add_option("DIR", check_args->dir, "Atlas folder (holding atlas.yaml)")->required();
  check->add_flag("--json", check_args->json, "Print JSON instead of a table");
  check
      ->add_option("--max-penetration", check_args->max_penetration_mm,
                   "Deepest muscle vertex allowed inside a bone (mm)")
      ->check(CLI::Range(0.0, 100.0));
  check
      ->add_option("--min-inside", check_args->min_inside,
                   "Least fraction of the fibre part (length less tendon) of each action line "
                   "inside its muscle")
      ->check(CLI::Range(0.0, 1.0));
  check
      ->add_option("--max-bone-overlap", check_args->anatomy.max_bone_overlap_mm,
                   "Deepest vertex of a bone allowed inside another bone (mm)")
      ->check(CLI::Range(0.0, 100.0));
  check
      ->add_option("--max-neighbour-gap", check_args->anatomy.max_neighbour_gap_mm,
                   "Farthest a bone may be from its nearest neighbour (mm)")
      ->check(CLI::Range(0.0, 100.0));
  check
      ->add_option("--max-joint-gap", check_args->anatomy.max_joint_gap_mm,
                   "Widest gap allowed between the bones of a joint, and the patella and the "
                   "femur (mm)")
      ->check(CLI::Range(0.0, 100.0));
  check
      ->add_option("--max-hip-offset", check_args->anatomy.max_hip_centre_offset_mm,
                   "Farthest the femoral head centre may be from the acetabulum's (mm)")
      ->check(CLI::Range(0.0, 100.0));
  check->callback([check_args] { run_check(*check_args); });
}

}  // namespace mmm::app
