#pragma once
// Forward kinematics of an OpenSim model: where every body is, in the ground
// frame, for given coordinate values.
//
// A joint connects a parent frame P (fixed to the parent body) and a child
// frame C (fixed to the child body):
//   X_ground_child = X_ground_parent * X_parent_P * M(q) * X_child_C^-1
// M(q) is the joint's motion. For a CustomJoint (gait2392's hip, knee, ankle,
// subtalar, mtp) it is built from the six transform axes as OpenSim's
// SpatialTransform does (Simbody's function-based mobilizer): the three
// rotations apply in order, each about its axis as carried by the rotations
// before it (body-fixed sequence), with angle function_k(q); the three
// translations are along their axes expressed in P, by function_k(q), and
// come first in the composition (translation, then rotation). Pin joints
// rotate about P's z axis; weld joints do not move; ball and free joints
// use X-Y-Z body-fixed angles (and translations).

#include <Eigen/Geometry>
#include <map>
#include <string>

#include "core/opensim/osim_model.h"

namespace mmm::opensim {

// Coordinate name -> value (rad or m). Coordinates not given take their
// default_value.
using CoordinateValues = std::map<std::string, double, std::less<>>;

// M(q) of one joint (P -> C at the current coordinate values), in metres.
// Throws InvalidInputError for a joint type it cannot move (naming it).
Eigen::Isometry3d joint_motion(const Joint& joint, const CoordinateValues& values);

// Every body's pose in the ground frame (body -> ground, metres), the ground
// included (identity). Throws InvalidInputError when a body is not connected
// to the ground or a joint names an unknown body.
std::map<std::string, Eigen::Isometry3d> body_poses(const OsimModel& model,
                                                    const CoordinateValues& values = {});

// The rigid transform of a frame reference (frame -> its body).
Eigen::Isometry3d frame_in_body(const FrameRef& frame);

}  // namespace mmm::opensim
