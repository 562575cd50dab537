#pragma once
// Where muscles touch at rest, one motion on both sides: the targets of
// neighbouring muscles blended across their interface, so that the skeleton
// does not drive two touching muscles into each other in the first place.
//
// Each muscle's targets come from its own action lines (muscle_binding.h).
// Two muscles that lie against each other at rest (the adductors, the vasti)
// follow different lines, and their targets overlap by millimetres as soon
// as the joints move. Here a vertex near another muscle at rest (distance d
// below the reach R) takes, with weight
//
//   beta(d) = (1 - d / R)^2 / 2,
//
// the other muscle's motion at its rest position: the nearest vertex u of
// that muscle carried rigidly, T_n(u) + R_n(u) (X - X_u). On the interface
// itself (d = 0) both sides get the mean of the two motions, and so the same
// target; further away each muscle follows its own lines. Attachments keep
// their bones' motion (beta scaled by 1 - the binding's bone blend).

#include <Eigen/Core>
#include <vector>

#include "core/wrapping/muscle_binding.h"
#include "core/wrapping/muscle_penetration.h"

namespace mmm::wrapping {

struct InterfaceLink {
  int vertex = -1;                                   // of this muscle
  int muscle = -1;                                   // the other muscle
  int other_vertex = -1;                             // its vertex nearest to this one at rest
  double weight = 0.0;                               // beta, in (0, 1/2]
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // X_vertex - X_other_vertex at rest (mm)
};

// Per muscle of `rest` (every muscle at rest), its vertices within `reach_mm`
// of another muscle's surface, linked to the nearest one. Throws
// InvalidInputError for a reach that is not positive and finite.
std::vector<std::vector<InterfaceLink>> muscle_interfaces(const MuscleSurfaces& rest,
                                                          double reach_mm, int threads);

// `own` blended with the other muscles' motions over `links` (all[n]: muscle
// n's own targets in the same pose; bone_blend: this muscle's binding's).
MuscleBinding::Targets blend_interfaces(const MuscleBinding::Targets& own,
                                        const std::vector<InterfaceLink>& links,
                                        const std::vector<const MuscleBinding::Targets*>& all,
                                        const Eigen::VectorXd& bone_blend);

}  // namespace mmm::wrapping
