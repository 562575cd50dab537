#include "nodes/build_hulls.h"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/wrapping/muscle_hulls.h"
#include "core/wrapping/muscle_wrapping.h"
#include "nodes/muscle_selection.h"

namespace mmm::nodes {

workflow::NodeSpec BuildHulls::spec() {
  using workflow::port::Atlas;
  using workflow::port::File;
  using workflow::port::Report;
  const wrapping::MuscleWrappingOptions d;
  return workflow::NodeSpec{
      "build_hulls", 1,
      "Progressive outer hull of every muscle's wrapping surface (edge collapses that only "
      "move the surface outward, least volume first), with a containment check; stored for "
      "wrap_muscles to reuse while the surface is unchanged"}
      .resources(2, 2048)
      .input<Atlas>("atlas", "The (scaled) atlas")
      .param<std::int64_t>("target_faces", d.target_faces,
                           "Wrapping resolution the hull encloses: each muscle's full mesh "
                           "decimated to this many faces (as wrap_muscles's target_faces)",
                           {.min = 0, .max = 1000000})
      .param<std::int64_t>("hull_faces", d.hull_faces, "Faces of each hull",
                           {.min = 4, .max = 1000000})
      .param<std::string>("muscles", "",
                          "Comma-separated muscle names; empty: every muscle of the atlas")
      .output<File>("hulls", "Folder bundle: hulls.json + one binary PLY per muscle (ParaView)")
      .output<Report>("report", "Per muscle: faces, volume added (%), vertices outside, time");
}

void BuildHulls::run(workflow::NodeContext& context) {
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const std::vector<const atlas::Muscle*> muscles =
      selected_muscles(atlas, context.text("muscles"), "build_hulls");
  const Eigen::Index target_faces = context.integer("target_faces");
  const Eigen::Index hull_faces = context.integer("hull_faces");
  std::vector<wrapping::MuscleHull> hulls;
  nlohmann::json rows = nlohmann::json::array();
  int outside = 0;
  double seconds = 0.0;
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    const atlas::Muscle& muscle = *muscles[m];
    context.progress(static_cast<std::int64_t>(m), static_cast<std::int64_t>(muscles.size()),
                     "hull of " + muscle.name);
    const mesh::IndexedMesh surface = wrapping::wrapping_surface(muscle, atlas_dir, target_faces);
    wrapping::MuscleHull hull = wrapping::build_muscle_hull(muscle.name, surface, hull_faces);
    const mesh::ProgressiveHullReport& r = hull.report;
    outside += r.vertices_outside;
    seconds += hull.seconds;
    rows.push_back({{"muscle", muscle.name},
                    {"faces_before", r.faces_before},
                    {"faces_after", r.faces_after},
                    {"volume_added_percent", 100.0 * (r.volume_after / r.volume_before - 1.0)},
                    {"vertices_outside", r.vertices_outside},
                    {"max_outside_mm", r.max_outside_mm},
                    {"seconds", hull.seconds}});
    hulls.push_back(std::move(hull));
  }
  if (outside > 0) {
    context.warn(std::to_string(outside) +
                 " surface vertices lie outside their hull (see the report); the wrapping "
                 "still runs, the hull is only its first approximation");
  }
  const std::filesystem::path folder = context.scratch_dir() / "hulls";
  wrapping::write_hulls(folder, hulls);
  context.set_output("hulls", pack_directory(folder));
  context.set_output("report", nlohmann::json{{"muscles", rows},
                                              {"target_faces", target_faces},
                                              {"hull_faces", hull_faces},
                                              {"vertices_outside", outside},
                                              {"seconds", seconds}}
                                   .dump(2));
  context.progress(static_cast<std::int64_t>(muscles.size()),
                   static_cast<std::int64_t>(muscles.size()), "done");
}

}  // namespace mmm::nodes
