#pragma once
// Matrix arithmetic shared by the surface deformers of core/wrapping/
// (volume_deformer.cpp, joint_deformer.cpp). Not part of the public contract.

#include <Eigen/Core>

namespace mmm::wrapping::detail {

// The Frobenius inner product sum_ij a_ij b_ij.
inline double frobenius_dot(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  return (a.array() * b.array()).sum();
}

}  // namespace mmm::wrapping::detail
