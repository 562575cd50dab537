#pragma once
// Node types for the tests of workflow/definition: the specs of the real mesh
// nodes (nodes/, which this test suite does not link), plus a node that takes
// an Integer and a manual node. Their run functions do nothing.

#include <cstdint>
#include <filesystem>
#include <string>

#include "tests/support/manual_task_stub.h"
#include "tests/support/test_data.h"
#include "workflow/node_registry.h"

namespace mmm::workflow::test {

inline NodeRegistry make_test_registry() {
  NodeRegistry registry;
  const auto nothing = [](NodeContext&) {};
  registry.add(
      NodeSpec{"load_mesh", 1, "Read a surface mesh file into a Mesh (mm)"}
          .input<port::File>("file", "The mesh file")
          .param_enum("format", "stl", {"stl", "obj", "ply", "off", "vtp"}, "Format")
          .param<double>("scale", 1.0, "Multiply coordinates to get mm", {.min = 1e-4, .max = 1e6})
          .output<port::Mesh>("mesh", "The surface"),
      nothing);
  registry.add(NodeSpec{"decimate_mesh", 1, "Lower-resolution copy of a mesh"}
                   .input<port::Mesh>("mesh", "Surface to simplify")
                   .param<std::int64_t>("target_faces", 5000, "Faces to reach", {.min = 4})
                   .param<double>("max_normal_deviation", 60.0, "Largest normal change",
                                  {.min = 1, .max = 180}, "deg")
                   .output<port::Mesh>("decimated", "The simplified surface"),
               nothing);
  registry.add(NodeSpec{"measure_mesh", 1, "Health check and measures of a mesh"}
                   .input<port::Mesh>("mesh", "Surface to measure")
                   .output<port::Report>("report", "JSON report"),
               nothing);
  registry.add(NodeSpec{"takes_integer", 1, "Uses an integer"}
                   .input<port::Integer>("count", "A count")
                   .output<port::Report>("report", "JSON report"),
               nothing);
  registry.add(NodeSpec{"pick_landmarks", 1, "An operator places landmarks on a mesh"}
                   .input<port::Mesh>("mesh", "Surface to mark")
                   .optional_input<port::LandmarkSet>("previous", "Landmarks to start from")
                   .output<port::LandmarkSet>("landmarks", "The landmarks")
                   .manual(),
               nothing, mmm::test::stub_task_behaviour());
  return registry;
}

inline std::filesystem::path malformed_dir() {
  return mmm::test::source_dir() / "tests/workflow/definition/malformed";
}

inline std::filesystem::path example_dir() { return mmm::test::source_dir() / "schemas/examples"; }

}  // namespace mmm::workflow::test
