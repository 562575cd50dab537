#include "core/mesh/mesh_check.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::mesh {
namespace {

IndexedMesh unit_cube() { return make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()); }

IndexedMesh without_face(const IndexedMesh& mesh, Eigen::Index face) {
  IndexedMesh out = mesh;
  out.F.resize(mesh.F.rows() - 1, 3);
  for (Eigen::Index f = 0, g = 0; f < mesh.F.rows(); ++f) {
    if (f != face) out.F.row(g++) = mesh.F.row(f);
  }
  return out;
}

TEST(MeshCheckTest, CleanPrimitivesAreWatertight) {
  for (const IndexedMesh& mesh :
       {unit_cube(), make_icosphere(3), make_torus(3, 1, 16, 8), make_cylinder(1, 2, 12)}) {
    const MeshCheckReport report = check_mesh(mesh);
    EXPECT_TRUE(report.watertight());
    EXPECT_TRUE(report.problems().empty());
    EXPECT_EQ(report.connected_components, 1);
  }
  // Euler characteristic: 2 for sphere-like, 0 for the torus (genus 1).
  EXPECT_EQ(check_mesh(make_icosphere(2)).euler_characteristic, 2);
  EXPECT_EQ(check_mesh(make_torus(3, 1, 16, 8)).euler_characteristic, 0);
}

TEST(MeshCheckTest, MissingFaceOpensOneLoop) {
  const MeshCheckReport report = check_mesh(without_face(unit_cube(), 0));
  EXPECT_FALSE(report.closed());
  EXPECT_EQ(report.boundary_edges, 3);
  EXPECT_EQ(report.boundary_loops, 1);
  ASSERT_EQ(report.problems().size(), 1U);
  EXPECT_NE(report.problems()[0].find("open"), std::string::npos);
}

TEST(MeshCheckTest, FlippedFaceBreaksOrientation) {
  IndexedMesh cube = unit_cube();
  std::swap(cube.F(3, 1), cube.F(3, 2));
  const MeshCheckReport report = check_mesh(cube);
  EXPECT_TRUE(report.closed());
  EXPECT_FALSE(report.orientation_consistent());
  EXPECT_EQ(report.inconsistently_oriented_edges, 3);  // all three edges of the face
}

TEST(MeshCheckTest, ThirdFaceOnAnEdgeIsNonManifold) {
  IndexedMesh cube = unit_cube();
  cube.V.conservativeResize(9, 3);
  cube.V.row(8) << 0.5, 0.5, 3.0;  // a fin standing on edge (0, 2)
  cube.F.conservativeResize(13, 3);
  cube.F.row(12) << 0, 2, 8;
  const MeshCheckReport report = check_mesh(cube);
  EXPECT_EQ(report.non_manifold_edges, 1);
  EXPECT_FALSE(report.closed());
  EXPECT_FALSE(report.manifold());
}

TEST(MeshCheckTest, BowTieVertexIsNonManifold) {
  // Two cubes sharing only one corner vertex.
  IndexedMesh a = unit_cube();
  IndexedMesh b = make_box(Eigen::Vector3d::Ones(), Eigen::Vector3d::Constant(2));
  IndexedMesh both;
  both.V.resize(15, 3);
  both.V.topRows(8) = a.V;
  // b's vertex 0 is (1,1,1) = a's vertex 7: reuse it, append the other 7.
  both.V.bottomRows(7) = b.V.bottomRows(7);
  both.F.resize(24, 3);
  both.F.topRows(12) = a.F;
  for (Eigen::Index f = 0; f < 12; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = b.F(f, k);
      both.F(12 + f, k) = v == 0 ? 7 : v + 7;
    }
  }
  const MeshCheckReport report = check_mesh(both);
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(report.non_manifold_vertices, 1);
  EXPECT_EQ(report.connected_components, 1);  // joined through the vertex
  EXPECT_FALSE(report.watertight());
}

TEST(MeshCheckTest, DuplicatesDegeneratesAndStrayVerticesAreCounted) {
  IndexedMesh cube = unit_cube();
  cube.V.conservativeResize(10, 3);
  cube.V.row(8) = cube.V.row(3);   // duplicate of vertex 3, unused
  cube.V.row(9) << 0.5, 0.5, 0.5;  // stray vertex
  cube.F.conservativeResize(13, 3);
  cube.F.row(12) << 0, 1, 1;  // repeated index
  const MeshCheckReport report = check_mesh(cube);
  EXPECT_EQ(report.duplicate_vertices, 1);
  EXPECT_EQ(report.unreferenced_vertices, 2);
  EXPECT_EQ(report.degenerate_faces, 1);
}

TEST(MeshCheckTest, CountsComponents) {
  IndexedMesh a = make_icosphere(1);
  IndexedMesh two;
  two.V.resize(2 * a.V.rows(), 3);
  two.V << a.V, (a.V.rowwise() + Eigen::RowVector3d(5, 0, 0));
  two.F.resize(2 * a.F.rows(), 3);
  two.F << a.F, (a.F.array() + static_cast<int>(a.V.rows())).matrix();
  const MeshCheckReport report = check_mesh(two);
  EXPECT_EQ(report.connected_components, 2);
  EXPECT_TRUE(report.watertight());
  EXPECT_EQ(report.euler_characteristic, 4);
}

TEST(MeshCheckTest, RejectsOutOfRangeIndex) {
  IndexedMesh cube = unit_cube();
  cube.F(5, 2) = 42;
  EXPECT_THROW(check_mesh(cube), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh
