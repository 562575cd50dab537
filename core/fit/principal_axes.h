#pragma once
// Principal axes of a point set or of the solid enclosed by a closed mesh: the
// centroid and the eigenvectors of the covariance, long axis first. They give
// a bone a frame of its own (axis 0 along the shaft of a long bone), the
// starting pose for registering it onto another subject's, and the axes along
// which rigid_fit's kAxisScaled model scales it.
//
//   centroid c = sum w_i p_i / sum w_i          (or the solid's centroid)
//   covariance C = sum w_i (p_i - c)(p_i - c)^T / sum w_i
//                                               (or the solid's, per unit volume)
//   C = A diag(s^2) A^T, s sorted decreasing
//   sign of axis k (k = 0, 1): the shape's third moment along it is positive
//     (the long tail of the distribution points along +axis), so the frame
//     follows the shape, not the pose; when that moment vanishes (a shape
//     symmetric about the axis), the largest-magnitude component is made
//     positive instead
//   axis 2 = axis 0 x axis 1 (right-handed)
// The solid's moments come from the divergence theorem over the faces (see
// core/mesh/mass_properties.h); its third moment from the same idea applied
// to (a.(x - c))^3 = div(a (a.(x - c))^4 / 4).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/mesh/mesh.h"

namespace mmm::fit {

struct PrincipalAxes {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // mm
  // Columns: unit axes, by decreasing extent, right-handed (a rotation).
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  // Standard deviation of the shape along each axis (mm): sqrt of the
  // covariance's eigenvalues, decreasing. A box of side a has a / sqrt(12)
  // along it as a solid, a / 2 through its 8 corners.
  Eigen::Vector3d extents = Eigen::Vector3d::Zero();
  // Third moment along each axis divided by extent^3 (the skewness, >= 0 for
  // axes 0 and 1 unless the shape is symmetric about them, see above).
  Eigen::Vector3d skewness = Eigen::Vector3d::Zero();

  // The principal frame: maps coordinates along the axes (mm) to the input's,
  // x = centroid + axes * local.
  [[nodiscard]] Eigen::Isometry3d frame() const {
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.linear() = axes;
    f.translation() = centroid;
    return f;
  }
};

// Principal axes of a weighted point set.
//   points   #P by 3 positions (mm)
//   weights  #P non-negative weights, or empty for all 1
// Axes whose extents are equal (a sphere, a cube) are any orthonormal basis
// of their eigenspace. Throws InvalidInputError when there is no point of
// positive weight, a coordinate or weight is not finite, a weight is negative,
// or the weight count is not #P.
PrincipalAxes principal_axes(const Eigen::MatrixX3d& points,
                             const Eigen::VectorXd& weights = Eigen::VectorXd());

// Principal axes of the solid enclosed by a closed, consistently oriented mesh
// (uniform density; inward orientation is accepted). Throws InvalidInputError
// for a mesh without faces, with invalid indices or coordinates, with an edge
// not shared by exactly two faces or inconsistent orientation (check_mesh), or
// enclosing no volume (use the point-set form on its vertices instead).
PrincipalAxes principal_axes(const mesh::IndexedMesh& closed_mesh);

}  // namespace mmm::fit
