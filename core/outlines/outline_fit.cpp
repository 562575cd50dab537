#include "core/outlines/outline_fit.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include "core/errors.h"
#include "core/outlines/bone_cover.h"
#include "core/outlines/contour_points.h"
#include "core/outlines/fit_rows.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::outlines {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Node positions: centroids of the vertices in each cell of a grid of pitch h.
Eigen::MatrixX3d place_nodes(const Eigen::MatrixX3d& vertices, double h) {
  std::map<std::tuple<long, long, long>, std::pair<Vector3d, int>> cells;
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    const Vector3d p = vertices.row(i).transpose();
    const auto key =
        std::make_tuple(std::lround(std::floor(p.x() / h)), std::lround(std::floor(p.y() / h)),
                        std::lround(std::floor(p.z() / h)));
    auto& cell = cells[key];
    if (cell.second == 0) cell.first.setZero();
    cell.first += p;
    ++cell.second;
  }
  Eigen::MatrixX3d nodes(static_cast<Eigen::Index>(cells.size()), 3);
  Eigen::Index k = 0;
  for (const auto& [key, cell] : cells) nodes.row(k++) = (cell.first / cell.second).transpose();
  return nodes;
}

NodeWeights node_weights(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& nodes, double h,
                         int neighbours) {
  const int count = std::min<int>(neighbours, static_cast<int>(nodes.rows()));
  NodeWeights out(static_cast<std::size_t>(points.rows()));
  std::vector<std::pair<double, int>> distance(static_cast<std::size_t>(nodes.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (Eigen::Index n = 0; n < nodes.rows(); ++n) {
      distance[static_cast<std::size_t>(n)] = {(nodes.row(n) - points.row(i)).squaredNorm(),
                                               static_cast<int>(n)};
    }
    std::partial_sort(distance.begin(), distance.begin() + count, distance.end());
    const double nearest = distance.front().first;
    double total = 0.0;
    auto& row = out[static_cast<std::size_t>(i)];
    for (int k = 0; k < count; ++k) {
      // Relative to the nearest node, so a point far from every node still
      // gets weights (and no underflow).
      const double w =
          std::exp(-0.5 * (distance[static_cast<std::size_t>(k)].first - nearest) / (h * h));
      row.emplace_back(distance[static_cast<std::size_t>(k)].second, w);
      total += w;
    }
    for (auto& [node, w] : row) w /= total;
  }
  return out;
}

// A node's displacement against an affine combination of its graph
// neighbours' that reproduces the node's own position (sum w = 1,
// sum w n_j = n_i, least-norm w): zero for any displacement field linear in
// position, so a bone may widen, narrow or shear locally without cost, while a
// node that moves apart from its surroundings (a spike, a dent) pays.
struct BendingStencil {
  int node = 0;
  std::vector<std::pair<int, double>> neighbours;
};

std::vector<BendingStencil> bending_stencils(const Eigen::MatrixX3d& nodes,
                                             const std::vector<std::pair<int, int>>& graph) {
  std::vector<std::vector<int>> adjacent(static_cast<std::size_t>(nodes.rows()));
  for (const auto& [i, j] : graph) {
    adjacent[static_cast<std::size_t>(i)].push_back(j);
    adjacent[static_cast<std::size_t>(j)].push_back(i);
  }
  std::vector<BendingStencil> out;
  for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
    const std::vector<int>& around = adjacent[static_cast<std::size_t>(i)];
    if (around.size() < 2) continue;
    const auto k = static_cast<Eigen::Index>(around.size());
    Eigen::MatrixXd A(4, k);
    double scale = 0.0;
    for (Eigen::Index c = 0; c < k; ++c) {
      const Vector3d d =
          (nodes.row(around[static_cast<std::size_t>(c)]) - nodes.row(i)).transpose();
      A(0, c) = 1.0;
      A.block<3, 1>(1, c) = d;
      scale = std::max(scale, d.squaredNorm());
    }
    // Least-norm solution of A w = (1, 0, 0, 0), regularised for flat or
    // one-sided neighbourhoods (where no exact linear reproduction exists).
    Eigen::Matrix4d gram = A * A.transpose();
    gram.diagonal().tail<3>().array() += 1e-3 * scale;
    gram(0, 0) += 1e-3;
    const Eigen::VectorXd w = A.transpose() * gram.ldlt().solve(Eigen::Vector4d(1, 0, 0, 0));
    BendingStencil stencil;
    stencil.node = static_cast<int>(i);
    for (Eigen::Index c = 0; c < k; ++c)
      stencil.neighbours.emplace_back(around[static_cast<std::size_t>(c)], w[c]);
    out.push_back(std::move(stencil));
  }
  return out;
}

struct Model {
  Vector3d centre = Vector3d::Zero();
  Eigen::VectorXd theta;

  [[nodiscard]] Eigen::Matrix3d D() const {
    return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(theta.data());
  }
  [[nodiscard]] Vector3d b() const { return theta.segment<3>(9); }
  [[nodiscard]] Vector3d t(int node) const { return theta.segment<3>(kAffineUnknowns + 3 * node); }

  [[nodiscard]] Vector3d map(const Vector3d& rest,
                             const std::vector<std::pair<int, double>>& w) const {
    Vector3d x = rest + D() * (rest - centre) + b();
    for (const auto& [node, weight] : w) x += weight * t(node);
    return x;
  }
  [[nodiscard]] Eigen::MatrixX3d map_all(const Eigen::MatrixX3d& rest, const NodeWeights& w) const {
    Eigen::MatrixX3d out(rest.rows(), 3);
    for (Eigen::Index i = 0; i < rest.rows(); ++i) {
      out.row(i) = map(rest.row(i).transpose(), w[static_cast<std::size_t>(i)]).transpose();
    }
    return out;
  }
};

Eigen::VectorXd solve_rows(const std::vector<FitRow>& rows, int unknowns) {
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double s = std::sqrt(rows[r].weight);
    for (const auto& [column, value] : rows[r].terms) {
      triplets.emplace_back(static_cast<int>(r), column, s * value);
    }
    rhs[static_cast<Eigen::Index>(r)] = s * rows[r].value;
  }
  Eigen::SparseMatrix<double> A(static_cast<Eigen::Index>(rows.size()), unknowns);
  A.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SparseMatrix<double> normal = A.transpose() * A;
  scaling::SparseCholesky solver(normal);
  if (solver.info() != Eigen::Success) {
    throw SolverError("outline fit: the normal equations could not be factorised");
  }
  Eigen::VectorXd theta = solver.solve(A.transpose() * rhs);
  if (solver.info() != Eigen::Success || !theta.allFinite()) {
    throw SolverError("outline fit: the normal equations could not be solved");
  }
  return theta;
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(fraction, 0.0, 1.0) * (values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

void check_input(const BoneOutlineInput& input, const std::vector<FitView>& views,
                 const OutlineFitOptions& options) {
  const std::string what = "outline fit of bone '" + input.bone + "'";
  if (input.full == nullptr || input.work == nullptr) {
    throw InvalidInputError(what + ": no surface given");
  }
  mesh::validate_indices_and_coordinates(*input.full);
  mesh::validate_indices_and_coordinates(*input.work);
  if (input.full->V.rows() < 4 || input.work->V.rows() < 4 || input.work->F.rows() < 4) {
    throw InvalidInputError(what + ": the surface has too few vertices or faces");
  }
  if (options.stages.empty()) throw InvalidInputError(what + ": no fitting stages");
  for (const FitView& view : views) {
    if (view.view == nullptr || view.edges.size() != options.stages.size()) {
      throw InvalidInputError(what + ": each view needs one edge image per stage");
    }
  }
  for (const PinnedPoint& pin : input.pins) {
    if (!pin.rest.allFinite() || !pin.target.allFinite() || !(pin.weight >= 0)) {
      throw InvalidInputError(what + ": pinned point '" + pin.name + "' is not finite");
    }
  }
  for (const CorrectionPoint& correction : input.corrections) {
    if (correction.view < 0 || correction.view >= static_cast<int>(views.size()) ||
        !correction.pixel.allFinite()) {
      throw InvalidInputError(what + ": a correction point has no view or is not finite");
    }
  }
}

}  // namespace

BoneOutlineFit fit_bone_outline(const BoneOutlineInput& input, const std::vector<FitView>& views,
                                const OutlineFitOptions& options) {
  check_input(input, views, options);
  const mesh::IndexedMesh& full = *input.full;
  const mesh::IndexedMesh& work = *input.work;
  const double h = options.node_spacing_mm;
  const Eigen::MatrixX3d nodes = place_nodes(full.V, h);
  const int node_count = static_cast<int>(nodes.rows());
  const int unknowns = kAffineUnknowns + 3 * node_count;
  const NodeWeights work_weights = node_weights(work.V, nodes, h, options.node_neighbours);
  Eigen::MatrixX3d pin_rest(static_cast<Eigen::Index>(input.pins.size()), 3);
  for (std::size_t p = 0; p < input.pins.size(); ++p) {
    pin_rest.row(static_cast<Eigen::Index>(p)) = input.pins[p].rest.transpose();
  }
  const NodeWeights pin_weights = node_weights(pin_rest, nodes, h, options.node_neighbours);

  Model model;
  model.centre = work.V.colwise().mean().transpose();
  model.theta = Eigen::VectorXd::Zero(unknowns);
  const double radius =
      std::sqrt((work.V.rowwise() - model.centre.transpose()).rowwise().squaredNorm().mean());

  // Node graph: pairs closer than 2.2 spacings.
  std::vector<std::pair<int, int>> graph;
  for (int i = 0; i < node_count; ++i) {
    for (int j = i + 1; j < node_count; ++j) {
      if ((nodes.row(i) - nodes.row(j)).norm() < 2.2 * h) graph.emplace_back(i, j);
    }
  }

  const std::vector<BendingStencil> bending = bending_stencils(nodes, graph);

  BoneOutlineFit result;
  result.bone = input.bone;
  result.nodes = node_count;
  result.views.resize(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) result.views[v].view = views[v].view->name;
  Eigen::VectorXd support = Eigen::VectorXd::Zero(node_count);
  Eigen::MatrixX3d current = work.V;
  bool first_iteration = true;
  Eigen::VectorXd last_moves;  // of the work surface's vertices, in the last iteration
  const bool thickness_on = options.thickness.weight > 0;
  std::vector<BoneCover> own_cover;
  own_cover.reserve(views.size());
  for (const FitView& view : views) {
    own_cover.push_back(thickness_on && view.cover != nullptr ? BoneCover(work, *view.view)
                                                              : BoneCover());
  }
  std::vector<double> gains(views.size(), 0.0);
  for (std::size_t stage = 0; stage < options.stages.size(); ++stage) {
    const OutlineFitStage& settings = options.stages[stage];
    const bool last_stage = stage + 1 == options.stages.size();
    for (int iteration = 0; iteration < settings.iterations; ++iteration) {
      ++result.iterations;
      std::vector<FitRow> rows;
      support.setZero();
      const mesh::IndexedMesh surface{current, work.F};
      // The current surface's tree, for the thickness term of both views.
      const bool thickness_stage =
          thickness_on && static_cast<int>(stage) >= options.thickness.first_stage;
      const std::optional<mesh::AabbTree> surface_tree =
          thickness_stage ? std::optional<mesh::AabbTree>(std::in_place, surface) : std::nullopt;
      for (std::size_t v = 0; v < views.size(); ++v) {
        const image::RadiographView& view = *views[v].view;
        const EdgeImage& edges = *views[v].edges[stage];
        const double spacing = view.pixel_spacing_mm;
        const std::vector<ContourPoint> contour = contour_points(surface, view);
        ViewFit& stats = result.views[v];
        stats.contour_points = static_cast<int>(contour.size());
        stats.corrections = 0;
        // The operator's corrections in this view: each tied to the nearest
        // contour point.
        std::vector<Vector2d> corrections;
        for (const CorrectionPoint& c : input.corrections) {
          if (c.view == static_cast<int>(v)) corrections.push_back(c.pixel);
        }
        const double correction_radius_px = options.correction_radius_mm / spacing;
        std::vector<double> residuals;
        for (const ContourPoint& point : contour) {
          const bool overridden = std::ranges::any_of(corrections, [&](const Vector2d& q) {
            return (q - point.pixel).norm() < correction_radius_px;
          });
          if (overridden) continue;
          const std::optional<EdgeImage::Edge> edge =
              edges.edge_along(point.pixel, point.outward, settings.reach_mm / spacing,
                               options.min_fall_factor * edges.median_gradient(), options.nearness);
          if (!edge) continue;
          const double residual_mm = std::abs(edge->offset_px) * spacing;
          residuals.push_back(residual_mm);
          // n . J x(theta) = n . J x_cur + s*   (in mm: times the spacing)
          const Eigen::Matrix<double, 2, 3> J = projection_jacobian(view, point.position);
          const Vector3d a = (J.transpose() * point.outward) * spacing;
          FitRow row;
          const Vector3d rest_a = work.V.row(point.vertex_a).transpose();
          const Vector3d rest_b = work.V.row(point.vertex_b).transpose();
          const auto& wa = work_weights[static_cast<std::size_t>(point.vertex_a)];
          const auto& wb = work_weights[static_cast<std::size_t>(point.vertex_b)];
          const double fixed = add_point(row, a, rest_a, model.centre, wa, 1.0 - point.t) +
                               add_point(row, a, rest_b, model.centre, wb, point.t);
          row.value = a.dot(point.position) + edge->offset_px * spacing - fixed;
          row.weight = residual_mm <= options.robust_mm ? 1.0 : options.robust_mm / residual_mm;
          for (const auto& [node, w] : wa) support[node] += (1.0 - point.t) * w;
          for (const auto& [node, w] : wb) support[node] += point.t * w;
          rows.push_back(std::move(row));
        }
        for (const Vector2d& q : corrections) {
          // The contour point nearest the operator's point follows it.
          const ContourPoint* nearest = nullptr;
          for (const ContourPoint& point : contour) {
            if (nearest == nullptr || (point.pixel - q).norm() < (nearest->pixel - q).norm()) {
              nearest = &point;
            }
          }
          if (nearest == nullptr) continue;
          ++stats.corrections;
          const Eigen::Matrix<double, 2, 3> J = projection_jacobian(view, nearest->position);
          const Vector2d offset = (q - nearest->pixel) * spacing;  // mm
          for (int axis = 0; axis < 2; ++axis) {
            const Vector3d a = J.row(axis).transpose() * spacing;
            FitRow row;
            const double fixed =
                add_point(row, a, work.V.row(nearest->vertex_a).transpose(), model.centre,
                          work_weights[static_cast<std::size_t>(nearest->vertex_a)],
                          1.0 - nearest->t) +
                add_point(row, a, work.V.row(nearest->vertex_b).transpose(), model.centre,
                          work_weights[static_cast<std::size_t>(nearest->vertex_b)], nearest->t);
            row.value = a.dot(nearest->position) + offset[axis] - fixed;
            row.weight = options.correction_weight;
            rows.push_back(std::move(row));
          }
        }
        if (thickness_stage) {
          ThicknessView thickness_view{&view, &edges, views[v].cover, &own_cover[v], views[v].soft};
          if (options.thickness.refresh_gain) gains[v] = 0.0;
          ThicknessRows thickness =
              thickness_rows(*surface_tree, work.V, work_weights, model.centre, thickness_view,
                             options.thickness, gains[v]);
          stats.thickness_samples = static_cast<int>(thickness.rows.size());
          stats.thickness_mean_mm = thickness.residual_mm.empty()
                                        ? 0.0
                                        : std::accumulate(thickness.residual_mm.begin(),
                                                          thickness.residual_mm.end(), 0.0) /
                                              static_cast<double>(thickness.residual_mm.size());
          stats.thickness_gain = gains[v];
          // On a coarse surface (few contour points against many rays) the
          // term's total weight is capped at max_share times the outline's.
          const double total =
              options.thickness.weight * static_cast<double>(thickness.rows.size());
          const double cap = options.thickness.max_share * static_cast<double>(contour.size());
          const double scale = total > cap ? cap / total : 1.0;
          for (FitRow& row : thickness.rows) row.weight *= scale;
          std::ranges::move(thickness.rows, std::back_inserter(rows));
        }
        stats.matched = static_cast<int>(residuals.size());
        if (std::getenv("MMM_DEBUG_FIT") != nullptr) {
          std::fprintf(
              stderr, "%s stage %zu it %d view %zu: %zu/%zu matched, mean %.3f\n",
              input.bone.c_str(), stage, iteration, v, residuals.size(), contour.size(),
              residuals.empty()
                  ? 0.0
                  : std::accumulate(residuals.begin(), residuals.end(), 0.0) / residuals.size());
        }
        double mean = 0.0;
        for (const double r : residuals) mean += r;
        mean = residuals.empty() ? 0.0 : mean / static_cast<double>(residuals.size());
        if (first_iteration) stats.start_mean_mm = mean;
        stats.mean_mm = mean;
        stats.p95_mm = percentile(residuals, 0.95);
      }
      first_iteration = false;
      for (std::size_t p = 0; p < input.pins.size(); ++p) {
        for (int axis = 0; axis < 3; ++axis) {
          FitRow row;
          const double fixed = add_point(row, Vector3d::Unit(axis), input.pins[p].rest,
                                         model.centre, pin_weights[p], 1.0);
          row.value = input.pins[p].target[axis] - fixed;
          row.weight = options.pin_weight * input.pins[p].weight;
          rows.push_back(std::move(row));
        }
      }
      for (const auto& [i, j] : graph) {
        for (int axis = 0; axis < 3; ++axis) {
          FitRow row;
          row.terms = {{kAffineUnknowns + 3 * i + axis, 1.0},
                       {kAffineUnknowns + 3 * j + axis, -1.0}};
          row.weight = options.smoothness_weight * settings.smoothness_factor;
          rows.push_back(std::move(row));
        }
      }
      for (const BendingStencil& stencil : bending) {
        for (int axis = 0; axis < 3; ++axis) {
          FitRow row;
          row.terms.emplace_back(kAffineUnknowns + 3 * stencil.node + axis, 1.0);
          for (const auto& [j, w] : stencil.neighbours) {
            row.terms.emplace_back(kAffineUnknowns + 3 * j + axis, -w);
          }
          row.weight = options.bending_weight;
          rows.push_back(std::move(row));
        }
      }
      for (int i = 0; i < node_count; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
          rows.push_back({{{kAffineUnknowns + 3 * i + axis, 1.0}}, 0.0, options.prior_weight});
        }
      }
      for (int k = 0; k < 9; ++k) {
        rows.push_back({{{k, radius}}, 0.0, options.affine_weight});
      }
      for (int k = 9; k < kAffineUnknowns; ++k) {
        rows.push_back({{{k, 1.0}}, 0.0, options.prior_weight});
      }
      model.theta = solve_rows(rows, unknowns);
      const Eigen::MatrixX3d next = model.map_all(work.V, work_weights);
      last_moves = (next - current).rowwise().norm();
      const double change = last_moves.maxCoeff();
      current = next;
      if (change < options.converged_mm) {
        if (last_stage) result.converged = true;
        break;
      }
    }
  }

  result.last_change_mm = last_moves.maxCoeff();
  result.last_change_p95_mm = percentile(
      std::vector<double>(last_moves.data(), last_moves.data() + last_moves.size()), 0.95);
  // The full surface, and what the fit did.
  const NodeWeights full_weights = node_weights(full.V, nodes, h, options.node_neighbours);
  result.vertices = model.map_all(full.V, full_weights);
  const Eigen::VectorXd moved = (result.vertices - full.V).rowwise().norm();
  result.moved_mean_mm = moved.mean();
  result.moved_max_mm = moved.maxCoeff();
  int held = 0;
  for (const auto& row : full_weights) {
    double seen = 0.0;
    for (const auto& [node, w] : row) seen += w * std::min(1.0, support[node]);
    if (seen < 0.5) ++held;
  }
  result.held_by_prior = static_cast<double>(held) / static_cast<double>(full.V.rows());
  result.linear = Eigen::Matrix3d::Identity() + model.D();
  result.translation = model.b() - model.D() * model.centre;
  for (std::size_t p = 0; p < input.pins.size(); ++p) {
    result.pin_residual_mm.push_back(
        (model.map(input.pins[p].rest, pin_weights[p]) - input.pins[p].target).norm());
  }
  // The operator's points against the final outline.
  const mesh::IndexedMesh final_surface{current, work.F};
  for (std::size_t v = 0; v < views.size() && !input.corrections.empty(); ++v) {
    std::vector<double> distances;
    const std::vector<ContourPoint> contour = contour_points(final_surface, *views[v].view);
    for (const CorrectionPoint& c : input.corrections) {
      if (c.view != static_cast<int>(v) || contour.empty()) continue;
      double best = std::numeric_limits<double>::infinity();
      for (const ContourPoint& point : contour)
        best = std::min(best, (point.pixel - c.pixel).norm());
      distances.push_back(best * views[v].view->pixel_spacing_mm);
    }
    result.views[v].correction_mean_mm =
        distances.empty() ? 0.0
                          : std::accumulate(distances.begin(), distances.end(), 0.0) /
                                static_cast<double>(distances.size());
  }
  return result;
}

}  // namespace mmm::outlines
