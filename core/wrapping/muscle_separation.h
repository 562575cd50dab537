#pragma once
// Muscles that overlap at rest pushed apart before they are wrapped: the
// rest state of impenetrability between muscles.
//
// Segmented surfaces overlap where two muscles were traced one by one (in the
// Visible Human atlas the long head of biceps femoris runs up to 13 mm into
// five neighbours). Kept as it is, such an overlap would have to be resolved
// again at every frame against the rest shape's own detail. Here it is
// resolved once, at rest, with the same volume-preserving deformation as the
// wrapping: in rounds, the shared contacts of the current surfaces
// (muscle_penetration.h) are added to each muscle's pins (a vertex keeps its
// latest pin), and every muscle is solved toward its rest surface with all of
// its pins, exact volume and its bone contacts (bones at rest). Rounds end
// when no overlap deeper than the tolerance is left, or after `max_rounds`.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/wrapping/bone_contacts.h"
#include "core/wrapping/muscle_penetration.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {

struct SeparationOptions {
  int max_rounds = 8;  // >= 1
  MuscleContactOptions contact;
  DeformerOptions deformer;
  ContactOptions bone_contacts;  // tolerance and clearance of the bone contacts
};

struct MuscleSeparation {
  std::vector<Eigen::MatrixX3d> positions;   // per muscle, separated (same faces)
  std::vector<double> overlap_before_mm;     // deepest vertex inside another muscle, at rest
  std::vector<double> overlap_after_mm;      // the same, separated
  std::vector<double> max_move_mm;           // largest vertex move
  std::vector<double> volume_error_percent;  // separated vs rest
  int rounds = 0;                            // rounds run
  double seconds = 0.0;
};

// surfaces[m]: muscle m at rest (closed, outward); bones: every bone at rest
// in the same frame (empty: no bone contacts). Muscles that overlap nothing
// are left exactly as they are. Throws InvalidInputError on invalid options
// or meshes.
MuscleSeparation separate_muscles(const std::vector<mesh::IndexedMesh>& surfaces,
                                  const std::vector<PosableBone>& bones,
                                  const SeparationOptions& options, int threads);

}  // namespace mmm::wrapping
