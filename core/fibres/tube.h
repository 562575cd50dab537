#pragma once
// Generalised cylinders (nerves, vessels, tendons; the second reference
// document): a circular cross-section of varying radius swept along a
// centreline. The cross-section is carried by rotation-minimising frames
// (double reflection, Wang et al. 2008), not Frenet-Serret frames: a Frenet
// frame is undefined where the curvature vanishes and turns over by 180
// degrees at an inflection point (the twisting the reference document
// reports); a rotation-minimising frame turns only as much as the tangent
// does.

#include <Eigen/Core>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::fibres {

// An orthonormal frame at a centreline point: tangent, and the two axes of
// the cross-section (normal x binormal = tangent).
struct Frame {
  Eigen::Vector3d tangent;
  Eigen::Vector3d normal;
  Eigen::Vector3d binormal;
};

// Rotation-minimising frames along a polyline (N >= 2 points, N by 3, mm):
// tangents by central differences, the first normal `first_normal` made
// orthogonal to the first tangent (zero: any orthogonal direction), each
// next frame by double reflection. Throws InvalidInputError for fewer than
// two points, non-finite points, repeated consecutive points or a first
// normal along the first tangent.
std::vector<Frame> rotation_minimising_frames(
    const Eigen::MatrixXd& centreline,
    const Eigen::Vector3d& first_normal = Eigen::Vector3d::Zero());

// Frenet-Serret frames of the same polyline (normal toward the centre of
// curvature, by finite differences); where the curvature vanishes the
// previous normal is kept. For comparison: they flip at inflections.
std::vector<Frame> frenet_frames(const Eigen::MatrixXd& centreline);

// The tube's surface: `sides` (>= 3) vertices around each centreline point
// at radius radii[i] (> 0) in its frame, closed by a flat cap at each end,
// outward oriented. Throws InvalidInputError for sizes that do not match, a
// radius <= 0 or a frame count that differs from the centreline's.
mesh::IndexedMesh tube_mesh(const Eigen::MatrixXd& centreline, const Eigen::VectorXd& radii,
                            const std::vector<Frame>& frames, int sides);

// Largest angle (radians) between the normals of consecutive frames after
// carrying one onto the other's tangent plane: how much the cross-section
// turns about the centreline from one point to the next.
double largest_twist_step(const std::vector<Frame>& frames);

}  // namespace mmm::fibres
