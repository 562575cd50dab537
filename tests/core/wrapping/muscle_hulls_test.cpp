// Stored hulls: the containment check (no vertex of the surface outside its
// hull, checked again here independently), the content hash that decides
// reuse, a bit-identical round trip through the hull folder, and errors that
// name the file.

#include "core/wrapping/muscle_hulls.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/primitives.h"
#include "core/mesh/signed_distance.h"
#include "tests/support/test_data.h"

namespace mmm::wrapping {
namespace {

// A lumpy closed surface (a sphere with bumps), so that the hull has
// something to enclose.
mesh::IndexedMesh lumpy_sphere() {
  mesh::IndexedMesh surface = mesh::make_icosphere(4, 20.0);
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v) {
    const Eigen::Vector3d p = surface.V.row(v).transpose();
    const double bump = 1.0 + 0.15 * std::sin(3.0 * p.x() / 20.0) * std::cos(4.0 * p.z() / 20.0);
    surface.V.row(v) = (p * bump).transpose();
  }
  return surface;
}

TEST(MuscleHullsTest, NoVertexOfTheSurfaceLiesOutsideItsHull) {
  const mesh::IndexedMesh surface = lumpy_sphere();
  const MuscleHull hull = build_muscle_hull("lumpy", surface, 300);
  EXPECT_LE(hull.hull.F.rows(), 300);
  EXPECT_GE(hull.hull.F.rows(), 299);
  EXPECT_EQ(hull.report.vertices_outside, 0);
  EXPECT_GT(hull.report.volume_after, hull.report.volume_before);
  // Independently of the report: every surface vertex inside or on the hull.
  const mesh::SignedDistance distance(hull.hull);
  double worst = -1e9;
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v)
    worst = std::max(worst, distance.at(surface.V.row(v).transpose()));
  EXPECT_LE(worst, mesh::kProgressiveHullOnSurfaceTolerance);
  EXPECT_EQ(hull.source_hash, mesh_hash(surface));
}

TEST(MuscleHullsTest, TheHashFollowsTheContent) {
  const mesh::IndexedMesh surface = lumpy_sphere();
  EXPECT_EQ(mesh_hash(surface), mesh_hash(lumpy_sphere()));
  EXPECT_EQ(mesh_hash(surface).size(), 64U);
  mesh::IndexedMesh moved = surface;
  moved.V(7, 2) += 1e-12;
  EXPECT_NE(mesh_hash(moved), mesh_hash(surface));
  mesh::IndexedMesh flipped = surface;
  std::swap(flipped.F(0, 1), flipped.F(0, 2));
  EXPECT_NE(mesh_hash(flipped), mesh_hash(surface));
}

TEST(MuscleHullsTest, AStoredHullIsFoundOnlyForItsSurfaceAndFaceCount) {
  const mesh::IndexedMesh surface = lumpy_sphere();
  const std::vector<MuscleHull> hulls = {build_muscle_hull("lumpy", surface, 300)};
  const std::string hash = mesh_hash(surface);
  EXPECT_EQ(find_hull(hulls, "lumpy", hash, 300), &hulls.front());
  EXPECT_EQ(find_hull(hulls, "lumpy", hash, 400), nullptr);
  EXPECT_EQ(find_hull(hulls, "other", hash, 300), nullptr);
  EXPECT_EQ(find_hull(hulls, "lumpy", mesh_hash(mesh::make_icosphere(2, 5.0)), 300), nullptr);
}

TEST(MuscleHullsTest, AHullFolderReadsBackBitIdentical) {
  const test::ScratchDir dir("muscle_hulls");
  const mesh::IndexedMesh surface = lumpy_sphere();
  const std::vector<MuscleHull> written = {build_muscle_hull("lumpy", surface, 300),
                                           build_muscle_hull("ball", mesh::make_icosphere(3), 100)};
  write_hulls(dir.path() / "hulls", written);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "hulls" / "lumpy.ply"));
  const std::vector<MuscleHull> read = read_hulls(dir.path() / "hulls");
  ASSERT_EQ(read.size(), 2U);
  for (std::size_t h = 0; h < read.size(); ++h) {
    EXPECT_EQ(read[h].muscle, written[h].muscle);
    EXPECT_EQ(read[h].source_hash, written[h].source_hash);
    EXPECT_EQ(read[h].faces_asked, written[h].faces_asked);
    EXPECT_EQ(read[h].hull.V, written[h].hull.V);
    EXPECT_EQ(read[h].hull.F, written[h].hull.F);
    EXPECT_EQ(read[h].report.vertices_outside, written[h].report.vertices_outside);
    EXPECT_DOUBLE_EQ(read[h].report.volume_after, written[h].report.volume_after);
  }
}

TEST(MuscleHullsTest, BrokenHullFoldersAreErrorsNamingTheFile) {
  const test::ScratchDir dir("muscle_hulls");
  const auto message_of = [](const std::filesystem::path& folder) {
    try {
      (void)read_hulls(folder);
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message_of(dir.path() / "none").find("hulls.json"), std::string::npos);

  write_hulls(dir.path() / "h", {build_muscle_hull("ball", mesh::make_icosphere(3), 100)});
  std::filesystem::remove(dir.path() / "h" / "ball.ply");
  EXPECT_NE(message_of(dir.path() / "h").find("ball.ply"), std::string::npos);

  write_hulls(dir.path() / "h", {build_muscle_hull("ball", mesh::make_icosphere(3), 100)});
  std::ofstream(dir.path() / "h" / "hulls.json") << R"({"hulls": [{"muscle": 3}]})";
  EXPECT_NE(message_of(dir.path() / "h").find("malformed hull index"), std::string::npos);

  write_hulls(dir.path() / "h", {build_muscle_hull("ball", mesh::make_icosphere(3), 100)});
  mesh::write_mesh(mesh::make_icosphere(1), dir.path() / "h" / "ball.ply");
  EXPECT_NE(message_of(dir.path() / "h").find("rebuild the hulls"), std::string::npos);
}

}  // namespace
}  // namespace mmm::wrapping
