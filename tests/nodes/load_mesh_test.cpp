#include "nodes/load_mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/ply.h"
#include "core/mesh/primitives.h"
#include "tests/nodes/node_harness.h"
#include "workflow/definition/node_catalog.h"

namespace mmm::nodes {
namespace {

using workflow::PortType;

// Golden spec: a change of a port, a parameter or a default must show here.
TEST(LoadMeshTest, SpecIsPinned) {
  EXPECT_EQ(workflow::node_spec_json(LoadMesh::spec()).dump(2), R"json({
  "description": "Read a surface mesh file into a Mesh (mm)",
  "inputs": [
    {
      "description": "The mesh file (STL, OBJ, PLY, OFF or VTP)",
      "name": "file",
      "required": true,
      "type": "File"
    }
  ],
  "manual": false,
  "name": "load_mesh",
  "outputs": [
    {
      "description": "The surface, coordinates in mm",
      "name": "mesh",
      "type": "Mesh"
    }
  ],
  "params": [
    {
      "choices": [
        "stl",
        "obj",
        "ply",
        "off",
        "vtp"
      ],
      "default": "stl",
      "description": "Format of the file",
      "name": "format",
      "type": "enum"
    },
    {
      "default": 1.0,
      "description": "Multiply coordinates to get mm (1000 for files in metres)",
      "max": 1000000.0,
      "min": 0.0001,
      "name": "scale",
      "type": "number"
    }
  ],
  "version": 1
})json");
}

TEST(LoadMeshTest, ReadsStlAndScalesToMillimetres) {
  test::NodeHarness harness;
  const auto stl = harness.folder() / "box.stl";
  mesh::write_mesh(mesh::make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 2, 3)), stl);
  const auto outputs =
      harness.run<LoadMesh>({{"file", harness.add_file(PortType::kFile, stl)}}, {{"scale", 10.0}});
  const workflow::ArtifactRef& out = outputs.at("mesh");
  EXPECT_EQ(out.type, PortType::kMesh);
  const mesh::IndexedMesh box = mesh::read_ply(out.path);
  EXPECT_EQ(box.num_vertices(), 8);  // STL corners welded into shared vertices
  EXPECT_EQ(box.num_faces(), 12);
  // Exact: 1, 2, 3 are floats in STL and times 10 is exact in double.
  EXPECT_EQ(Eigen::Vector3d(box.V.colwise().maxCoeff()), Eigen::Vector3d(10, 20, 30));
  ASSERT_FALSE(harness.log().empty());
  EXPECT_THAT(harness.log().back(), ::testing::HasSubstr("8 vertices, 12 faces (stl)"));
}

TEST(LoadMeshTest, ReadsEveryFormatWithoutAFileExtension) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(2, 5.0);
  for (const std::string format : {"stl", "obj", "ply", "off", "vtp"}) {
    test::NodeHarness harness;
    const auto file = harness.folder() / ("sphere." + format);
    mesh::write_mesh(sphere, file);
    const auto outputs = harness.run<LoadMesh>({{"file", harness.add_file(PortType::kFile, file)}},
                                               {{"format", format}});
    const mesh::IndexedMesh loaded = mesh::read_ply(outputs.at("mesh").path);
    EXPECT_EQ(loaded.num_faces(), sphere.num_faces()) << format;
    EXPECT_EQ(loaded.num_vertices(), sphere.num_vertices()) << format;
  }
}

TEST(LoadMeshTest, SameInputGivesTheSameArtifact) {
  test::NodeHarness harness;
  const auto ply = harness.folder() / "sphere.ply";
  mesh::write_mesh(mesh::make_icosphere(1), ply);
  const auto input = harness.add_file(PortType::kFile, ply);
  const auto first = harness.run<LoadMesh>({{"file", input}}, {{"format", std::string("ply")}});
  const auto second = harness.run<LoadMesh>({{"file", input}}, {{"format", std::string("ply")}});
  EXPECT_EQ(first.at("mesh").hash, second.at("mesh").hash);  // restartable, cacheable
}

TEST(LoadMeshTest, WrongFormatIsAnIoError) {
  test::NodeHarness harness;
  const auto stl = harness.folder() / "box.stl";
  mesh::write_mesh(mesh::make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), stl);
  const auto input = harness.add_file(PortType::kFile, stl);
  EXPECT_THROW(harness.run<LoadMesh>({{"file", input}}, {{"format", std::string("ply")}}), IoError);
  EXPECT_THROW(harness.run<LoadMesh>({}, {}), InvalidInputError);  // input not connected
}

TEST(LoadMeshTest, OpenSimFemurInMetresBecomesMillimetres) {
  test::NodeHarness harness;
  const auto femur = mmm::test::data_dir() / "gait2392/Geometry/femur_r.vtp";
  const auto outputs = harness.run<LoadMesh>({{"file", harness.add_file(PortType::kFile, femur)}},
                                             {{"format", std::string("vtp")}, {"scale", 1000.0}});
  const mesh::IndexedMesh loaded = mesh::read_ply(outputs.at("mesh").path);
  EXPECT_EQ(loaded.num_faces(), 908);
  // An adult femur is 350-500 mm long; in metres it would be below 1.
  const double length = (loaded.V.colwise().maxCoeff() - loaded.V.colwise().minCoeff()).maxCoeff();
  EXPECT_GT(length, 350.0);
  EXPECT_LT(length, 500.0);
}

}  // namespace
}  // namespace mmm::nodes
