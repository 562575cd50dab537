#pragma once
// An OpenSim model's muscle paths as atlas action lines on the model's own
// bodies, so that action_line_path() evaluates OpenSim's model and an
// atlas the same way (e.g. to compare an atlas's moment arms with the
// model it was built from). Bodies become bones whose frame is the
// identity: with motion::skeleton_from_osim, a body's coordinates are its
// OpenSim frame in mm.

#include "core/atlas/atlas.h"
#include "core/opensim/osim_model.h"

namespace mmm::wrapping {

// Every body (but the ground) as a bone, every muscle with a path as a
// muscle with one action line: fixed points, conditional points (range in
// rad or m as OpenSim gives it, translational ranges in mm), moving points
// (functions scaled to mm, taking the coordinate in OpenSim's units, as the
// atlas's moving points do). Wrap objects are not carried (the obstacle set
// here wraps spheres and cylinders; gait2392 has none). Throws
// InvalidInputError for a path point on the ground.
atlas::Atlas osim_action_lines(const opensim::OsimModel& model);

}  // namespace mmm::wrapping
