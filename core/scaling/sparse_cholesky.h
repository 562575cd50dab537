#pragma once
// The sparse symmetric positive-definite solver of the scaling energies:
// CHOLMOD's supernodal Cholesky (SuiteSparse) through Eigen — several times
// faster than Eigen's simplicial LDLT on the bi-Laplacian systems of
// 10-25K-vertex meshes. Factor once, solve many right-hand sides.

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

namespace mmm::scaling {

using SparseCholesky = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;

}  // namespace mmm::scaling
