#pragma once
// Shared fixtures of the motion tests: OpenSim's gait2392 model as a
// skeleton, and marker trials synthesised from known coordinates.

#include <Eigen/Core>
#include <string>

#include "core/motion/skeleton.h"
#include "core/opensim/trc.h"

namespace mmm::test {

// OpenSim's gait2392 model scaled to subject01 (39 markers), read once.
const motion::Skeleton& subject01_skeleton();

// Smooth known coordinates over `frames` frames at 60 Hz: every free
// coordinate a sinusoid of gait-like amplitude inside its range around its
// default, the root walking along +x; locked coordinates, and those that
// move no marker (nothing could measure them), at default.
Eigen::MatrixXd synthetic_coordinates(const motion::Skeleton& skeleton, int frames);

// The trial every model marker of `skeleton` would record at those
// coordinates (mm, marker names of the skeleton), starting at t = 0.
opensim::MarkerTrajectories synthetic_trial(const motion::Skeleton& skeleton,
                                            const Eigen::MatrixXd& coordinates);

}  // namespace mmm::test
