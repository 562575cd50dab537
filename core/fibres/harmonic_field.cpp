#include "core/fibres/harmonic_field.h"

#include <algorithm>
#include <limits>
#include <string>

#include "core/errors.h"
#include "core/mesh/laplacian.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;

constexpr int kMinimumVertices = 3;

// Squared distance from every vertex to the nearest of `points`.
Eigen::VectorXd squared_distances(const Eigen::MatrixX3d& vertices,
                                  const Eigen::MatrixX3d& points) {
  Eigen::VectorXd nearest(vertices.rows());
  for (Index v = 0; v < vertices.rows(); ++v) {
    nearest(v) = (points.rowwise() - vertices.row(v)).rowwise().squaredNorm().minCoeff();
  }
  return nearest;
}

// The vertices within `distance` (squared distances `squared`) that are not
// `taken`; when fewer than kMinimumVertices, the kMinimumVertices nearest
// ones that are not taken.
std::vector<int> within(const Eigen::VectorXd& squared, double distance,
                        const std::vector<bool>& taken) {
  std::vector<int> chosen;
  std::vector<int> free;
  for (Index v = 0; v < squared.size(); ++v) {
    if (taken[static_cast<std::size_t>(v)]) continue;
    free.push_back(static_cast<int>(v));
    if (squared(v) <= distance * distance) chosen.push_back(static_cast<int>(v));
  }
  if (static_cast<int>(chosen.size()) < kMinimumVertices) {
    const auto count = std::min<std::size_t>(kMinimumVertices, free.size());
    std::partial_sort(free.begin(), free.begin() + static_cast<std::ptrdiff_t>(count), free.end(),
                      [&](int a, int b) { return squared(a) < squared(b); });
    chosen.assign(free.begin(), free.begin() + static_cast<std::ptrdiff_t>(count));
    std::sort(chosen.begin(), chosen.end());
  }
  return chosen;
}

}  // namespace

AttachmentVertices attachment_vertices(const mesh::IndexedMesh& surface,
                                       const Attachments& attachments, double distance_mm) {
  if (attachments.origin.rows() == 0 || attachments.insertion.rows() == 0) {
    throw InvalidInputError("attachment_vertices: an attachment area has no points");
  }
  const Eigen::VectorXd to_origin = squared_distances(surface.V, attachments.origin);
  const Eigen::VectorXd to_insertion = squared_distances(surface.V, attachments.insertion);
  // A vertex nearer the other area is that area's.
  const auto n = static_cast<std::size_t>(surface.V.rows());
  std::vector<bool> nearer_insertion(n);
  std::vector<bool> nearer_origin(n);
  for (std::size_t v = 0; v < n; ++v) {
    nearer_insertion[v] = to_insertion(static_cast<Index>(v)) < to_origin(static_cast<Index>(v));
    nearer_origin[v] = !nearer_insertion[v];
  }
  AttachmentVertices result;
  result.origin = within(to_origin, distance_mm, nearer_insertion);
  std::vector<bool> taken(n, false);
  for (const int v : result.origin) taken[static_cast<std::size_t>(v)] = true;
  for (std::size_t v = 0; v < n; ++v) taken[v] = taken[v] || nearer_origin[v];
  result.insertion = within(to_insertion, distance_mm, taken);
  if (static_cast<int>(result.insertion.size()) < kMinimumVertices) {
    // Nothing is nearer the insertion: its nearest vertices not on the origin.
    std::vector<bool> origin_only(n, false);
    for (const int v : result.origin) origin_only[static_cast<std::size_t>(v)] = true;
    result.insertion = within(to_insertion, distance_mm, origin_only);
  }
  return result;
}

Eigen::VectorXd harmonic_field(const mesh::IndexedMesh& surface,
                               const AttachmentVertices& attachments) {
  const Index n = surface.V.rows();
  if (attachments.origin.empty() || attachments.insertion.empty()) {
    throw InvalidInputError(
        "harmonic_field: no surface vertex lies on the " +
        std::string(attachments.origin.empty() ? "origin" : "insertion") +
        " attachment; check that the attachment areas touch the muscle surface");
  }
  // Known values: 0 on the origin, 1 on the insertion; -1 marks unknowns.
  Eigen::VectorXd known = Eigen::VectorXd::Constant(n, -1.0);
  for (const int v : attachments.origin) {
    known(v) = 0.0;
  }
  for (const int v : attachments.insertion) {
    if (known(v) == 0.0) {
      throw InvalidInputError("harmonic_field: vertex " + std::to_string(v) +
                              " is on both attachments; separate them");
    }
    known(v) = 1.0;
  }
  std::vector<Index> unknown_index(static_cast<std::size_t>(n), -1);
  Index unknowns = 0;
  for (Index v = 0; v < n; ++v) {
    if (known(v) < 0.0) {
      unknown_index[static_cast<std::size_t>(v)] = unknowns++;
    }
  }
  // -L restricted to the unknowns (positive definite when every piece of
  // the surface touches an attachment); the knowns move to the right side.
  const Eigen::SparseMatrix<double> laplacian = mesh::cotangent_laplacian(surface.V, surface.F);
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
  for (Index col = 0; col < laplacian.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      const Index row_unknown = unknown_index[static_cast<std::size_t>(it.row())];
      if (row_unknown < 0) {
        continue;
      }
      const Index col_unknown = unknown_index[static_cast<std::size_t>(it.col())];
      if (col_unknown >= 0) {
        entries.emplace_back(row_unknown, col_unknown, -it.value());
      } else {
        rhs(row_unknown) += it.value() * known(it.col());
      }
    }
  }
  Eigen::SparseMatrix<double> system(unknowns, unknowns);
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd field = known;
  if (unknowns > 0) {
    scaling::SparseCholesky solver(system);
    if (solver.info() != Eigen::Success) {
      throw SolverError(
          "harmonic_field: the Laplace system could not be factored; a piece of the muscle "
          "surface touches neither attachment (clean the mesh into one closed piece)");
    }
    const Eigen::VectorXd solved = solver.solve(rhs);
    for (Index v = 0; v < n; ++v) {
      if (const Index u = unknown_index[static_cast<std::size_t>(v)]; u >= 0) {
        field(v) = solved(u);
      }
    }
  }
  return field;
}

}  // namespace mmm::fibres
