#include "core/fibres/mass_spring.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Axes = Eigen::Matrix<double, 3, 2>;

// A layer's contour with its arc length, and the plane its interior particles
// stay in: an origin (the centroid), orthonormal in-plane axes, the unit
// normal; and its size.
struct Layer {
  const Contour* contour = nullptr;
  std::vector<double> arc;  // arc length at each point, then of the whole loop
  Vector3d origin;
  Axes axes;
  Vector3d normal;
  double size = 0;  // square root of the enclosed area (mm)
};

std::string at_layer(std::size_t k) { return "mass_spring: layer " + std::to_string(k); }

Vector3d point(const Contour& contour, Index m) { return contour.row(m % contour.rows()); }

Layer make_layer(const Contour& contour, std::size_t k) {
  const Index n = contour.rows();
  if (n < 3) {
    throw InvalidInputError(at_layer(k) + " has " + std::to_string(n) +
                            " points; a contour needs at least 3");
  }
  for (Index m = 0; m < n; ++m) {
    if (!contour.row(m).allFinite())
      throw InvalidInputError(at_layer(k) + ", point " + std::to_string(m) + " is not finite");
  }
  Layer layer;
  layer.contour = &contour;
  layer.arc.assign(static_cast<std::size_t>(n) + 1, 0.0);
  Vector3d weighted = Vector3d::Zero();
  for (Index m = 0; m < n; ++m) {
    const double length = (point(contour, m + 1) - point(contour, m)).norm();
    const auto s = static_cast<std::size_t>(m);
    layer.arc[s + 1] = layer.arc[s] + length;
    weighted += 0.5 * length * (point(contour, m) + point(contour, m + 1));
  }
  const double perimeter = layer.arc.back();
  if (!(perimeter > 0.0)) {
    throw InvalidInputError(at_layer(k) +
                            ": all points coincide; a contour must loop around the muscle");
  }
  layer.origin = weighted / perimeter;
  Vector3d area = Vector3d::Zero();  // Newell: half the sum of edge cross products
  for (Index m = 0; m < n; ++m) {
    area += 0.5 * (point(contour, m) - layer.origin).cross(point(contour, m + 1) - layer.origin);
  }
  if (area.norm() <= 1e-12 * perimeter * perimeter) {
    throw InvalidInputError(at_layer(k) + " encloses no area (its " + std::to_string(n) +
                            " points are collinear); a contour must loop around the muscle");
  }
  layer.normal = area.normalized();
  layer.size = std::sqrt(area.norm());
  layer.axes.col(0) = layer.normal.unitOrthogonal();
  layer.axes.col(1) = layer.normal.cross(layer.axes.col(0));
  return layer;
}

// All contours turn the same way, and that is counter-clockwise seen from the
// insertion end: their normals point along the way from origin to insertion.
void check_orientation(const std::vector<Layer>& layers) {
  double travel = 0.0;
  for (std::size_t k = 0; k + 1 < layers.size(); ++k) {
    if (layers[k].normal.dot(layers[k + 1].normal) <= 0.0) {
      throw InvalidInputError(
          "mass_spring: layers " + std::to_string(k) + " and " + std::to_string(k + 1) +
          " turn opposite ways (their planes are at least 90 degrees apart); hint: every "
          "contour runs counter-clockwise seen from the insertion end (fibre_set.h)");
    }
    travel +=
        (layers[k].normal + layers[k + 1].normal).dot(layers[k + 1].origin - layers[k].origin);
  }
  if (travel < 0.0) {
    throw InvalidInputError(
        "mass_spring: the contours run clockwise seen from the insertion end (the last layer); "
        "hint: reverse the point order of every contour keeping point 0, or list the layers "
        "from the origin end");
  }
}

// Fraction of the unit square's perimeter from (1, 0.5) counter-clockwise to
// its boundary point (u, v).
double perimeter_fraction(double u, double v) {
  double along = 0.0;
  if (u >= 1.0) {
    along = v >= 0.5 ? v - 0.5 : 3.5 + v;
  } else if (v >= 1.0) {
    along = 0.5 + (1.0 - u);
  } else if (u <= 0.0) {
    along = 1.5 + (1.0 - v);
  } else {
    along = 2.5 + u;
  }
  return along / 4.0;
}

// The contour point at `fraction` (in [0, 1]) of its perimeter from point 0.
Vector3d contour_point(const Layer& layer, double fraction) {
  const Contour& contour = *layer.contour;
  const double s = fraction * layer.arc.back();
  const auto after = std::upper_bound(layer.arc.begin(), layer.arc.end(), s);
  const Index m = std::clamp<Index>(after - layer.arc.begin() - 1, 0, contour.rows() - 1);
  const auto i = static_cast<std::size_t>(m);
  const double length = layer.arc[i + 1] - layer.arc[i];
  const double t = length > 0.0 ? std::clamp((s - layer.arc[i]) / length, 0.0, 1.0) : 0.0;
  return (1.0 - t) * point(contour, m) + t * point(contour, m + 1);
}

// Where particle (u, v) of the unit square starts: on the square's ring
// through it, shrunk about the centre by `ring` (0 at the centre, 1 on the
// boundary), mapped to the contour shrunk about its centroid alike. On the
// boundary, its pinned contour point.
Vector3d start_position(const Layer& layer, double u, double v) {
  const double a = u - 0.5;
  const double b = v - 0.5;
  const double ring = 2.0 * std::max(std::abs(a), std::abs(b));
  if (ring == 0.0) return layer.origin;
  const double fraction = perimeter_fraction(0.5 + a / ring, 0.5 + b / ring);
  return layer.origin + ring * (contour_point(layer, fraction) - layer.origin);
}

// The balance equations A x = b of the interior particles' in-plane
// coordinates x (two per particle, relative to their layer's origin).
class SpringSystem {
 public:
  explicit SpringSystem(Index particles) : rhs_(Eigen::VectorXd::Zero(2 * particles)) {}

  // An across spring of stiffness s from particle p of `layer` to the pinned
  // point q.
  void pinned(Index p, const Layer& layer, const Vector3d& q, double s) {
    diagonal(p, s);
    rhs_.segment<2>(2 * p) += s * layer.axes.transpose() * (q - layer.origin);
  }

  // An across spring of stiffness s between particles p and q of one layer.
  void across(Index p, Index q, double s) {
    diagonal(p, s);
    diagonal(q, s);
    for (Index r = 0; r < 2; ++r) {  // the block is -s I: no zeros stored
      triplets_.emplace_back(2 * p + r, 2 * q + r, -s);
      triplets_.emplace_back(2 * q + r, 2 * p + r, -s);
    }
  }

  // An along spring of stiffness s between particle p of layer lp and q of
  // layer lq, of energy (the header's) s/2 r_p r_q |(p - c_p) / r_p - (q -
  // c_q) / r_q|^2 with c a layer's origin and r its size.
  void along(Index p, const Layer& lp, Index q, const Layer& lq, double s) {
    diagonal(p, s * lq.size / lp.size);
    diagonal(q, s * lp.size / lq.size);
    couple(p, q, -s * lp.axes.transpose() * lq.axes);
  }

  [[nodiscard]] Eigen::SparseMatrix<double> matrix() const {
    Eigen::SparseMatrix<double> a(rhs_.size(), rhs_.size());
    a.setFromTriplets(triplets_.begin(), triplets_.end());
    return a;
  }
  [[nodiscard]] const Eigen::VectorXd& rhs() const { return rhs_; }

 private:
  void diagonal(Index p, double s) {
    triplets_.emplace_back(2 * p, 2 * p, s);
    triplets_.emplace_back(2 * p + 1, 2 * p + 1, s);
  }

  // The block (p, q) and its transpose at (q, p).
  void couple(Index p, Index q, const Eigen::Matrix2d& block) {
    for (Index r = 0; r < 2; ++r) {
      for (Index c = 0; c < 2; ++c) {
        triplets_.emplace_back(2 * p + r, 2 * q + c, block(r, c));
        triplets_.emplace_back(2 * q + c, 2 * p + r, block(r, c));
      }
    }
  }

  std::vector<Eigen::Triplet<double>> triplets_;
  Eigen::VectorXd rhs_;
};

// Solves A d = b (A of SpringSystem) by conjugate gradients, preconditioned
// with A's along chains: A without the couplings between particles of one
// layer, one block-tridiagonal system per fibre whose LDLT has no fill. The
// chains carry the along springs exactly, so the count of steps depends on
// the layer grid (about its width), not on the stiffness ratio.
class ChainPreconditionedCg {
 public:
  ChainPreconditionedCg(const Eigen::SparseMatrix<double>& a, Index layer_unknowns) : a_(a) {
    Eigen::SparseMatrix<double> chains = a;
    chains.prune([&](const Index& r, const Index& c, const double&) {
      return r / 2 == c / 2 || r / layer_unknowns != c / layer_unknowns;
    });
    chains_.compute(chains);
    if (chains_.info() != Eigen::Success) {
      throw SolverError("mass_spring: the LDLT factorisation of the fibres' along chains (" +
                        std::to_string(a.rows()) + " unknowns) failed");
    }
  }

  // To a residual of kRelativeResidual |b|, or after as many steps as
  // unknowns (rounding) and a margin.
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    constexpr double kRelativeResidual = 1e-12;
    Eigen::VectorXd d = Eigen::VectorXd::Zero(b.size());
    Eigen::VectorXd r = b;
    Eigen::VectorXd z = chains_.solve(r);
    Eigen::VectorXd p = z;
    double rz = r.dot(z);
    const double stop = kRelativeResidual * b.norm();
    for (Index step = 0; step < b.size() + 100 && r.norm() > stop; ++step) {
      const Eigen::VectorXd ap = a_ * p;
      const double alpha = rz / p.dot(ap);
      d += alpha * p;
      r -= alpha * ap;
      z = chains_.solve(r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    return d;
  }

 private:
  const Eigen::SparseMatrix<double>& a_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> chains_;
};

void check_options(const MassSpringOptions& options) {
  const auto positive = [](double value) { return std::isfinite(value) && value > 0.0; };
  if (options.grid < 3) {
    throw InvalidInputError("mass_spring: grid must be >= 3, got " + std::to_string(options.grid) +
                            " (a border ring around at least one interior fibre)");
  }
  if (!positive(options.along_stiffness) || !positive(options.across_stiffness)) {
    throw InvalidInputError(
        "mass_spring: along_stiffness and across_stiffness must be finite "
        "and > 0, got " +
        std::to_string(options.along_stiffness) + " and " +
        std::to_string(options.across_stiffness));
  }
  if (options.max_iterations < 1) {
    throw InvalidInputError("mass_spring: max_iterations must be >= 1, got " +
                            std::to_string(options.max_iterations));
  }
  if (!positive(options.tolerance_mm)) {
    throw InvalidInputError("mass_spring: tolerance_mm must be finite and > 0, got " +
                            std::to_string(options.tolerance_mm));
  }
}

}  // namespace

MassSpringResult mass_spring_fibres(const std::vector<Contour>& layers,
                                    const MassSpringOptions& options) {
  check_options(options);
  if (layers.size() < 2) {
    throw InvalidInputError("mass_spring: at least 2 layers (contours) are needed, got " +
                            std::to_string(layers.size()));
  }
  std::vector<Layer> planes;
  planes.reserve(layers.size());
  for (std::size_t k = 0; k < layers.size(); ++k) planes.push_back(make_layer(layers[k], k));
  check_orientation(planes);

  const int grid = options.grid;
  const auto count = static_cast<Index>(layers.size());
  const Index side = grid - 2;  // interior particles per grid row of a layer
  const auto interior = [&](int i, int j) {
    return i > 0 && j > 0 && i < grid - 1 && j < grid - 1;
  };
  const auto index = [&](Index k, int i, int j) { return (k * side + (i - 1)) * side + (j - 1); };
  const auto layer = [&](Index k) -> const Layer& { return planes[static_cast<std::size_t>(k)]; };

  MassSpringResult result;
  result.fibres.assign(static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid),
                       Fibre(count, 3));
  const auto particle = [&](Index k, int i, int j) {
    return result
        .fibres[static_cast<std::size_t>(i) * static_cast<std::size_t>(grid) +
                static_cast<std::size_t>(j)]
        .row(k);
  };
  // i / (grid - 1), exactly 1 at i = grid - 1 (a border particle on the contour).
  const auto unit = [&](int i) { return static_cast<double>(i) / (grid - 1); };
  Eigen::VectorXd x(2 * count * side * side);
  for (Index k = 0; k < count; ++k) {
    for (int i = 0; i < grid; ++i) {
      for (int j = 0; j < grid; ++j) {
        const Vector3d start = start_position(layer(k), unit(i), unit(j));
        particle(k, i, j) = start.transpose();
        if (interior(i, j)) {
          x.segment<2>(2 * index(k, i, j)) = layer(k).axes.transpose() * (start - layer(k).origin);
        }
      }
    }
  }

  SpringSystem system(count * side * side);
  const auto across = [&](Index k, int i, int j, int ni, int nj) {
    if (ni >= grid || nj >= grid) return;
    const bool inside = interior(i, j);
    const bool neighbour_inside = interior(ni, nj);
    const double s = options.across_stiffness;
    if (inside && neighbour_inside) {
      system.across(index(k, i, j), index(k, ni, nj), s);
    } else if (inside) {
      system.pinned(index(k, i, j), layer(k), particle(k, ni, nj).transpose(), s);
    } else if (neighbour_inside) {
      system.pinned(index(k, ni, nj), layer(k), particle(k, i, j).transpose(), s);
    }
  };
  for (Index k = 0; k < count; ++k) {
    for (int i = 0; i < grid; ++i) {
      for (int j = 0; j < grid; ++j) {
        across(k, i, j, i + 1, j);
        across(k, i, j, i, j + 1);
        if (k + 1 < count && interior(i, j)) {  // border particles are pinned at both ends
          system.along(index(k, i, j), layer(k), index(k + 1, i, j), layer(k + 1),
                       options.along_stiffness);
        }
      }
    }
  }

  const Eigen::SparseMatrix<double> a = system.matrix();
  const ChainPreconditionedCg solver(a, 2 * side * side);
  while (result.iterations < options.max_iterations) {
    const Eigen::VectorXd move = solver.solve(system.rhs() - a * x);
    x += move;
    ++result.iterations;
    result.largest_move_mm = 0.0;
    for (Index p = 0; p < move.size() / 2; ++p) {
      result.largest_move_mm = std::max(result.largest_move_mm, move.segment<2>(2 * p).norm());
    }
    if (!std::isfinite(result.largest_move_mm)) {
      throw SolverError("mass_spring: the balance solve gave non-finite moves");
    }
    if (result.largest_move_mm < options.tolerance_mm) {
      result.converged = true;
      break;
    }
  }

  for (Index k = 0; k < count; ++k) {
    for (int i = 1; i < grid - 1; ++i) {
      for (int j = 1; j < grid - 1; ++j) {
        particle(k, i, j) =
            (layer(k).origin + layer(k).axes * x.segment<2>(2 * index(k, i, j))).transpose();
      }
    }
  }
  return result;
}

}  // namespace mmm::fibres
