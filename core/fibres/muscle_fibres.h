#pragma once
// One muscle's fibres by any of the four methods, at rest and in every frame
// of a wrapped motion. What does not change from frame to frame is prepared
// once: the attachment samples (carried by their bones per frame) and, for
// the harmonic and cadaver methods, the harmonic field of the rest surface
// (a wrapped muscle keeps its vertices, so the field stays valid), and the
// muscle's end patches (end_patches.h): the fibres end on the muscle's own
// surface where it lies on its bones or, where the segmentation stops at a
// tendon, on its end cap.
//
//   slicing      slicing_decomposition.h
//   harmonic     harmonic_decomposition.h
//   mass_spring  mass_spring_decomposition.h
//   cadaver      cadaver_fibres.h, from measured surface fibres. The atlas's
//                data (Visible Human Female) has none, so without measured
//                fibres four stand-ins are traced: the harmonic method's
//                fibres of the first row of the template (one side of the
//                muscle), moved onto the surface. Results say when. Every
//                fibre is then connected at each end to the nearest point
//                of its end patch (fibre_mapping.h,
//                connect_to_nearest_attachments).

#include <Eigen/Geometry>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/fibres/atlas_attachments.h"
#include "core/fibres/decomposition.h"
#include "core/fibres/end_patches.h"
#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

enum class DecompositionMethod { kSlicing, kHarmonic, kMassSpring, kCadaver };
std::string_view method_name(DecompositionMethod method);
std::optional<DecompositionMethod> method_from_name(std::string_view name);

struct MuscleFibres {
  std::vector<Fibre> fibres;
  // Where the ends belong in this frame: the muscle's end patches
  // (end_patches.h) at this frame's vertex positions.
  Attachments attachments;
  // The atlas's attachment areas on the bones, carried by the bones' pose,
  // and each one's closest approach to its end patch: the tendon the
  // segmentation left out (0 where the muscle lies on the bone).
  Attachments bone_areas;
  double origin_gap_mm = 0.0;
  double insertion_gap_mm = 0.0;
  int moved_inside = 0;  // fibre points moved into the muscle
  int interpolated_contours = 0;
  bool stand_in_measured = false;  // cadaver: measured fibres were stand-ins
  double seconds = 0.0;            // this decomposition (the precomputed field not included)
};

class MuscleFibreModel {
 public:
  using BonePose = std::function<Eigen::Isometry3d(const std::string&)>;

  // `rest`: the muscle surface every frame's positions belong to; `measured`
  // (cadaver only): surface fibres at rest, empty for the stand-ins. Throws
  // InvalidInputError for bad options or attachments.
  MuscleFibreModel(std::string name, mesh::IndexedMesh rest, MuscleAttachmentSamples samples,
                   DecompositionMethod method, const DecompositionOptions& options,
                   std::vector<Fibre> measured = {});

  // Fibres of the surface at `positions` (the rest surface's vertices moved,
  // #V by 3), attachments carried by `pose` (empty: at rest).
  [[nodiscard]] MuscleFibres decompose(const Eigen::MatrixX3d& positions,
                                       const BonePose& pose = {}) const;
  [[nodiscard]] MuscleFibres decompose_at_rest() const { return decompose(rest_.V); }

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const mesh::IndexedMesh& rest() const { return rest_; }
  [[nodiscard]] DecompositionMethod method() const { return method_; }
  [[nodiscard]] double field_seconds() const { return field_seconds_; }
  [[nodiscard]] const EndPatches& end_patches() const { return ends_; }

 private:
  [[nodiscard]] MuscleFibres decompose_checked(const Eigen::MatrixX3d& positions,
                                               const BonePose& pose) const;

  std::string name_;
  mesh::IndexedMesh rest_;
  MuscleAttachmentSamples samples_;
  DecompositionMethod method_;
  DecompositionOptions options_;
  std::vector<Fibre> measured_;
  EndPatches ends_;
  Eigen::VectorXd field_;  // harmonic and cadaver methods
  double field_seconds_ = 0.0;
};

}  // namespace mmm::fibres
