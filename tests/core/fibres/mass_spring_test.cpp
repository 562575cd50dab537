// MMSS mass-spring fibres: in a straight cylinder every fibre is a straight
// line, the border on the surface and the grid mirror-symmetric; in a square
// prism (at uneven levels, tilted) the balance is the evenly spaced grid;
// in a tapering frustum the fibres stay inside every contour and every
// interior particle is in balance; bad input is refused by name.

#include "core/fibres/mass_spring.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;
using Eigen::Vector2d;
using Eigen::Vector3d;

// `n` points of the circle of `radius` about (cx, 0, z), from +x on,
// counter-clockwise seen from +z: with the origin at the lowest z, that is
// counter-clockwise seen from the insertion end, and point 0 (+x) is where
// the unit square's (1, 0.5) goes, so u runs along x and v along y.
Contour circle_contour(double radius, double z, int n, double cx = 0.0) {
  Contour c(n, 3);
  for (int m = 0; m < n; ++m) {
    const double angle = 2.0 * std::numbers::pi * m / n;
    c.row(m) << cx + radius * std::cos(angle), radius * std::sin(angle), z;
  }
  return c;
}

std::vector<Contour> cylinder_contours(int points) {
  std::vector<Contour> layers;
  for (int k = 0; k <= 10; ++k) layers.push_back(circle_contour(10.0, 10.0 * k, points));
  return layers;
}

const Fibre& fibre(const MassSpringResult& r, int grid, int i, int j) {
  return r.fibres[static_cast<std::size_t>(i) * static_cast<std::size_t>(grid) +
                  static_cast<std::size_t>(j)];
}

bool border(int grid, int i, int j) { return i == 0 || j == 0 || i == grid - 1 || j == grid - 1; }

// Distance in x y from p to the closed polygon c.
double distance_to_polygon(const Contour& c, const Vector2d& p) {
  double best = INFINITY;
  for (Index m = 0; m < c.rows(); ++m) {
    const Vector2d a = c.row(m).head<2>().transpose();
    const Vector2d b = c.row((m + 1) % c.rows()).head<2>().transpose();
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + t * (b - a) - p).norm());
  }
  return best;
}

// Even-odd crossing test in x y.
bool inside_polygon(const Contour& c, const Vector2d& p) {
  bool inside = false;
  for (Index m = 0, n = c.rows(); m < n; ++m) {
    const Vector2d a = c.row(m).head<2>().transpose();
    const Vector2d b = c.row((m + 1) % n).head<2>().transpose();
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

// Largest net spring force in x y on an interior particle, from the fibres
// and the header's energy; zero at the balance. For polygons in planes of
// constant z, symmetric about their centre (then centroid and vertex mean
// coincide).
double largest_imbalance(const std::vector<Contour>& layers, const MassSpringResult& r,
                         const MassSpringOptions& o) {
  std::vector<Vector2d> centre;
  std::vector<double> size;  // square root of the area (shoelace)
  for (const Contour& c : layers) {
    centre.emplace_back(c.leftCols<2>().colwise().mean().transpose());
    double area = 0.0;
    for (Index m = 0; m < c.rows(); ++m) {
      const Index n = (m + 1) % c.rows();
      area += 0.5 * (c(m, 0) * c(n, 1) - c(n, 0) * c(m, 1));
    }
    size.push_back(std::sqrt(area));
  }
  const int g = o.grid;
  double largest = 0.0;
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const auto at = [&](int i, int j, std::size_t l) {
      return Vector2d(fibre(r, g, i, j).row(static_cast<Index>(l)).head<2>().transpose());
    };
    for (int i = 1; i < g - 1; ++i) {
      for (int j = 1; j < g - 1; ++j) {
        const Vector2d p = at(i, j, k);
        Vector2d force = o.across_stiffness * (at(i - 1, j, k) + at(i + 1, j, k) + at(i, j - 1, k) +
                                               at(i, j + 1, k) - 4.0 * p);
        for (const std::size_t l : {k - 1, k + 1}) {  // k - 1 wraps past the end at k = 0
          if (l >= layers.size()) continue;
          // -d/dp of s/2 r_k r_l |(p - c_k) / r_k - (q - c_l) / r_l|^2
          force +=
              o.along_stiffness * (at(i, j, l) - centre[l] - size[l] / size[k] * (p - centre[k]));
        }
        largest = std::max(largest, force.norm());
      }
    }
  }
  return largest;
}

TEST(MassSpringTest, FibresOfAStraightCylinderAreStraightAndSymmetric) {
  const int points = 64;
  const MassSpringOptions options;  // grid 9: 32 border fibres, on every other polygon vertex
  const int g = options.grid;
  const MassSpringResult r = mass_spring_fibres(cylinder_contours(points), options);
  ASSERT_EQ(r.fibres.size(), 81U);
  double crooked = 0.0;
  double border_off = 0.0;
  double interior_radius = 0.0;
  double asymmetry = 0.0;
  for (int i = 0; i < g; ++i) {
    for (int j = 0; j < g; ++j) {
      const Fibre& f = fibre(r, g, i, j);
      ASSERT_EQ(f.rows(), 11);
      const Vector3d a = f.row(0).transpose();
      const Vector3d axis = (f.row(10).transpose() - a).normalized();
      for (Index k = 0; k < 11; ++k) {
        const Vector3d p = f.row(k).transpose();
        crooked = std::max(crooked, (p - a - (p - a).dot(axis) * axis).norm());
        EXPECT_NEAR(p.z(), 10.0 * static_cast<double>(k), 1e-12);  // in its layer's plane
        const double radius = p.head<2>().norm();
        if (border(g, i, j)) {
          border_off = std::max(border_off, std::abs(radius - 10.0));
        } else {
          interior_radius = std::max(interior_radius, radius);
        }
        Vector3d mirrored_x = fibre(r, g, g - 1 - i, j).row(k).transpose();
        mirrored_x.x() = -mirrored_x.x();
        Vector3d mirrored_y = fibre(r, g, i, g - 1 - j).row(k).transpose();
        mirrored_y.y() = -mirrored_y.y();
        asymmetry = std::max({asymmetry, (mirrored_x - p).norm(), (mirrored_y - p).norm()});
      }
    }
  }
  // Fibre (8, 4) is contour point 0 (+x), (4, 8) a quarter round (+y).
  EXPECT_LT((fibre(r, g, 8, 4).row(5) - Eigen::RowVector3d(10, 0, 50)).norm(), 1e-9);
  EXPECT_LT((fibre(r, g, 4, 8).row(5) - Eigen::RowVector3d(0, 10, 50)).norm(), 1e-9);
  EXPECT_LT(crooked, 1e-6);     // identical layers: the along springs pull nowhere
  EXPECT_LT(border_off, 1e-9);  // polygon vertices are on the circle (rounding only)
  EXPECT_LT(asymmetry, 1e-6);   // the sampled circle is symmetric in x and in y
  // Interior strictly inside: measured 8.74 mm, at the interior corners (1, 1)
  // etc. next to the border's corners.
  EXPECT_GT(interior_radius, 8.5);
  EXPECT_LT(interior_radius, 9.0);
}

TEST(MassSpringTest, BorderFibresBetweenVerticesLieOnThePolygonsChords) {
  // grid 8: 28 border fibres on a 64-gon, most between vertices, on chords
  // that come as close as 10 cos(pi / 64) to the axis.
  MassSpringOptions options;
  options.grid = 8;
  const std::vector<Contour> layers = cylinder_contours(64);
  const MassSpringResult r = mass_spring_fibres(layers, options);
  const double inner = 10.0 * std::cos(std::numbers::pi / 64);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      if (!border(8, i, j)) continue;
      for (Index k = 0; k < 11; ++k) {
        const Vector2d p = fibre(r, 8, i, j).row(k).head<2>().transpose();
        EXPECT_LT(distance_to_polygon(layers[static_cast<std::size_t>(k)], p), 1e-9);
        EXPECT_GT(p.norm(), inner - 1e-9);  // rounding of the chord interpolation
        EXPECT_LT(p.norm(), 10.0 + 1e-9);
      }
    }
  }
}

TEST(MassSpringTest, ATiltedSquarePrismGivesTheEvenlySpacedGrid) {
  // Side 20 about the z axis, point 0 the middle of the x = 10 side, corners
  // and extra points unevenly along the sides (arc length does not care).
  Eigen::MatrixXd square(9, 2);
  square << 10, 0, 10, 4, 10, 10, 3, 10, -10, 10, -10, -2, -10, -10, 6, -10, 10, -10;
  // The whole stack tilted and moved: the planes are not z = constant.
  const Eigen::Isometry3d place =
      Eigen::Translation3d(5, -3, 12) * Eigen::AngleAxisd(0.7, Vector3d(1, 2, -0.5).normalized());
  std::vector<Contour> layers;
  const std::vector<double> levels = {0, 3, 10, 30, 31};  // uneven
  for (const double z : levels) {
    Contour c(square.rows(), 3);
    for (Index m = 0; m < square.rows(); ++m)
      c.row(m) = (place * Vector3d(square(m, 0), square(m, 1), z)).transpose();
    layers.push_back(c);
  }
  for (const int g : {9, 6}) {  // 6: (1, 0.5) falls between grid points
    MassSpringOptions options;
    options.grid = g;
    const MassSpringResult r = mass_spring_fibres(layers, options);
    double worst = 0.0;
    for (int i = 0; i < g; ++i) {
      for (int j = 0; j < g; ++j) {
        for (std::size_t k = 0; k < levels.size(); ++k) {
          const Vector3d expected =
              place * Vector3d(-10.0 + 20.0 * i / (g - 1), -10.0 + 20.0 * j / (g - 1), levels[k]);
          worst = std::max(
              worst, (fibre(r, g, i, j).row(static_cast<Index>(k)).transpose() - expected).norm());
        }
      }
    }
    EXPECT_LT(worst, 1e-9) << g;  // an affine grid is in balance exactly; rounding only
    // The starting grid is already the balance: one iteration moves nothing.
    EXPECT_EQ(r.iterations, 1) << g;
    EXPECT_TRUE(r.converged) << g;
  }
}

TEST(MassSpringTest, FibresOfATaperingFrustumStayInsideEveryContour) {
  // 13 layers 5 mm apart, radius 20 at z = 0 to 8 at z = 60, the axis leaning
  // toward +x by 0.1 mm per mm; then the same flattening to an ellipse of 8
  // by 12 mm (layers not similar: the along springs pull).
  for (const double flatten : {0.0, 0.5}) {
    std::vector<Contour> layers;
    for (int k = 0; k <= 12; ++k) {
      Contour c = circle_contour(20.0 - k, 5.0 * k, 48, 0.5 * k);
      c.col(1) *= 1.0 + flatten * k / 12.0;
      layers.push_back(c);
    }
    for (const double along : {1.0, 10.0, 1e4}) {
      MassSpringOptions options;
      options.along_stiffness = along;
      const MassSpringResult r = mass_spring_fibres(layers, options);
      double closest = INFINITY;  // of an interior particle to its contour
      for (int i = 1; i < options.grid - 1; ++i) {
        for (int j = 1; j < options.grid - 1; ++j) {
          for (Index k = 0; k <= 12; ++k) {
            const Contour& c = layers[static_cast<std::size_t>(k)];
            const Vector3d p = fibre(r, options.grid, i, j).row(k).transpose();
            EXPECT_NEAR(p.z(), 5.0 * static_cast<double>(k), 1e-9);  // in its plane
            EXPECT_TRUE(inside_polygon(c, p.head<2>())) << i << " " << j << " " << k;
            closest = std::min(closest, distance_to_polygon(c, p.head<2>()));
          }
        }
      }
      // Measured 1.02 mm (similar layers, any along stiffness); 1.12, 1.07 and
      // 0.93 mm flattening (along 1, 10, 1e4): the interior corners next to
      // the border's at the small end, where border fibres are 1.6 mm apart.
      EXPECT_GT(closest, 0.8) << flatten << " " << along;
      // Forces are ~ 10 (1 + along) stiffness mm; 1e-11 of that is rounding
      // (measured 3e-14 to 2.4e-10).
      EXPECT_LT(largest_imbalance(layers, r, options), 1e-10 * (1.0 + along))
          << flatten << " " << along;
      EXPECT_TRUE(r.converged);
    }
  }
}

TEST(MassSpringTest, ConvergesAndReportsTheLastMove) {
  const MassSpringOptions options;
  const MassSpringResult r = mass_spring_fibres(cylinder_contours(64), options);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.largest_move_mm, options.tolerance_mm);
  // A Newton step on a quadratic energy: the first lands on the balance, the
  // second moves by rounding only.
  EXPECT_EQ(r.iterations, 2);
  EXPECT_LT(r.largest_move_mm, 1e-9);
  EXPECT_LT(largest_imbalance(cylinder_contours(64), r, options), 1e-9);

  MassSpringOptions once = options;
  once.max_iterations = 1;  // the move from the start (concentric rings) to the balance
  const MassSpringResult first = mass_spring_fibres(cylinder_contours(64), once);
  EXPECT_FALSE(first.converged);
  EXPECT_EQ(first.iterations, 1);
  EXPECT_GT(first.largest_move_mm, 0.1);  // measured 1.25 mm
  EXPECT_LT(first.largest_move_mm, 2.0);
}

std::string refusal(const std::vector<Contour>& layers, const MassSpringOptions& options = {}) {
  try {
    (void)mass_spring_fibres(layers, options);
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "accepted";
}

TEST(MassSpringTest, BadInputIsRefusedByName) {
  const std::vector<Contour> good = cylinder_contours(16);
  const auto says = [](const std::string& message, const std::string& part) {
    EXPECT_NE(message.find(part), std::string::npos) << message;
  };
  says(refusal({good.front()}), "at least 2 layers");
  std::vector<Contour> bad = good;
  bad[1] = good[1].topRows(2);
  says(refusal(bad), "layer 1 has 2 points");
  bad = good;
  bad[2](5, 1) = std::nan("");
  says(refusal(bad), "layer 2, point 5 is not finite");
  bad = good;
  bad[3].col(1).setZero();  // all on the x axis
  says(refusal(bad), "layer 3 encloses no area");
  bad = good;
  bad[4].rowwise() = Eigen::RowVector3d(1, 2, 40);
  says(refusal(bad), "layer 4: all points coincide");
  bad = good;
  bad[1] = good[1].colwise().reverse();  // clockwise
  says(refusal(bad), "layers 0 and 1 turn opposite ways");
  bad = good;
  for (Contour& c : bad) c = Contour(c.colwise().reverse());  // all clockwise
  says(refusal(bad), "run clockwise seen from the insertion end");
  says(refusal(std::vector<Contour>(good.rbegin(), good.rend())), "run clockwise");

  MassSpringOptions options;
  options.grid = 2;
  says(refusal(good, options), "grid must be >= 3, got 2");
  options = {};
  options.along_stiffness = 0.0;
  says(refusal(good, options), "stiffness must be finite and > 0");
  options = {};
  options.across_stiffness = std::nan("");
  says(refusal(good, options), "stiffness must be finite and > 0");
  options = {};
  options.max_iterations = 0;
  says(refusal(good, options), "max_iterations must be >= 1, got 0");
  options = {};
  options.tolerance_mm = -1.0;
  says(refusal(good, options), "tolerance_mm must be finite and > 0");
  EXPECT_EQ(refusal(good), "accepted");
}

}  // namespace
}  // namespace mmm::fibres
