// The Cadaver Fibres decomposition of a cylinder "muscle" (radius 15 mm,
// length 100 mm) from four straight fibres measured on its upper half: the
// surface fibres stay on the surface, the inward rays are radial, so every
// deeper fibre is a straight line parallel to the axis, the layers are
// uniform along the chord and the last one lies on the opposite side.

#include "core/fibres/cadaver_fibres.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/winding_number.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector3d;

constexpr double kMuscleRadius = 15.0;
constexpr double kMuscleLength = 100.0;
constexpr int kAround = 96;
constexpr int kRings = 20;  // side bands of 5 mm
// Largest gap between the circle and the 96-gon inscribed in it (mm).
const double kSag = kMuscleRadius * (1.0 - std::cos(std::numbers::pi / kAround));

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
double angle_of(const Vector3d& p) { return degrees(std::atan2(p.y(), p.x())); }
double radius_of(const Vector3d& p) { return p.head<2>().norm(); }

// Closed cylinder around the z axis, z in [0, kMuscleLength]: kRings + 1 rings of
// kAround vertices, fan caps, outward oriented. The two side faces of band
// r (z in [5 r, 5 r + 5]) at middle angle a (degrees) are left out when
// keep(r, a) is false.
template <typename Keep>
mesh::IndexedMesh banded_cylinder(Keep keep) {
  std::vector<Vector3d> vertices;
  for (int r = 0; r <= kRings; ++r) {
    for (int k = 0; k < kAround; ++k) {
      const double a = 2.0 * std::numbers::pi * k / kAround;
      vertices.emplace_back(kMuscleRadius * std::cos(a), kMuscleRadius * std::sin(a),
                            kMuscleLength * r / kRings);
    }
  }
  const int bottom = static_cast<int>(vertices.size());
  vertices.emplace_back(0, 0, 0);
  vertices.emplace_back(0, 0, kMuscleLength);
  std::vector<Eigen::Vector3i> faces;
  for (int k = 0; k < kAround; ++k) {
    const int next = (k + 1) % kAround;
    for (int r = 0; r < kRings; ++r) {
      if (!keep(r, 360.0 * (k + 0.5) / kAround)) continue;
      const int a = r * kAround;
      const int b = a + kAround;
      faces.emplace_back(a + k, a + next, b + next);
      faces.emplace_back(a + k, b + next, b + k);
    }
    faces.emplace_back(bottom, next, k);
    faces.emplace_back(bottom + 1, kRings * kAround + k, kRings * kAround + next);
  }
  mesh::IndexedMesh result;
  result.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v)
    result.V.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  result.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    result.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return result;
}

mesh::IndexedMesh closed_cylinder() {
  return banded_cylinder([](int, double) { return true; });
}

// A straight measured fibre at `angle` degrees on the true circle, from z =
// 10 to z = 90, through unevenly spaced points.
Fibre measured_line(double angle) {
  const double a = angle * std::numbers::pi / 180.0;
  Fibre fibre(5, 3);
  int i = 0;
  for (const double z : {10.0, 25.0, 40.0, 70.0, 90.0})
    fibre.row(i++) << kMuscleRadius * std::cos(a), kMuscleRadius * std::sin(a), z;
  return fibre;
}

std::vector<Fibre> four_lines() {
  return {measured_line(30), measured_line(60), measured_line(90), measured_line(120)};
}

// Largest distance of a fibre's points from the line through its first
// point parallel to the z axis (mm).
double off_axis_parallel(const Fibre& fibre) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < fibre.rows(); ++i)
    worst = std::max(worst, (fibre.row(i).head<2>() - fibre.row(0).head<2>()).norm());
  return worst;
}

TEST(CadaverFibresTest, CountsAndOrderOnACylinder) {
  const CadaverFibreResult result = cadaver_fibres(closed_cylinder(), four_lines());
  ASSERT_EQ(result.fibres.size(), 81U);
  ASSERT_EQ(result.surface.size(), 9U);
  EXPECT_EQ(result.rays_missed, 0);
  for (const Fibre& fibre : result.fibres) ASSERT_EQ(fibre.rows(), 21);
  for (std::size_t j = 0; j < 9; ++j)
    EXPECT_EQ(result.fibres[j * 9], result.surface[j]) << j;  // layer 0 is the surface fibre
  // Origin to insertion: z = 10 + 4 i exactly (straight lines resampled by
  // arc length, projected horizontally onto vertical facets).
  for (const Fibre& fibre : result.fibres)
    for (Eigen::Index i = 0; i < 21; ++i)
      EXPECT_NEAR(fibre(i, 2), 10.0 + 4.0 * static_cast<double>(i), 1e-9) << i;
}

TEST(CadaverFibresTest, SurfaceFibresStayOnTheSurfaceAcrossTheMeasuredOnes) {
  const mesh::IndexedMesh muscle = closed_cylinder();
  const CadaverFibreResult result = cadaver_fibres(muscle, four_lines());
  const mesh::AabbTree tree(muscle);
  double previous_angle = 0.0;
  for (std::size_t j = 0; j < result.surface.size(); ++j) {
    const Fibre& fibre = result.surface[j];
    EXPECT_LT(off_axis_parallel(fibre), 1e-9) << j;  // straight measured lines stay straight
    for (Eigen::Index i = 0; i < fibre.rows(); ++i) {
      const Vector3d p = fibre.row(i).transpose();
      EXPECT_LT(tree.closest_point(p).squared_distance, 1e-18) << j << " " << i;  // projected
      EXPECT_GE(radius_of(p), kMuscleRadius - kSag - 1e-9) << j << " " << i;      // on the 96-gon
      EXPECT_LE(radius_of(p), kMuscleRadius + 1e-9) << j << " " << i;
    }
    const double angle = angle_of(fibre.row(0).transpose());
    if (j > 0) {
      // In order across, spread fairly evenly over the 90 degrees (11.25
      // each; measured: 10.3 to 12.0, a spline per coordinate through four
      // points of an arc is not the arc's arc-length parameterisation).
      EXPECT_GT(angle - previous_angle, 9.0) << j;
      EXPECT_LT(angle - previous_angle, 13.5) << j;
    }
    previous_angle = angle;
  }
  // The outermost surface fibres are the outermost measured ones (the true
  // circle at 30 and 120 degrees, moved onto the 96-gon: < 0.01 degrees).
  EXPECT_NEAR(angle_of(result.surface.front().row(0).transpose()), 30.0, 0.01);
  EXPECT_NEAR(angle_of(result.surface.back().row(0).transpose()), 120.0, 0.01);
}

TEST(CadaverFibresTest, DeeperFibresAreStraightAndReachTheOppositeSide) {
  const mesh::IndexedMesh muscle = closed_cylinder();
  const CadaverFibreResult result = cadaver_fibres(muscle, four_lines());
  const mesh::AabbTree tree(muscle);
  const mesh::WindingNumber winding(tree);
  double worst_straight = 0.0;
  double worst_opposite = 0.0;
  double worst_step = 0.0;
  double lowest_winding = 1.0;
  for (std::size_t j = 0; j < 9; ++j) {
    const Fibre& top = result.surface[j];
    const Fibre& bottom = result.fibres[j * 9 + 8];
    for (std::size_t k = 0; k < 9; ++k) {
      const Fibre& fibre = result.fibres[j * 9 + k];
      worst_straight = std::max(worst_straight, off_axis_parallel(fibre));
      for (Eigen::Index i = 0; i < 21; ++i) {
        const Vector3d p = fibre.row(i).transpose();
        EXPECT_LE(radius_of(p), kMuscleRadius + 1e-9) << j << " " << k << " " << i;
        if (k > 0 && k < 8) lowest_winding = std::min(lowest_winding, winding.at(p));
        // Uniform along the chord: every layer one eighth of it further.
        const Vector3d step = (bottom.row(i) - top.row(i)).transpose() / 8.0;
        const Vector3d expected = top.row(i).transpose() + static_cast<double>(k) * step;
        worst_step = std::max(worst_step, (p - expected).norm());
      }
    }
    // The last layer on the opposite surface, across the axis from the
    // surface fibre: the vertex normals of the 96-gon are radial and are
    // interpolated with the weights that give the point, so the inward
    // direction at p is exactly -p / |p| and the chord is a diameter.
    for (Eigen::Index i = 0; i < 21; ++i) {
      const Vector3d far = bottom.row(i).transpose();
      EXPECT_LT(tree.closest_point(far).squared_distance, 1e-18) << j << " " << i;
      const double off = (far.head<2>() + top.row(i).head<2>().transpose()).norm();
      worst_opposite = std::max(worst_opposite, off);
    }
  }
  // Rounding only (measured: 1.1e-14 mm off parallel, 2.6e-14 mm off the
  // diametric point).
  EXPECT_LT(worst_straight, 1e-9);
  EXPECT_LT(worst_step, 1e-9);
  EXPECT_LT(worst_opposite, 1e-9);
  // Inside: the fast winding number errs by < 1e-2 (measured lowest: 0.9946).
  EXPECT_GT(lowest_winding, 0.9);
}

TEST(CadaverFibresTest, RaysThroughAHoleMissAndBorrowTheirNeighboursDepth) {
  // No side faces for 40 < z < 60 between 180 and 330 degrees, where the
  // rays from the surface fibres (30 to 120 degrees) leave the muscle.
  const mesh::IndexedMesh open = banded_cylinder([](int band, double angle) {
    return !(band >= 8 && band < 12 && angle > 180 && angle < 330);
  });
  const CadaverFibreResult result = cadaver_fibres(open, four_lines());
  // Vertices at z = 42, 46, 50, 54, 58 of each of the 9 surface fibres.
  EXPECT_EQ(result.rays_missed, 45);
  const CadaverFibreResult closed = cadaver_fibres(closed_cylinder(), four_lines());
  double worst = 0.0;
  for (std::size_t f = 0; f < 81; ++f) {
    EXPECT_LT(off_axis_parallel(result.fibres[f]), 1e-9) << f;
    worst = std::max(worst, (result.fibres[f] - closed.fibres[f]).cwiseAbs().maxCoeff());
  }
  // The chords of a straight cylinder do not change along it: the
  // interpolated lengths are the closed mesh's.
  EXPECT_LT(worst, 1e-9);
}

TEST(CadaverFibresTest, FibresSharingAnOriginMeetThere) {
  // A fan: every fibre starts at 75 degrees, z = 10, and ends at its own angle.
  std::vector<Fibre> fan = four_lines();
  for (Fibre& fibre : fan) fibre.row(0) = measured_line(75).row(0);
  CadaverFibreOptions options;
  options.surface_fibres = 5;
  options.depth_layers = 3;
  options.segments = 10;
  const CadaverFibreResult result = cadaver_fibres(closed_cylinder(), fan, options);
  ASSERT_EQ(result.fibres.size(), 15U);
  EXPECT_EQ(result.rays_missed, 0);
  for (const Fibre& fibre : result.surface) {
    ASSERT_EQ(fibre.rows(), 11);
    EXPECT_LT((fibre.row(0) - result.surface.front().row(0)).norm(), 1e-12);
  }
  EXPECT_NEAR(angle_of(result.surface.front().row(10).transpose()), 30.0, 0.01);
  EXPECT_NEAR(angle_of(result.surface.back().row(10).transpose()), 120.0, 0.01);
}

TEST(CadaverFibresTest, OneDepthLayerGivesTheSurfaceFibres) {
  CadaverFibreOptions options;
  options.depth_layers = 1;
  options.surface_fibres = 4;
  const CadaverFibreResult result = cadaver_fibres(closed_cylinder(), four_lines(), options);
  ASSERT_EQ(result.fibres.size(), 4U);
  EXPECT_EQ(result.rays_missed, 0);
  // Four evenly spaced measured fibres, four surface fibres: the measured ones.
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_EQ(result.fibres[j], result.surface[j]);
    EXPECT_NEAR(angle_of(result.surface[j].row(5).transpose()),
                30.0 + 30.0 * static_cast<double>(j), 0.01)
        << j;
  }
}

TEST(CadaverFibresTest, BadInputIsRefused) {
  const mesh::IndexedMesh muscle = closed_cylinder();
  const std::vector<Fibre> lines = four_lines();
  EXPECT_THROW((void)cadaver_fibres(muscle, {lines[0]}), InvalidInputError);
  EXPECT_THROW((void)cadaver_fibres(mesh::IndexedMesh{}, lines), InvalidInputError);

  std::vector<Fibre> bad = lines;
  bad[2](3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)cadaver_fibres(muscle, bad), InvalidInputError);
  bad = lines;
  bad[1] = lines[1].topRows(1);
  EXPECT_THROW((void)cadaver_fibres(muscle, bad), InvalidInputError);
  bad = lines;
  bad[1].row(2) = bad[1].row(1);  // repeated point
  EXPECT_THROW((void)cadaver_fibres(muscle, bad), InvalidInputError);
  bad = lines;
  bad[3] = lines[3].colwise().reverse();  // insertion to origin
  EXPECT_THROW((void)cadaver_fibres(muscle, bad), InvalidInputError);
  bad = lines;
  bad[2] = bad[1];  // the same fibre twice
  EXPECT_THROW((void)cadaver_fibres(muscle, bad), InvalidInputError);

  for (const CadaverFibreOptions& options :
       {CadaverFibreOptions{0, 9, 9}, CadaverFibreOptions{20, 1, 9}, CadaverFibreOptions{20, 9, 0}})
    EXPECT_THROW((void)cadaver_fibres(muscle, lines, options), InvalidInputError);

  // Oriented inward: every "inward" ray leaves the cylinder at once.
  mesh::IndexedMesh inverted = muscle;
  inverted.F.col(1).swap(inverted.F.col(2));
  EXPECT_THROW((void)cadaver_fibres(inverted, lines), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres
