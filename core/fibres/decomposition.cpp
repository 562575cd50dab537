#include "core/fibres/decomposition.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {

using Eigen::Vector3d;

void validate(const DecompositionOptions& options) {
  if (options.fibres < 1) {
    throw InvalidInputError("fibres: " + std::to_string(options.fibres) +
                            " asked for; ask for at least 1 (e.g. 81)");
  }
  if (options.segments < 2) {
    throw InvalidInputError("segments: " + std::to_string(options.segments) +
                            " per fibre; use at least 2 (20-30 suffice for any muscle)");
  }
  if (options.contour_points < 8 || options.contour_points % 8 != 0) {
    throw InvalidInputError("contour_points: " + std::to_string(options.contour_points) +
                            " is not a positive multiple of 8; use 64");
  }
  if (options.smoothing_passes < 0) {
    throw InvalidInputError("smoothing_passes: must be >= 0");
  }
}

MuscleAxes muscle_axes(const mesh::IndexedMesh& surface, const Attachments& attachments) {
  for (const auto* points : {&attachments.origin, &attachments.insertion}) {
    if (points->rows() == 0 || !points->allFinite()) {
      throw InvalidInputError(std::string(points == &attachments.origin ? "origin" : "insertion") +
                              " attachment: no points, or a point that is not finite; the muscle "
                              "needs its attachment areas in the atlas");
    }
  }
  if (surface.V.rows() < 4 || !surface.V.allFinite()) {
    throw InvalidInputError("muscle surface: fewer than 4 vertices or a non-finite one");
  }
  MuscleAxes axes;
  axes.origin_centre = attachments.origin.colwise().mean().transpose();
  axes.insertion_centre = attachments.insertion.colwise().mean().transpose();
  const Vector3d span = axes.insertion_centre - axes.origin_centre;
  if (span.norm() < 1e-6) {
    throw InvalidInputError(
        "attachments: the origin and insertion areas have the same centroid; the muscle has no "
        "direction");
  }
  axes.axis = span.normalized();
  const Eigen::MatrixX3d centred = surface.V.rowwise() - surface.V.colwise().mean();
  const Eigen::MatrixX3d across = centred - (centred * axes.axis) * axes.axis.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(across.transpose() * across);
  Vector3d reference = solver.eigenvectors().col(2);  // largest spread
  reference -= reference.dot(axes.axis) * axes.axis;
  if (reference.norm() < 1e-9) {  // a muscle with no spread across its axis
    reference = axes.axis.unitOrthogonal();
  }
  reference.normalize();
  // A deterministic sign: its largest component positive.
  Eigen::Index largest = 0;
  reference.cwiseAbs().maxCoeff(&largest);
  axes.reference = reference(largest) < 0.0 ? Vector3d(-reference) : reference;
  return axes;
}

}  // namespace mmm::fibres
