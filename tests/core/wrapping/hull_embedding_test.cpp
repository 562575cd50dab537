// A fine surface carried by its hull: at rest it stays where it is, a rigid
// motion of the hull moves it by exactly that motion, and a stretched hull
// stretches it the same way along the stretch.

#include "core/wrapping/hull_embedding.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/mesh/progressive_hull.h"

namespace mmm::wrapping {
namespace {

struct FineAndHull {
  mesh::IndexedMesh fine;
  mesh::IndexedMesh hull;
};

FineAndHull sphere_and_hull() {
  FineAndHull result;
  result.fine = mesh::make_icosphere(4, 20.0);  // 5120 faces
  mesh::ProgressiveHullOptions options;
  options.target_faces = 200;
  result.hull = mesh::progressive_hull(result.fine, options);
  return result;
}

TEST(HullEmbeddingTest, TheRestHullGivesTheRestSurface) {
  const FineAndHull meshes = sphere_and_hull();
  const HullEmbedding embedding(meshes.hull, meshes.fine.V);
  const HullEmbedding::Transfer transfer = embedding.transfer(meshes.hull.V);
  EXPECT_LT((transfer.positions - meshes.fine.V).cwiseAbs().maxCoeff(), 1e-9);
  for (const Eigen::Matrix3d& rotation : transfer.rotations)
    EXPECT_LT((rotation - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  // The fine sphere lies inside its hull, a few tenths of a millimetre at most.
  EXPECT_GT(embedding.max_offset(), 0.0);
  EXPECT_LT(embedding.max_offset(), 3.0);
}

TEST(HullEmbeddingTest, ARigidMotionOfTheHullMovesTheSurfaceRigidly) {
  const FineAndHull meshes = sphere_and_hull();
  const HullEmbedding embedding(meshes.hull, meshes.fine.V);
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()));
  motion.translation() = Eigen::Vector3d(30, -12, 55);
  Eigen::MatrixX3d moved_hull = meshes.hull.V;
  for (Eigen::Index v = 0; v < moved_hull.rows(); ++v)
    moved_hull.row(v) = (motion * Eigen::Vector3d(meshes.hull.V.row(v))).transpose();
  const HullEmbedding::Transfer transfer = embedding.transfer(moved_hull);
  double worst = 0.0;
  for (Eigen::Index v = 0; v < meshes.fine.V.rows(); ++v) {
    const Eigen::Vector3d expected = motion * Eigen::Vector3d(meshes.fine.V.row(v));
    worst = std::max(worst, (transfer.positions.row(v).transpose() - expected).norm());
    EXPECT_LT((transfer.rotations[static_cast<std::size_t>(v)] - motion.linear()).norm(), 1e-9);
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(HullEmbeddingTest, AStretchedHullStretchesTheSurfaceAlongIt) {
  const FineAndHull meshes = sphere_and_hull();
  const HullEmbedding embedding(meshes.hull, meshes.fine.V);
  const Eigen::Vector3d scale(1.5, 1.0, 1.0);
  const Eigen::MatrixX3d stretched = meshes.hull.V * scale.asDiagonal();
  const HullEmbedding::Transfer transfer = embedding.transfer(stretched);
  // A point of the fine sphere maps to the stretched sphere up to its
  // (small) offset inside the hull: the x axis stretches by 1.5, within the
  // offset; y and z stay within it.
  const double slack = 1.5 * embedding.max_offset() + 1e-9;
  for (Eigen::Index v = 0; v < meshes.fine.V.rows(); ++v) {
    const Eigen::Vector3d expected = scale.asDiagonal() * Eigen::Vector3d(meshes.fine.V.row(v));
    EXPECT_LT((transfer.positions.row(v).transpose() - expected).norm(), slack) << v;
  }
}

TEST(HullEmbeddingTest, WrongInputIsAnError) {
  const FineAndHull meshes = sphere_and_hull();
  EXPECT_THROW(HullEmbedding(mesh::IndexedMesh{}, meshes.fine.V), InvalidInputError);
  Eigen::MatrixX3d nan_fine = meshes.fine.V;
  nan_fine(3, 1) = std::nan("");
  EXPECT_THROW(HullEmbedding(meshes.hull, nan_fine), InvalidInputError);
  const HullEmbedding embedding(meshes.hull, meshes.fine.V);
  EXPECT_THROW((void)embedding.transfer(meshes.fine.V), InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping
