#include "core/landmarks/triangulation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.h"

namespace mmm::landmarks {
namespace {

using image::RadiographView;

// A standing adult's right leg in a field centred at knee height.
std::array<RadiographView, 2> knee_centred_views() {
  image::BiplanarOptions options;
  options.isocentre_mm = {0, 0, 500};
  return image::make_biplanar_views(options);
}

std::vector<Eigen::Vector2d> project_all(std::span<const RadiographView> views,
                                         const Eigen::Vector3d& X) {
  std::vector<Eigen::Vector2d> pixels;
  for (const RadiographView& view : views) pixels.push_back(image::project(view, X));
  return pixels;
}

// 1/2 sum of squared reprojection errors (mm^2): Ceres' cost.
double cost(std::span<const RadiographView> views, std::span<const Eigen::Vector2d> pixels,
            const Eigen::Vector3d& X) {
  double sum = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    sum += std::pow(image::reprojection_error_mm(views[i], X, pixels[i]), 2);
  }
  return 0.5 * sum;
}

TEST(TriangulationTest, ExactPixelsGiveThePoint) {
  const auto views = knee_centred_views();
  for (const Eigen::Vector3d& X :
       {Eigen::Vector3d(90, 0, 900), Eigen::Vector3d(80, 30, 480), Eigen::Vector3d(75, 0, 80)}) {
    const std::vector<Eigen::Vector2d> pixels = project_all(views, X);
    const Triangulation result = triangulate(views, pixels);
    // Exact pixels: only rounding (coordinates ~1e3 mm, pixels ~1e3) separates them.
    EXPECT_LT((result.point_mm - X).norm(), 1e-6);
    ASSERT_EQ(result.reprojection_error_mm.size(), 2U);
    for (const double error : result.reprojection_error_mm) EXPECT_LT(error, 1e-6);
    EXPECT_LT(result.rms_error_mm, 1e-6);
    EXPECT_LE(result.final_cost, result.initial_cost);
    EXPECT_FALSE(result.termination.empty());
    EXPECT_FALSE(result.solver_report.empty());
  }
}

TEST(TriangulationTest, NoisyPixelsCostNoMoreThanTheLinearPoint) {
  const auto views = knee_centred_views();
  std::mt19937 rng(20240611);
  // 3 pixels of click noise (0.7 mm at the isocentre).
  std::normal_distribution<double> noise(0.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d X(80 + trial, 30 - trial, 480 + 20 * trial);
    std::vector<Eigen::Vector2d> pixels = project_all(views, X);
    for (Eigen::Vector2d& pixel : pixels) pixel += Eigen::Vector2d(noise(rng), noise(rng));
    const Triangulation result = triangulate(views, pixels);
    EXPECT_TRUE(result.converged) << result.solver_report;
    const double linear_cost = cost(views, pixels, result.linear_point_mm);
    const double refined_cost = cost(views, pixels, result.point_mm);
    // Ceres minimises this very cost from the linear point: it cannot end
    // higher (1e-12 mm^2: rounding of costs of order 1 mm^2).
    EXPECT_LE(refined_cost, linear_cost + 1e-12);
    EXPECT_NEAR(result.initial_cost, linear_cost, 1e-9 * (1 + linear_cost));
    EXPECT_NEAR(result.final_cost, refined_cost, 1e-9 * (1 + refined_cost));
    // The per-view errors are those of projection.h at the refined point.
    for (std::size_t i = 0; i < views.size(); ++i) {
      EXPECT_DOUBLE_EQ(result.reprojection_error_mm[i],
                       image::reprojection_error_mm(views[i], result.point_mm, pixels[i]));
    }
    // Noise of 0.7 mm per coordinate moves the point by a few mm at most.
    EXPECT_LT((result.point_mm - X).norm(), 5.0);
  }
}

TEST(TriangulationTest, ThreeViewsOfDifferentResolution) {
  // A third view at 1/4 of the resolution (the frontal geometry with a
  // coarser detector): exact pixels still give the point, and its error is
  // counted in mm (a pixel there is 4 times as many mm).
  const auto pair = knee_centred_views();
  image::BiplanarOptions coarse_options;
  coarse_options.isocentre_mm = {0, 0, 500};
  coarse_options.detector_pixel_pitch_mm = 1.2;
  RadiographView oblique = image::make_biplanar_views(coarse_options)[0];
  oblique.name = "oblique";
  const std::vector<RadiographView> views = {pair[0], pair[1], oblique};
  const Eigen::Vector3d X(90, 0, 900);
  const std::vector<Eigen::Vector2d> pixels = project_all(views, X);
  const Triangulation result = triangulate(views, pixels);
  EXPECT_LT((result.point_mm - X).norm(), 1e-6);  // rounding, as above
  // The isocentre, one pixel off in the coarse view's u alone. Near the
  // isocentre only the frontal and coarse views see x (it lies on the
  // lateral view's central ray), so the fit splits the disagreement between
  // them: equal shares in mm (0.46 mm each, half the coarse spacing), not in
  // pixels (which would leave the coarse view almost all of it).
  const Eigen::Vector3d iso(0, 0, 500);
  std::vector<Eigen::Vector2d> off = project_all(views, iso);
  off[2].x() += 1.0;
  const Triangulation moved = triangulate(views, off);
  // Second-order terms of a 0.5 mm move at 1300 mm: ~1e-7 mm.
  EXPECT_NEAR(moved.reprojection_error_mm[0], 0.5 * oblique.pixel_spacing_mm, 1e-6);
  EXPECT_NEAR(moved.reprojection_error_mm[2], 0.5 * oblique.pixel_spacing_mm, 1e-6);
  EXPECT_LT(moved.reprojection_error_mm[1], 1e-6);
}

TEST(TriangulationTest, DegenerateInputIsRejected) {
  const auto views = knee_centred_views();
  const Eigen::Vector3d X(80, 30, 480);
  const std::vector<Eigen::Vector2d> pixels = project_all(views, X);
  // One view.
  EXPECT_THROW(triangulate(std::span(views).first(1), std::span(pixels).first(1)),
               InvalidInputError);
  // Counts that differ.
  EXPECT_THROW(triangulate(views, std::span(pixels).first(1)), InvalidInputError);
  // The same view twice: parallel rays.
  const std::array<RadiographView, 2> twice = {views[0], views[0]};
  const std::array<Eigen::Vector2d, 2> same = {pixels[0], pixels[0]};
  EXPECT_THROW(triangulate(twice, same), InvalidInputError);
  // A non-finite pixel.
  std::vector<Eigen::Vector2d> bad = pixels;
  bad[1].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(triangulate(views, bad), InvalidInputError);
  // Options out of range.
  TriangulationOptions options;
  options.max_iterations = 0;
  EXPECT_THROW(triangulate(views, pixels, options), InvalidInputError);
}

}  // namespace
}  // namespace mmm::landmarks
