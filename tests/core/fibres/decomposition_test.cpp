// The contour decompositions on a cylinder muscle with its attachments on
// the end discs: the harmonic field is exactly z / length (a linear
// function is harmonic on a cylinder's side), its level sets are the rings;
// fibres of the parallel template run straight along the axis in their
// middle part, end on the discs, stay inside, and do not cross; the other
// templates keep every fibre inside too.

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/fibres/end_patches.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/fibre_templates.h"
#include "core/fibres/harmonic_decomposition.h"
#include "core/fibres/harmonic_field.h"
#include "core/fibres/slicing_decomposition.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/winding_number.h"
#include "tests/core/fibres/muscle_shapes.h"

namespace mmm::fibres {
namespace {

constexpr double kRadius = 10.0;
constexpr double kLength = 100.0;

int points_outside(const mesh::IndexedMesh& surface, const std::vector<Fibre>& fibres,
                   double tolerance) {
  const mesh::AabbTree tree(surface);
  const mesh::WindingNumber inside(tree);
  int outside = 0;
  for (const Fibre& fibre : fibres) {
    for (Eigen::Index k = 0; k < fibre.rows(); ++k) {
      const Eigen::Vector3d p = fibre.row(k).transpose();
      if (!inside.is_inside(p) && tree.closest_point(p).squared_distance > tolerance * tolerance) {
        ++outside;
      }
    }
  }
  return outside;
}

TEST(FibreTemplates, LabelsFillTheSquareAndTemplatesStayInIt) {
  const std::vector<Eigen::Vector2d> labels = fibre_labels(81);
  ASSERT_EQ(labels.size(), 81U);
  EXPECT_NEAR(labels.front().x(), 1.0 / 18.0, 1e-12);
  EXPECT_NEAR(labels.back().y(), 17.0 / 18.0, 1e-12);
  EXPECT_EQ(fibre_labels(10).size(), 10U);  // 4 columns, 3 rows, the last one short
  for (const auto architecture :
       {atlas::FibreArchitecture::kParallel, atlas::FibreArchitecture::kFanned,
        atlas::FibreArchitecture::kPennate, atlas::FibreArchitecture::kCurved}) {
    for (const TemplateFibre& fibre : fibre_template(architecture, 49)) {
      for (int k = 0; k <= 20; ++k) {
        const Eigen::Vector2d uv = fibre.at(k / 20.0);
        EXPECT_GE(uv.minCoeff(), 0.0);
        EXPECT_LE(uv.maxCoeff(), 1.0);
      }
    }
  }
  // Fanned: the narrow end spans a third of the broad one.
  const std::vector<TemplateFibre> fan = fibre_template(atlas::FibreArchitecture::kFanned, 81);
  EXPECT_NEAR(fan.back().at(1.0).x() - fan.front().at(1.0).x(),
              (fan.back().at(0.0).x() - fan.front().at(0.0).x()) / 3.0, 1e-12);
  EXPECT_THROW((void)fibre_labels(0), InvalidInputError);
}

TEST(HarmonicField, IsTheHeightOnACylinder) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  const EndPatches ends =
      end_patches(cylinder, testing::cylinder_attachments(kRadius, kLength), 1.5);
  EXPECT_LT(ends.origin_gap_mm, 1e-9);
  EXPECT_EQ(ends.origin.size(), 49U);  // the bottom ring and the cap's centre
  EXPECT_EQ(ends.insertion.size(), 49U);
  const Eigen::VectorXd field = harmonic_field(cylinder, ends);
  const Eigen::VectorXd expected = cylinder.V.col(2) / kLength;
  EXPECT_LT((field - expected).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(HarmonicField, RefusesMissingAttachments) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 16, 4);
  EXPECT_THROW((void)harmonic_field(cylinder, {{}, {1, 2}}), InvalidInputError);
  EXPECT_THROW((void)harmonic_field(cylinder, {{1}, {1}}), InvalidInputError);
}

void expect_parallel_fibres(const std::vector<Fibre>& fibres, const mesh::IndexedMesh& surface) {
  ASSERT_EQ(fibres.size(), 81U);
  for (const Fibre& fibre : fibres) {
    ASSERT_EQ(fibre.rows(), 21);
    // Ends on the end discs (the surface points nearest their attachment point).
    EXPECT_LT(std::abs(fibre(0, 2)), 1e-6);
    EXPECT_LT(std::abs(fibre(20, 2) - kLength), 1e-6);
    // The middle part runs along the axis: x, y constant to 0.1 mm.
    const Eigen::MatrixX3d middle = fibre.middleRows(4, 13);
    const Eigen::RowVector3d mean = middle.colwise().mean();
    EXPECT_LT((middle.leftCols(2).rowwise() - mean.leftCols(2)).rowwise().norm().maxCoeff(), 0.1);
    EXPECT_NEAR(fibre_length(fibre), kLength, 3.0);
  }
  EXPECT_EQ(points_outside(surface, fibres, 1e-6), 0);
  // The fibres spread over the section without meeting: nearest neighbours
  // at mid-length at least 1 mm apart, and some near the rim.
  double nearest = 1e9;
  double widest = 0.0;
  for (std::size_t i = 0; i < fibres.size(); ++i) {
    widest = std::max(widest, fibres[i].row(10).leftCols(2).norm());
    for (std::size_t j = i + 1; j < fibres.size(); ++j) {
      nearest = std::min(nearest, (fibres[i].row(10) - fibres[j].row(10)).norm());
    }
  }
  EXPECT_GT(nearest, 1.0);
  EXPECT_GT(widest, 0.7 * kRadius);
}

TEST(SlicingDecomposition, ParallelFibresOfACylinder) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  const SlicingResult result =
      slicing_fibres(cylinder, testing::cylinder_attachments(kRadius, kLength));
  EXPECT_EQ(result.interpolated_contours, 0);
  EXPECT_EQ(result.contours.size(), 21U);
  EXPECT_NEAR(result.axes.axis.z(), 1.0, 1e-12);
  expect_parallel_fibres(result.fibres, cylinder);
}

TEST(HarmonicDecomposition, ParallelFibresOfACylinder) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  const Attachments attachments = testing::cylinder_attachments(kRadius, kLength);
  const Eigen::VectorXd field = harmonic_field(cylinder, end_patches(cylinder, attachments));
  const HarmonicResult result = harmonic_fibres(cylinder, attachments, field);
  EXPECT_EQ(result.interpolated_contours, 0);
  // The level sets are the cylinder's cross-sections.
  for (const Contour& contour : result.contours) {
    EXPECT_LT(contour.col(2).maxCoeff() - contour.col(2).minCoeff(), 1e-9);
  }
  expect_parallel_fibres(result.fibres, cylinder);
}

TEST(SlicingDecomposition, EveryTemplateStaysInside) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  for (const auto architecture :
       {atlas::FibreArchitecture::kFanned, atlas::FibreArchitecture::kPennate,
        atlas::FibreArchitecture::kCurved}) {
    DecompositionOptions options;
    options.architecture = architecture;
    options.fibres = 64;
    options.segments = 30;
    const SlicingResult result =
        slicing_fibres(cylinder, testing::cylinder_attachments(kRadius, kLength), options);
    ASSERT_EQ(result.fibres.size(), 64U);
    EXPECT_EQ(result.fibres.front().rows(), 31);
    EXPECT_EQ(points_outside(cylinder, result.fibres, 1e-6), 0);
  }
}

TEST(SlicingDecomposition, BadInputIsRefused) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 16, 4);
  const Attachments attachments = testing::cylinder_attachments(kRadius, kLength);
  DecompositionOptions options;
  options.segments = 1;
  EXPECT_THROW((void)slicing_fibres(cylinder, attachments, options), InvalidInputError);
  options = {};
  options.contour_points = 60;
  EXPECT_THROW((void)slicing_fibres(cylinder, attachments, options), InvalidInputError);
  Attachments none = attachments;
  none.insertion.resize(0, 3);
  EXPECT_THROW((void)slicing_fibres(cylinder, none, {}), InvalidInputError);
  Attachments same = attachments;
  same.insertion = same.origin;
  EXPECT_THROW((void)slicing_fibres(cylinder, same, {}), InvalidInputError);
  EXPECT_THROW((void)harmonic_fibres(cylinder, attachments, Eigen::VectorXd::Zero(3)),
               InvalidInputError);
}

// The end patches of a cylinder whose end discs are its attachment areas:
// each disc and the side ring within the margin; an area 10 mm beyond the
// top (a tendon) gives the gap and the same top patch.
TEST(EndPatches, AreTheEndCapsWithOrWithoutATendonGap) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  Attachments areas = testing::cylinder_attachments(kRadius, kLength);
  const EndPatches touching = end_patches(cylinder, areas, 1.5);
  EXPECT_LT(touching.insertion_gap_mm, 1e-9);
  areas.insertion.col(2).array() += 10.0;
  const EndPatches beyond = end_patches(cylinder, areas, 1.5);
  EXPECT_NEAR(beyond.insertion_gap_mm, 10.0, 1e-9);  // the cap's centre, straight below
  EXPECT_EQ(beyond.insertion, touching.insertion);
  EXPECT_EQ(beyond.origin, touching.origin);
  for (const int v : beyond.insertion) {
    EXPECT_NEAR(cylinder.V(v, 2), kLength, 1e-9);
  }
  // The attachments the methods take: the patch vertices where the surface is now.
  Eigen::MatrixX3d moved = cylinder.V;
  moved.col(0).array() += 4.0;
  const Attachments at = patch_attachments(beyond, moved, areas);
  ASSERT_EQ(at.insertion.rows(), static_cast<Eigen::Index>(beyond.insertion.size()));
  EXPECT_EQ(at.insertion.row(0), moved.row(beyond.insertion.front()));
  EXPECT_NEAR(patch_gap(beyond.insertion, cylinder.V, areas.insertion), 10.0, 1e-9);
  EXPECT_THROW((void)end_patches(cylinder, areas, -1.0), InvalidInputError);
  areas.origin.resize(0, 3);
  EXPECT_THROW((void)end_patches(cylinder, areas), InvalidInputError);
}

// Fibres that stop short of the discs are connected to the nearest disc
// point: on the disc to 1e-9 (the closest surface point of a disc point is
// itself), straight where the cylinder is straight, none outside.
TEST(ConnectToNearestAttachments, CarriesShortFibresOntoTheDiscs) {
  const mesh::IndexedMesh cylinder = testing::ringed_cylinder(kRadius, kLength, 48, 40);
  const Attachments areas = testing::cylinder_attachments(kRadius, kLength);
  std::vector<Fibre> fibres;
  for (const double x : {-4.0, 0.0, 4.0}) {  // at y = 1
    Fibre f(11, 3);
    for (int k = 0; k <= 10; ++k) f.row(k) << x, 1.0, 15.0 + 5.0 * k;
    fibres.push_back(f);
  }
  const int moved = connect_to_nearest_attachments(fibres, cylinder, areas, 20, 2);
  // Only the six ends: on the discs, the winding number calls them outside
  // and keep_inside puts them back onto the surface (where they are).
  EXPECT_EQ(moved, 6);
  const std::vector<double> xs = {-4.0, 0.0, 4.0};
  for (std::size_t i = 0; i < fibres.size(); ++i) {
    const Fibre& f = fibres[i];
    ASSERT_EQ(f.rows(), 21);
    EXPECT_NEAR(f(0, 2), 0.0, 1e-9);
    EXPECT_NEAR(f(20, 2), kLength, 1e-9);
    // The nearest disc point of (x, 1) is within the disc grid's spacing of it.
    const Eigen::Vector2d own(xs[i], 1.0);
    EXPECT_LT((f.row(0).head<2>().transpose() - own).norm(), 2.0);
    EXPECT_LT((f.row(20).head<2>().transpose() - own).norm(), 2.0);
    // The middle stays where it was.
    EXPECT_LT((f.row(10).head<2>().transpose() - own).norm(), 0.1);
  }
  EXPECT_EQ(points_outside(cylinder, fibres, 1e-6), 0);
}

}  // namespace
}  // namespace mmm::fibres
