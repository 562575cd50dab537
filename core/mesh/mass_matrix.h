#pragma once
// Lumped (diagonal) mass matrices: the area each vertex stands for. Together
// with the cotangent Laplacian L (laplacian.h), M^{-1} L is the discrete
// Laplace-Beltrami operator and M weighs integrals: integral of f ~ 1^T M f.

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mmm::mesh {

enum class MassType {
  // Each triangle gives a third of its area to each of its corners.
  kBarycentric,
  // Mixed Voronoi areas (Meyer, Desbrun, Schroeder & Barr 2003, "Discrete
  // differential-geometry operators for triangulated 2-manifolds", Fig. 4): a
  // non-obtuse triangle gives each corner the part of the triangle closer to
  // it than to the other corners (the Voronoi cell clipped to the triangle);
  // an obtuse triangle gives half its area to the obtuse corner and a quarter
  // to each of the two others.
  kVoronoi,
};

// Diagonal mass matrix.
//
// V     #V by 3 vertex positions (mm)
// F     #F by 3 vertex indices into V
// type  how a triangle's area is shared between its corners
// Returns M  #V by #V sparse diagonal (mm^2); the diagonal sums to the total
//   surface area, vertices not referenced by F get 0. Degenerate triangles
//   (zero area up to rounding, same test as cotangent_laplacian) add nothing.
// Throws InvalidInputError when a face index is outside [0, #V) or a
// coordinate is not finite. O(#F).
Eigen::SparseMatrix<double> mass_matrix(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F,
                                        MassType type = MassType::kVoronoi);

}  // namespace mmm::mesh
