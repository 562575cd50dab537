#include "core/volumetric/lattice_tets.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/primitives.h"

namespace mmm::volumetric {
namespace {

using mesh::IndexedMesh;

std::set<std::array<int, 3>> sorted_faces(const IndexedMesh& surface) {
  std::set<std::array<int, 3>> out;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    std::array<int, 3> face = {surface.F(f, 0), surface.F(f, 1), surface.F(f, 2)};
    std::ranges::sort(face);
    out.insert(face);
  }
  return out;
}

// Two touching boxes: the six tetrahedra per cell fill them exactly, with
// positive volumes; each box's boundary is closed and outward; the faces on
// the plane where they touch are the same nodes in both (one interface).
TEST(LatticeTetsTest, TwoTouchingBoxesShareOneInterface) {
  const IndexedMesh a = mesh::make_box({0.0, 0.0, 0.0}, {30.0, 30.0, 30.0});
  const IndexedMesh b = mesh::make_box({30.0, 0.0, 0.0}, {60.0, 30.0, 30.0});
  const LabelledLattice lattice = build_labelled_lattice(
      {{"a", &a}, {"b", &b}}, {}, {.spacing_mm = 3.0, .max_regrowth_mm = 0.0});
  const TetMesh tets = lattice_tets(lattice);
  EXPECT_EQ(tets.T.rows(), 6 * 2 * 1000);
  const Eigen::VectorXd volumes = tet_volumes(tets);
  EXPECT_GT(volumes.minCoeff(), 0.0);
  EXPECT_NEAR(volumes.sum(), 2.0 * 27000.0, 1e-6);
  const IndexedMesh boundary_a = label_boundary(tets, 1);
  const IndexedMesh boundary_b = label_boundary(tets, 2);
  for (const IndexedMesh* s : {&boundary_a, &boundary_b}) {
    const mesh::MeshCheckReport report = mesh::check_mesh(*s);
    EXPECT_TRUE(report.closed());
    EXPECT_TRUE(report.orientation_consistent());
    EXPECT_NEAR(mesh::signed_volume(*s), 27000.0, 1e-6);  // outward, exactly the cells
  }
  std::set<std::array<int, 3>> shared;
  std::ranges::set_intersection(sorted_faces(boundary_a), sorted_faces(boundary_b),
                                std::inserter(shared, shared.begin()));
  EXPECT_EQ(shared.size(), 2U * 10U * 10U);  // the x = 30 plane, two triangles per cell face
  for (const std::array<int, 3>& face : shared) {
    for (const int v : face) EXPECT_NEAR(tets.V(v, 0), 30.0, 1e-9);
  }
  // The nodes both surfaces use are the interface's 11 x 11: moving one moves
  // both muscles' surfaces, there is nothing to keep in step.
  std::set<int> used_a(boundary_a.F.data(), boundary_a.F.data() + boundary_a.F.size());
  std::set<int> used_b(boundary_b.F.data(), boundary_b.F.data() + boundary_b.F.size());
  std::set<int> both;
  std::ranges::set_intersection(used_a, used_b, std::inserter(both, both.begin()));
  EXPECT_EQ(both.size(), 11U * 11U);
}

TEST(LatticeTetsTest, ASphereBoundaryEnclosesItsCells) {
  const IndexedMesh sphere = mesh::make_icosphere(4, 12.0);
  const LabelledLattice lattice =
      build_labelled_lattice({{"ball", &sphere}}, {}, {.spacing_mm = 1.5});
  const TetMesh tets = lattice_tets(lattice);
  const IndexedMesh boundary = label_boundary(tets, 1);
  EXPECT_NEAR(mesh::signed_volume(boundary), lattice.muscles[0].kept_mm3, 1e-6);
  EXPECT_NEAR(tet_volumes(tets).sum(), lattice.muscles[0].kept_mm3, 1e-6);
  EXPECT_TRUE(mesh::check_mesh(boundary).closed());
  EXPECT_THROW((void)label_boundary(tets, 2), InvalidInputError);
}

}  // namespace
}  // namespace mmm::volumetric
