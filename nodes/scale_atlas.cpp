#include "nodes/scale_atlas.h"

#include <string>

#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/directory_bundle.h"
#include "core/file_bytes.h"
#include "core/image/mesh_render.h"
#include "core/image/outline_overlay.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "core/scaling/atlas_scaling.h"

namespace mmm::nodes {
namespace {

scaling::AtlasScalingOptions scaling_options_from(const workflow::NodeContext& context) {
  scaling::AtlasScalingOptions options;
  options.landmark_weight = context.number("landmark_weight");
  options.joint_weight = context.number("joint_weight");
  options.bone.laplacian_weight = context.number("laplacian_weight");
  options.bone.determined_fraction = context.number("determined_fraction");
  options.local_radius_mm = context.number("local_radius_mm");
  options.muscle.laplacian_weight = context.number("laplacian_weight");
  options.muscle.attachment_weight = context.number("attachment_weight");
  options.muscle.contact_distance_mm = context.number("contact_distance_mm");
  options.muscle.penetration_tolerance_mm = context.number("penetration_tolerance_mm");
  options.muscle.max_penetration_iterations =
      static_cast<int>(context.integer("max_penetration_iterations"));
  options.muscle.blend_radius_mm = context.number("blend_radius_mm");
  options.threads = static_cast<int>(context.integer("threads"));
  return options;
}

// The overlay picture (see the header): outlines of the scaled bones at
// their first coarser level on the radiographs, the given landmarks as white
// crosses and the scaled atlas's as red circles.
image::RgbImage8 overlay_picture(const scaling::ScaledAtlas& scaled,
                                 const landmarks::LandmarkSet& given,
                                 const image::RadiographPair* pair) {
  std::vector<const mesh::IndexedMesh*> bones;
  for (const atlas::Bone& bone : scaled.atlas.bones) {
    const std::string level = bone.meshes.size() > 1 ? bone.meshes[1].level : "full";
    bones.push_back(&scaled.meshes.at(bone.name).at(level));
  }
  const std::vector<image::Rgb8> colours = image::distinct_colours(static_cast<int>(bones.size()));
  if (pair == nullptr) {
    std::vector<image::RenderItem> items;
    for (std::size_t b = 0; b < bones.size(); ++b) items.push_back({bones[b], colours[b]});
    image::RenderOptions front;
    front.image_width = 600;
    image::RenderOptions side = front;
    side.view_direction = Eigen::Vector3d(-1, 0, 0);
    const std::vector<image::RgbImage8> views = {image::render_meshes(items, front),
                                                 image::render_meshes(items, side)};
    return image::side_by_side(views);
  }
  std::vector<image::OutlineItem> items;
  for (std::size_t b = 0; b < bones.size(); ++b) {
    items.push_back({scaled.atlas.bones[b].name, bones[b], colours[b]});
  }
  image::OverlayOptions options;
  for (const landmarks::Landmark& landmark : given.landmarks) {
    options.points.push_back({landmark.position_mm, {255, 255, 255}, image::PointMarker::kCross});
    if (const atlas::Landmark* placed = scaled.atlas.find_landmark(landmark.name)) {
      options.points.push_back({placed->position, {255, 40, 40}, image::PointMarker::kCircle});
    }
  }
  return image::outline_overlay_pair(*pair, items, options);
}

}  // namespace

workflow::NodeSpec ScaleAtlas::spec() {
  using workflow::port::Atlas;
  using workflow::port::File;
  using workflow::port::LandmarkSet;
  using workflow::port::RadiographPair;
  using workflow::port::Report;
  const scaling::AtlasScalingOptions d;
  return workflow::NodeSpec{
      "scale_atlas", 1,
      "Morph the atlas onto the patient's landmarks: anatomical first stage, then Laplacian "
      "detail preservation with landmark, joint, attachment and non-penetration terms"}
      .resources(2, 3072)
      .input<Atlas>("atlas", "The generic atlas")
      .input<LandmarkSet>("landmarks",
                          "femoral_head_centre_r and patella_centre_r (required), "
                          "ankle_centre_r and further atlas landmarks (optional)")
      .optional_input<RadiographPair>("radiographs", "The patient's radiographs, for the overlay")
      .param<double>("landmark_weight", d.landmark_weight,
                     "Weight of each landmark term (per mm^2)", {.min = 1e-6})
      .param<double>("joint_weight", d.joint_weight,
                     "Weight keeping each bone on its parent's joint centre (per mm^2)",
                     {.min = 1e-6})
      .param<double>("laplacian_weight", d.bone.laplacian_weight,
                     "Weight of the Laplacian detail term", {.min = 1e-9})
      .param<double>("determined_fraction", d.bone.determined_fraction,
                     "Share of the strongest that an affine direction's landmark support needs "
                     "to be fitted rather than kept from the anatomical estimate",
                     {.min = 1e-12, .max = 1})
      .param<double>("local_radius_mm", d.local_radius_mm,
                     "Landmarks tagged local in the atlas (epicondyles, malleoli, heel) move "
                     "their bone within this radius of themselves instead of stretching the "
                     "whole bone; 0: every landmark acts on the bone's affine part",
                     {.min = 0, .max = 500}, "mm")
      .param<double>("attachment_weight", d.muscle.attachment_weight,
                     "Weight keeping muscle vertices that touch a bone on it (per mm^2)",
                     {.min = 1e-6})
      .param<double>("contact_distance_mm", d.muscle.contact_distance_mm,
                     "Muscle vertices this close to a bone at rest are attached to it",
                     {.min = 0, .max = 20}, "mm")
      .param<double>("penetration_tolerance_mm", d.muscle.penetration_tolerance_mm,
                     "Muscle-bone penetration beyond the atlas's own that is tolerated",
                     {.min = 0, .max = 5}, "mm")
      .param<std::int64_t>("max_penetration_iterations", d.muscle.max_penetration_iterations,
                           "Solves that push penetrating muscle vertices out",
                           {.min = 0, .max = 100})
      .param<double>("blend_radius_mm", d.muscle.blend_radius_mm,
                     "Radius of the muscles' blend of the bone maps", {.min = 0.1, .max = 100},
                     "mm")
      .param<std::int64_t>("threads", d.threads, "Worker threads", {.min = 1, .max = 64})
      .output<Atlas>("atlas", "The patient's atlas, in the landmarks' frame")
      .output<Report>(
          "report",
          "Landmark residuals, length factors (first stage and final), stretch warnings, muscles, "
          "timings")
      .output<File>("overlay", "PNG of the scaled bones' outlines on the radiographs");
}

void ScaleAtlas::run(workflow::NodeContext& context) {
  const scaling::AtlasScalingOptions options = scaling_options_from(context);
  context.progress(0, 5, "reading the atlas");
  const std::filesystem::path in = context.scratch_dir() / "atlas_in";
  unpack_directory(context.input_bytes("atlas"), in, "input 'atlas'");
  atlas::Atlas generic = atlas::read_atlas(in);
  atlas::AtlasMeshes meshes = atlas::read_atlas_meshes(generic, in, options.threads);
  const landmarks::LandmarkSet given =
      landmarks::landmark_set_from_json_text(context.input_bytes("landmarks"), "input 'landmarks'");
  context.progress(1, 5, "preparing the atlas");
  const auto prepared = scaling::prepare_atlas(std::move(generic), std::move(meshes), options);
  context.progress(2, 5, "scaling");
  const scaling::ScaledAtlas scaled = scaling::scale_atlas(*prepared, given, options);
  for (const auto& [name, residual] : scaled.landmark_residual_mm) {
    context.info("landmark " + name + ": residual " + std::to_string(residual) + " mm");
  }
  for (const std::string& note : scaled.notes) context.warn(note);
  for (const scaling::StretchWarning& warning : scaled.warnings) context.warn(warning.message);
  context.progress(3, 5, "writing the patient's atlas");
  const std::filesystem::path out = context.scratch_dir() / "atlas_out";
  atlas::write_atlas_with_meshes(scaled.atlas, scaled.meshes, out, options.threads);
  context.set_output("atlas", pack_directory(out));
  nlohmann::json report = scaling::scaling_report_json(scaled);
  report["prepare_seconds"] = prepared->prepare_seconds;
  context.set_output("report", report.dump(2));
  context.progress(4, 5, "drawing the overlay");
  std::optional<image::RadiographPair> pair;
  if (context.has_input("radiographs")) {
    pair = image::radiograph_pair_from_json_text(context.input_bytes("radiographs"),
                                                 "input 'radiographs'");
  }
  const std::filesystem::path overlay = context.scratch_dir() / "overlay.png";
  image::write_png(overlay_picture(scaled, given, pair ? &*pair : nullptr), overlay);
  context.set_output_file("overlay", overlay);
  context.progress(5, 5, "done");
}

}  // namespace mmm::nodes
