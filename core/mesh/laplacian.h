#pragma once
// Discrete Laplace operators on triangle meshes.
//
// Both follow the libigl `cotmatrix` sign convention: off-diagonal entries are
// non-negative weights w_ij on the edges, the diagonal is minus the row sum, so
// L is symmetric, every row sums to zero and L is negative semi-definite
// (x^T L x <= 0). (L f)_i = sum_j w_ij (f_j - f_i).
//
// The cotangent Laplacian is the stiffness matrix of linear finite elements
// (Pinkall & Polthier 1993; Meyer et al. 2003): -f^T L f = integral of
// |grad f|^2 over the surface. It carries no mass: the pointwise
// Laplace-Beltrami operator is M^{-1} L with M from mass_matrix.h.

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mmm::mesh {

// Cotangent Laplacian.
//
// V  #V by 3 vertex positions (mm)
// F  #F by 3 vertex indices into V
// Returns L  #V by #V sparse, L(i,j) = (cot a_ij + cot b_ij) / 2 for an edge
//   (i,j) whose opposite angles in its two triangles are a_ij and b_ij (a
//   boundary edge has a single term), L(i,i) = -sum_{j != i} L(i,j), zero
//   elsewhere. Entries are dimensionless (cotangents do not scale with mm).
//
// A degenerate triangle contributes nothing instead of infinite cotangents:
// its edges keep only the weights from their other triangles. Degenerate
// means zero area up to rounding (collinear or coincident corners, a repeated
// vertex index): twice the area <= 8 eps * l * (l + c), l the longest edge, c
// the largest absolute corner coordinate, eps the double machine epsilon. Obtuse angles
// give negative cotangents and may make off-diagonal entries negative; L stays
// negative semi-definite. Vertices not referenced by F get an empty row.
// Throws InvalidInputError when a face index is outside [0, #V) or a
// coordinate is not finite. O(#F) time and memory.
Eigen::SparseMatrix<double> cotangent_laplacian(const Eigen::MatrixX3d& V,
                                                const Eigen::MatrixX3i& F);

// Uniform (graph, "umbrella") Laplacian: L(i,j) = 1 for every distinct mesh
// edge (i,j), however many faces share it, L(i,i) = -(number of neighbours).
//
// F             #F by 3 vertex indices
// num_vertices  #V, the size of the returned matrix
// Returns L  num_vertices by num_vertices sparse, same sign convention as
//   cotangent_laplacian. Repeated indices inside a face make no self-edge.
// Throws InvalidInputError when num_vertices < 0 or an index is outside
// [0, num_vertices). O(#F) time and memory.
Eigen::SparseMatrix<double> uniform_laplacian(const Eigen::MatrixX3i& F, Eigen::Index num_vertices);

}  // namespace mmm::mesh
