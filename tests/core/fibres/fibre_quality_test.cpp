// Fibre quality on a closed cylinder (radius 10 mm, z from 0 to 100 mm) whose
// attachment areas are its end discs: a 3 x 3 grid of straight fibres scores
// perfectly and covers exactly the disc points a brute-force count finds; a
// fibre bulging to 15 mm has exactly its outside vertices counted; ends 3 mm
// off the discs give end distances of 3; uneven fibres give the hand-computed
// length and spacing spreads; and bad input is refused naming what is wrong.

#include "core/fibres/fibre_quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/fibres/t_polynomial.h"
#include "core/mesh/primitives.h"

namespace mmm::fibres {
namespace {

using Eigen::MatrixX3d;
using Eigen::Vector3d;

// 64 sides: a vertex at angle 0, so the surface passes through (10, 0, z).
mesh::IndexedMesh cylinder() { return mesh::make_cylinder(10.0, 100.0, 64); }

// Straight fibre at (x, y) from z = z0 to z = z1, `points` evenly spaced.
Fibre straight(double x, double y, double z0, double z1, int points = 21) {
  Fibre fibre(points, 3);
  for (int k = 0; k < points; ++k) fibre.row(k) << x, y, z0 + (z1 - z0) * k / (points - 1);
  return fibre;
}

// The 3 x 3 grid x, y in {-5, 0, 5}.
std::vector<Fibre> grid(double z0 = 0.0, double z1 = 100.0) {
  std::vector<Fibre> fibres;
  for (const double x : {-5.0, 0.0, 5.0})
    for (const double y : {-5.0, 0.0, 5.0}) fibres.push_back(straight(x, y, z0, z1));
  return fibres;
}

// Integer points (x, y) with x^2 + y^2 <= 100 on the plane z: 317 points, all
// distances to the grid's ends are square roots of integers, so "within 5" is
// decided exactly.
MatrixX3d disc(double z) {
  std::vector<Vector3d> points;
  for (int x = -10; x <= 10; ++x)
    for (int y = -10; y <= 10; ++y)
      if (x * x + y * y <= 100) points.emplace_back(x, y, z);
  MatrixX3d result(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    result.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  return result;
}

TEST(FibreQualityTest, AGridOfStraightFibresInACylinderScoresPerfectly) {
  const std::vector<Fibre> fibres = grid();
  const MatrixX3d origin = disc(0.0);
  const MatrixX3d insertion = disc(100.0);
  ASSERT_EQ(origin.rows(), 317);
  const FibreQuality quality = measure_fibre_quality(cylinder(), fibres, origin, insertion);
  EXPECT_EQ(quality.fibres, 9);
  EXPECT_EQ(quality.vertices, 9 * 21);
  EXPECT_EQ(quality.inside_fraction, 1.0);
  // Every end is a disc point: exactly 0.
  EXPECT_EQ(quality.origin_end_distance_median_mm, 0.0);
  EXPECT_EQ(quality.origin_end_distance_max_mm, 0.0);
  EXPECT_EQ(quality.insertion_end_distance_median_mm, 0.0);
  EXPECT_EQ(quality.insertion_end_distance_max_mm, 0.0);
  // 20 steps of 5 mm are exact in binary: exactly 100 mm, cv exactly 0.
  EXPECT_EQ(quality.length_median_mm, 100.0);
  EXPECT_EQ(quality.length_min_mm, 100.0);
  EXPECT_EQ(quality.length_max_mm, 100.0);
  EXPECT_EQ(quality.length_cv, 0.0);
  // Every fibre's nearest neighbour is one grid step (5 mm) away at every level.
  EXPECT_EQ(quality.spacing_mean_mm, 5.0);
  EXPECT_EQ(quality.spacing_cv, 0.0);
  // A line is a polynomial: only rounding of the least-squares solve remains.
  EXPECT_LT(quality.fit_error_max_mm, 1e-9);
  EXPECT_LE(quality.fit_error_mean_mm, quality.fit_error_max_mm);

  // Coverage by brute force over the integer disc points (exact arithmetic):
  // at 5 mm the grid's ends reach every point, even the rim's (10, 0) and
  // (8, 6); at 3 mm they miss the 80 points farther than 3 mm from all ends.
  const auto covered = [](int radius_squared) {
    int count = 0;
    for (int x = -10; x <= 10; ++x) {
      for (int y = -10; y <= 10; ++y) {
        if (x * x + y * y > 100) continue;
        bool near = false;
        for (const int ex : {-5, 0, 5})
          for (const int ey : {-5, 0, 5})
            near = near || (x - ex) * (x - ex) + (y - ey) * (y - ey) <= radius_squared;
        count += near ? 1 : 0;
      }
    }
    return count;
  };
  EXPECT_EQ(covered(25), 317);
  EXPECT_EQ(quality.origin_coverage, 1.0);
  EXPECT_EQ(quality.insertion_coverage, 1.0);
  FibreQualityOptions three_mm;
  three_mm.coverage_radius_mm = 3.0;
  const FibreQuality narrow =
      measure_fibre_quality(cylinder(), fibres, origin, insertion, three_mm);
  EXPECT_EQ(covered(9), 237);
  EXPECT_DOUBLE_EQ(narrow.origin_coverage, 237.0 / 317.0);
  EXPECT_DOUBLE_EQ(narrow.insertion_coverage, 237.0 / 317.0);
}

TEST(FibreQualityTest, CoverageOfRingsIsTheAreaFraction) {
  // Rings of radius i + 0.5 (i = 0..9) with 6 (2 i + 1) points each, about
  // one point per 0.5 mm^2: a single central fibre reaches the five rings
  // inside 5 mm, 6 (1 + 3 + 5 + 7 + 9) = 150 of 600 points, the area
  // fraction (5 / 10)^2 = 1/4. No ring lies at 5 mm, so rounding cannot
  // move a point across the radius.
  std::vector<Vector3d> points;
  for (int i = 0; i < 10; ++i) {
    const int count = 6 * (2 * i + 1);
    for (int j = 0; j < count; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / count;
      points.emplace_back((i + 0.5) * std::cos(angle), (i + 0.5) * std::sin(angle), 0.0);
    }
  }
  MatrixX3d origin(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    origin.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  ASSERT_EQ(origin.rows(), 600);
  const FibreQuality quality =
      measure_fibre_quality(cylinder(), {straight(0, 0, 0, 100)}, origin, disc(100.0));
  EXPECT_EQ(quality.origin_coverage, 0.25);
  EXPECT_DOUBLE_EQ(quality.origin_end_distance_max_mm, 0.5);  // the innermost ring
  // One fibre has no neighbour: no spacing at all.
  EXPECT_EQ(quality.spacing_mean_mm, 0.0);
  EXPECT_EQ(quality.spacing_cv, 0.0);
}

// x = 15 sin(pi k / 20) at z = 5 k: outside the 10 mm cylinder by more than
// the 0.5 mm tolerance where sin > 0.7, k = 5..15 (at k = 5 and 15: 10.607 mm,
// 0.607 outside; at k = 4 and 16: 8.817 mm, inside).
Fibre bulging() {
  Fibre fibre = straight(0, 0, 0, 100);
  for (int k = 0; k <= 20; ++k) fibre(k, 0) = 15.0 * std::sin(std::numbers::pi * k / 20.0);
  return fibre;
}

TEST(FibreQualityTest, AFibreBulgingOutOfTheSurfaceHasItsOutsideVerticesCounted) {
  std::vector<Fibre> fibres = grid();
  fibres.push_back(bulging());
  const FibreQuality quality = measure_fibre_quality(cylinder(), fibres, disc(0), disc(100));
  EXPECT_EQ(quality.vertices, 210);
  EXPECT_DOUBLE_EQ(quality.inside_fraction, (210.0 - 11.0) / 210.0);
  // A 0.7 mm tolerance takes in k = 5 and 15 (0.607 mm outside), not k = 6
  // and 14 (12.135 mm, 2.1 outside).
  FibreQualityOptions tolerant;
  tolerant.surface_tolerance_mm = 0.7;
  EXPECT_DOUBLE_EQ(
      measure_fibre_quality(cylinder(), fibres, disc(0), disc(100), tolerant).inside_fraction,
      (210.0 - 9.0) / 210.0);
  // Only the bulging fibre is not a polynomial of degree 5: it sets the max,
  // and the mean is a tenth of it (the lines add ~1e-13).
  const double bulge_error = fit_t_polynomial(bulging(), 5).mean_resultant_error;
  EXPECT_GT(bulge_error, 1e-3);  // a half sine is not a quintic
  EXPECT_NEAR(quality.fit_error_max_mm, bulge_error, 1e-12);
  EXPECT_NEAR(quality.fit_error_mean_mm, bulge_error / 10.0, 1e-12);
}

TEST(FibreQualityTest, EndsOffTheAttachmentAreasGiveTheirDistances) {
  // Origin ends lifted by 0, 1, 2, 3, 3, 3, 4, 5, 8 mm (median 3, max 8);
  // every insertion end 3 mm short of z = 100. The disc point straight below
  // or above each end is the nearest.
  const std::vector<double> lift = {0, 1, 2, 3, 3, 3, 4, 5, 8};
  std::vector<Fibre> fibres = grid();
  for (std::size_t i = 0; i < fibres.size(); ++i)
    fibres[i] = straight(fibres[i](0, 0), fibres[i](0, 1), lift[i], 97.0);
  const FibreQuality quality = measure_fibre_quality(cylinder(), fibres, disc(0), disc(100));
  EXPECT_DOUBLE_EQ(quality.origin_end_distance_median_mm, 3.0);
  EXPECT_DOUBLE_EQ(quality.origin_end_distance_max_mm, 8.0);
  EXPECT_DOUBLE_EQ(quality.insertion_end_distance_median_mm, 3.0);
  EXPECT_DOUBLE_EQ(quality.insertion_end_distance_max_mm, 3.0);
  // Lengths 97 - lift: median 94, 89 to 97.
  EXPECT_DOUBLE_EQ(quality.length_median_mm, 94.0);
  EXPECT_DOUBLE_EQ(quality.length_min_mm, 89.0);
  EXPECT_DOUBLE_EQ(quality.length_max_mm, 97.0);
  EXPECT_EQ(quality.inside_fraction, 1.0);
}

TEST(FibreQualityTest, UnevenFibresGiveTheHandComputedSpreads) {
  // Lengths 100, 80, 60 mm: mean 80, population std sqrt(800 / 3), cv
  // sqrt(1 / 24) = 0.2041.
  const std::vector<Fibre> lengths = {straight(-5, 0, 0, 100), straight(0, 0, 10, 90),
                                      straight(5, 0, 20, 80)};
  const FibreQuality by_length = measure_fibre_quality(cylinder(), lengths, disc(0), disc(100));
  EXPECT_NEAR(by_length.length_cv, std::sqrt(1.0 / 24.0), 1e-14);  // rounding of sums of 100
  EXPECT_DOUBLE_EQ(by_length.length_median_mm, 80.0);
  EXPECT_DOUBLE_EQ(by_length.length_min_mm, 60.0);
  EXPECT_DOUBLE_EQ(by_length.length_max_mm, 100.0);

  // Interior points at x = -6, 0, 2 (y = 0, z = 5 k): nearest neighbours 6, 2,
  // 2 mm at every k = 1..19, mean 10/3, std 4 sqrt(2) / 3, cv 2 sqrt(2) / 5 =
  // 0.5657. The ends meet at x = -1, 0, 1 (spacing 1), which must not count.
  std::vector<Fibre> spaced = {straight(-6, 0, 0, 100), straight(0, 0, 0, 100),
                               straight(2, 0, 0, 100)};
  spaced[0](0, 0) = spaced[0](20, 0) = -1.0;
  spaced[2](0, 0) = spaced[2](20, 0) = 1.0;
  const FibreQuality by_spacing = measure_fibre_quality(cylinder(), spaced, disc(0), disc(100));
  EXPECT_NEAR(by_spacing.spacing_mean_mm, 10.0 / 3.0, 1e-14);  // rounding of 57 sums
  EXPECT_NEAR(by_spacing.spacing_cv, 2.0 * std::sqrt(2.0) / 5.0, 1e-14);
  // Lengths 90 + 2 sqrt(50), 100, 90 + 2 sqrt(26).
  const double a = 90.0 + 2.0 * std::sqrt(50.0);
  const double c = 90.0 + 2.0 * std::sqrt(26.0);
  const double mean = (a + 100.0 + c) / 3.0;
  const double std = std::sqrt(
      ((a - mean) * (a - mean) + (100.0 - mean) * (100.0 - mean) + (c - mean) * (c - mean)) / 3.0);
  EXPECT_NEAR(by_spacing.length_cv, std / mean, 1e-14);
  EXPECT_DOUBLE_EQ(by_spacing.length_median_mm, c);  // 100.198 < a = 104.142
}

TEST(FibreQualityTest, FibresOfDifferentCountsAreComparedAtEqualArcLength) {
  // A 21-point fibre at x = 0 and a 3-point one at x = 5 with points at
  // z = 0, 10, 100: resampled at equal arc length both have point k at
  // z = 5 k, 5 mm apart (by index they would be up to 47 mm apart).
  Fibre sparse(3, 3);
  sparse << 5, 0, 0, 5, 0, 10, 5, 0, 100;
  const FibreQuality quality =
      measure_fibre_quality(cylinder(), {straight(0, 0, 0, 100), sparse}, disc(0), disc(100));
  EXPECT_NEAR(quality.spacing_mean_mm, 5.0, 1e-12);  // linear interpolation rounding
  EXPECT_NEAR(quality.spacing_cv, 0.0, 1e-12);
  // Three points take at most a quadratic, which interpolates a line exactly.
  EXPECT_LT(quality.fit_error_max_mm, 1e-9);
}

TEST(FibreQualityTest, TwoPointFibresHaveNoInteriorSpacingAndAnExactFit) {
  std::vector<Fibre> fibres;
  for (const Fibre& fibre : grid()) fibres.push_back(straight(fibre(0, 0), fibre(0, 1), 0, 100, 2));
  const FibreQuality quality = measure_fibre_quality(cylinder(), fibres, disc(0), disc(100));
  EXPECT_EQ(quality.vertices, 18);
  EXPECT_EQ(quality.spacing_mean_mm, 0.0);
  EXPECT_LT(quality.fit_error_max_mm, 1e-12);  // degree 1 through two points: rounding only
  EXPECT_EQ(quality.length_median_mm, 100.0);
}

TEST(FibreQualityTest, JsonHoldsEveryFieldByName) {
  std::vector<Fibre> fibres = grid();
  fibres.push_back(bulging());
  const FibreQuality quality = measure_fibre_quality(cylinder(), fibres, disc(0), disc(100));
  const nlohmann::json json = to_json(quality);
  EXPECT_EQ(json.size(), 17U);
  EXPECT_EQ(json.at("fibres").get<int>(), 10);
  EXPECT_EQ(json.at("vertices").get<int>(), 210);
  EXPECT_EQ(json.at("inside_fraction").get<double>(), quality.inside_fraction);
  EXPECT_EQ(json.at("spacing_cv").get<double>(), quality.spacing_cv);
  EXPECT_EQ(json.at("fit_error_max_mm").get<double>(), quality.fit_error_max_mm);
  const nlohmann::json hooked = quality;
  EXPECT_EQ(hooked, json);
}

TEST(FibreQualityTest, BadInputIsRefusedNamingWhatIsWrong) {
  const mesh::IndexedMesh surface = cylinder();
  const MatrixX3d origin = disc(0);
  const MatrixX3d insertion = disc(100);
  const auto message = [&](const std::vector<Fibre>& fibres, const MatrixX3d& o, const MatrixX3d& i,
                           const FibreQualityOptions& options = {},
                           const mesh::IndexedMesh& s = cylinder()) {
    try {
      (void)measure_fibre_quality(s, fibres, o, i, options);
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const auto contains = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };
  std::vector<Fibre> fibres = grid();
  EXPECT_TRUE(contains(message({}, origin, insertion), "no fibres"));
  std::vector<Fibre> bad = fibres;
  bad[1] = straight(0, 0, 0, 100, 1);
  EXPECT_TRUE(contains(message(bad, origin, insertion), "fibre 1 has 1 point"));
  bad = fibres;
  bad[2](3, 1) = std::nan("");
  EXPECT_TRUE(contains(message(bad, origin, insertion), "fibre 2 point 3 is not finite"));
  bad = fibres;
  bad[4] = straight(0, 0, 50, 50);
  EXPECT_TRUE(contains(message(bad, origin, insertion), "fibre 4 has zero length"));
  EXPECT_TRUE(contains(message(fibres, MatrixX3d(0, 3), insertion), "no origin points"));
  MatrixX3d infinite = insertion;
  infinite(7, 2) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(contains(message(fibres, origin, infinite), "insertion point 7 is not finite"));
  FibreQualityOptions options;
  options.surface_tolerance_mm = -1;
  EXPECT_TRUE(contains(message(fibres, origin, insertion, options), "surface_tolerance_mm"));
  options = {};
  options.coverage_radius_mm = 0;
  EXPECT_TRUE(contains(message(fibres, origin, insertion, options), "coverage_radius_mm"));
  options = {};
  options.polynomial_degree = 13;
  EXPECT_TRUE(contains(message(fibres, origin, insertion, options), "out of range"));
  EXPECT_TRUE(contains(message(fibres, origin, insertion, {}, mesh::IndexedMesh{}), "has no face"));
  mesh::IndexedMesh broken = surface;
  broken.F(0, 0) = 9999;
  EXPECT_TRUE(contains(message(fibres, origin, insertion, {}, broken), "muscle surface:"));
}

}  // namespace
}  // namespace mmm::fibres
