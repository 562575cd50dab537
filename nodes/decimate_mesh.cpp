#include "nodes/decimate_mesh.h"

#include <string>

#include "core/mesh/decimate.h"
#include "core/mesh/io/ply.h"

namespace mmm::nodes {

workflow::NodeSpec DecimateMesh::spec() {
  using workflow::port::Mesh;
  return workflow::NodeSpec{"decimate_mesh", 1,
                            "Lower-resolution copy of a mesh by quadric-error edge collapses"}
      .input<Mesh>("mesh", "Surface to simplify")
      .param<std::int64_t>("target_faces", 5000,
                           "Number of faces to reach (a larger value keeps the input)", {.min = 4})
      .param<double>("max_normal_deviation", 60.0,
                     "Largest change of a face normal allowed per collapse", {.min = 1, .max = 180},
                     "deg")
      .output<Mesh>("decimated", "The simplified surface");
}

void DecimateMesh::run(workflow::NodeContext& context) {
  context.progress(0, 3, "reading");
  const mesh::IndexedMesh input = mesh::read_ply(context.input("mesh").path);
  context.progress(1, 3, "decimating");
  mesh::DecimateReport report;
  const mesh::IndexedMesh coarse =
      mesh::decimate(input,
                     {.target_faces = static_cast<Eigen::Index>(context.integer("target_faces")),
                      .max_normal_deviation_degrees = context.number("max_normal_deviation")},
                     &report);
  context.info("decimated " + std::to_string(report.faces_before) + " -> " +
               std::to_string(report.faces_after) + " faces");
  context.progress(2, 3, "writing");
  const std::filesystem::path out = context.scratch_dir() / "decimated.ply";
  mesh::write_ply(coarse, out);
  context.set_output_file("decimated", out);
  context.progress(3, 3, "done");
}

}  // namespace mmm::nodes
