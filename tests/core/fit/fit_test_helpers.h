#pragma once
// Test-only random samples for the fitting tests, drawn from the raw mt19937
// stream (the standard distributions are implementation-defined; these are
// portable): uniform numbers, Gaussian noise, directions on the sphere and on
// a spherical cap, random rotations; and point sets moved by a transform.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

namespace mmm::test {

// Uniform in (0, 1), never exactly 0 (safe under a logarithm).
inline double open_unit(std::mt19937& rng) {
  return (static_cast<double>(rng()) + 0.5) / 4294967296.0;
}

// Standard normal by Box-Muller.
inline double standard_normal(std::mt19937& rng) {
  const double u = open_unit(rng);
  const double v = open_unit(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
}

inline Eigen::Vector3d gaussian_vector(std::mt19937& rng, double sigma) {
  return sigma * Eigen::Vector3d(standard_normal(rng), standard_normal(rng), standard_normal(rng));
}

// Unit vector uniform on the cap of half-angle `half_angle` (radians) around
// +z (half_angle = pi gives the whole sphere): cos(polar angle) is uniform.
inline Eigen::Vector3d direction_in_cap(std::mt19937& rng, double half_angle) {
  const double z = 1.0 - open_unit(rng) * (1.0 - std::cos(half_angle));
  const double phi = 2.0 * std::numbers::pi * open_unit(rng);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

inline Eigen::Vector3d unit_direction(std::mt19937& rng) {
  return direction_in_cap(rng, std::numbers::pi);
}

inline double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
inline double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Angle of the rotation taking a to b (radians, in [0, pi]).
inline double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// Each row of `points` mapped by t.
inline Eigen::MatrixX3d transformed(const Eigen::MatrixX3d& points, const Eigen::Affine3d& t) {
  return (points * t.linear().transpose()).rowwise() + t.translation().transpose();
}

}  // namespace mmm::test
