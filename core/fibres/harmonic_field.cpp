#include "core/fibres/harmonic_field.h"

#include <string>

#include "core/errors.h"
#include "core/mesh/laplacian.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::fibres {

using Eigen::Index;

Eigen::VectorXd harmonic_field(const mesh::IndexedMesh& surface, const EndPatches& ends) {
  const Index n = surface.V.rows();
  if (ends.origin.empty() || ends.insertion.empty()) {
    throw InvalidInputError(
        "harmonic_field: no surface vertex lies on the " +
        std::string(ends.origin.empty() ? "origin" : "insertion") +
        " attachment; check that the attachment areas touch the muscle surface");
  }
  // Known values: 0 on the origin, 1 on the insertion; -1 marks unknowns.
  Eigen::VectorXd known = Eigen::VectorXd::Constant(n, -1.0);
  for (const int v : ends.origin) {
    known(v) = 0.0;
  }
  for (const int v : ends.insertion) {
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
