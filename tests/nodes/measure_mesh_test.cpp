#include "nodes/measure_mesh.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/mesh/io/ply.h"
#include "core/mesh/primitives.h"
#include "tests/nodes/node_harness.h"
#include "workflow/definition/node_catalog.h"

namespace mmm::nodes {
namespace {

using workflow::PortType;

nlohmann::json measure(const mesh::IndexedMesh& surface, std::string* bytes = nullptr) {
  test::NodeHarness harness;
  const auto file = harness.folder() / "input.ply";
  mesh::write_ply(surface, file);
  const auto outputs =
      harness.run<MeasureMesh>({{"mesh", harness.add_file(PortType::kMesh, file)}});
  EXPECT_EQ(outputs.at("report").type, PortType::kReport);
  const std::string text = mmm::test::read_text(outputs.at("report").path);
  if (bytes != nullptr) *bytes = text;
  return nlohmann::json::parse(text);
}

// Golden spec: a change of a port, a parameter or a default must show here.
TEST(MeasureMeshTest, SpecIsPinned) {
  EXPECT_EQ(workflow::node_spec_json(MeasureMesh::spec()).dump(2), R"json({
  "description": "Health check (closed, manifold, oriented) and measures of a mesh",
  "inputs": [
    {
      "description": "Surface to measure",
      "name": "mesh",
      "required": true,
      "type": "Mesh"
    }
  ],
  "manual": false,
  "name": "measure_mesh",
  "outputs": [
    {
      "description": "JSON: check figures, area (mm^2), volume (mm^3), centroid, principal axes",
      "name": "report",
      "type": "Report"
    }
  ],
  "params": [],
  "version": 1
})json");
}

TEST(MeasureMeshTest, BoxHasExactVolumeAreaAndCentroid) {
  std::string bytes;
  const nlohmann::json report =
      measure(mesh::make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 20, 30)), &bytes);
  EXPECT_EQ(bytes, report.dump(2));  // the Report serialisation: sorted keys, 2-space indent
  EXPECT_EQ(report["units"], "mm");
  const auto& check = report["check"];
  EXPECT_EQ(check["vertices"], 8);
  EXPECT_EQ(check["faces"], 12);
  EXPECT_EQ(check["edges"], 18);
  EXPECT_EQ(check["euler_characteristic"], 2);
  EXPECT_TRUE(check["watertight"].get<bool>());
  EXPECT_TRUE(check["problems"].empty());
  const auto& p = report["mass_properties"];
  // Twelve tetrahedra and triangles of small integers: exact up to a few
  // roundings of values near 6000.
  EXPECT_NEAR(p["volume"].get<double>(), 6000.0, 1e-9);
  EXPECT_NEAR(p["area"].get<double>(), 2200.0, 1e-9);
  EXPECT_EQ(p["centroid_of"], "solid");
  EXPECT_NEAR(p["centroid"][0].get<double>(), 5.0, 1e-12);
  EXPECT_NEAR(p["centroid"][1].get<double>(), 10.0, 1e-12);
  EXPECT_NEAR(p["centroid"][2].get<double>(), 15.0, 1e-12);
  EXPECT_EQ(p["bounding_box"]["size"], nlohmann::json({10.0, 20.0, 30.0}));
  // Long axis along z (30 mm side): |z component| of the first axis is 1.
  EXPECT_NEAR(std::abs(p["principal_axes"][0][2].get<double>()), 1.0, 1e-12);
}

TEST(MeasureMeshTest, OpenSurfaceHasNoVolume) {
  mesh::IndexedMesh box = mesh::make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const Eigen::MatrixX3i faces = box.F.topRows(11);  // drop one triangle
  box.F = faces;
  const nlohmann::json report = measure(box);
  EXPECT_FALSE(report["check"]["closed"].get<bool>());
  EXPECT_EQ(report["check"]["boundary_edges"], 3);
  EXPECT_EQ(report["check"]["boundary_loops"], 1);
  EXPECT_FALSE(report["check"]["problems"].empty());
  EXPECT_TRUE(report["mass_properties"]["volume"].is_null());
  EXPECT_EQ(report["mass_properties"]["centroid_of"], "surface");
}

}  // namespace
}  // namespace mmm::nodes
