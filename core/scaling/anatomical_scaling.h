#pragma once
// The anatomical first stage of atlas scaling (VPHOP D10.2, section 3.2):
// from the two or three landmarks an operator places on the patient's
// radiographs — femoral head centre H, patella centre P, optionally ankle
// centre A (mm, patient frame) — per-bone affine maps that carry the atlas
// onto the most plausible human through those landmarks; and, as the
// baseline it must beat, one similarity for every bone. Both come as an
// atlas::PatientDeformation (bone_maps only, no neck warp), applied with
// deform_atlas / deform_bone_mesh / deform_muscle_mesh. Later stages (the
// Laplacian-regularised energy of D10.2) start from this estimate.
//
// What three points can tell. H, P, A fix nine numbers; a rigid placement
// takes six, so three shape numbers remain: the two leg segments' lengths
// and the knee angle. Nothing else about the person is observable from them
// — in particular neither bone widths nor the rotation of the limb about the
// H-P line when A is absent — so the rest comes from an anatomical prior:
// widths scale with stature, stature is the mean of the observed length
// factors, and the patient is assumed to stand as the atlas does (the least
// rotation that explains the landmarks). Person-to-person width deviations
// at a given stature (~5 %) are therefore not estimated: they are the
// residual the later, surface-based stages must remove.
//
// The model (the same family as patient_deformation.h, its factors fixed to
// what the landmarks determine):
//   c_b   centre of the joint attaching bone b to its parent (its child
//         frame's origin at rest), a_b the unit axis from c_b to the mean
//         centre of b's distal joints (the child frames' origins; gait2392
//         puts the knee's parent frame at the femur's origin, so the parent
//         frames would give the femur no axis)
//   M_b = L_b a_b a_b^T + s (I - a_b a_b^T)      length L_b, width s
//   map_b(x) = G( c'_b + Q_b M_b (x - c_b) ),  c'_b = map_parent(c_b) before G
// with L_femur = L_f, L_tibia = L_t, every other bone L_b = s (it only
// scales by s); s = (L_f + L_t) / 2; Q_b = Q (a rotation by theta about the
// knee) for the tibia and the bones hanging from it, I elsewhere; G = (R, t)
// a global rigid motion. Bones welded to a parent take the parent's map;
// the root (the pelvis) scales by s and, like every bone, goes through G,
// which puts the femoral-head landmark on H (so the hip centre, which the
// pelvis and femur maps share, sits where the patient's femoral head is).
//
// Estimation (three landmarks):
//   d1 = |P - H|, d2 = |A - P|, phi* = angle(P - H, A - P)
//   n  = unit normal of the atlas triangle, (P0 - H0) x (A0 - P0): theta
//        turns the tibia about n, the least rotation changing the knee angle
//   solve for (L_f, L_t, theta), G = identity (Newton, 3 x 3, finite-
//   difference Jacobian, started at L_f = d1 / |P0 - H0|, L_t = d2 / |A0 - P0|):
//        |P' - H'| = d1,  |A' - P'| = d2,  angle(P' - H', A' - P') = phi*
//   where X' is landmark X0 mapped by its bone's map. Now the triangle
//   H' P' A' is congruent to H P A; R takes the frame (P' - H', A' - P') onto
//   (P - H, A - P) and t = H - R H', so all three landmarks are met exactly.
// The patella is welded to the tibia in the default atlas and sits ~50 mm in
// front of the knee, so |P - H| is not the femur length alone: that is why
// the lengths are solved jointly rather than read off as |P - H| / |P0 - H0|.
//
// Two landmarks: one distance, so one shape number: L_f = L_t = s =
// |P - H| / |P0 - H0| (the tibia assumed to scale like the femur), theta = 0,
// and R the least-angle rotation taking P0 - H0 onto P - H. Every bone then
// has the same similarity: with two landmarks the anatomical estimate IS the
// uniform baseline (the estimate's notes say so).
//
// Uniform baseline: one similarity x -> s R x + t for every bone; two
// landmarks: s = |P - H| / |P0 - H0|, least-angle R, H0 onto H; three: the
// least-squares similarity (fit/rigid_fit.h, kSimilarity), which leaves
// residuals when the proportions differ from the atlas's.
//
// Landmark names are those of atlas::kRequiredLandmarks. The femoral-head
// landmark's bone is the femur; the patella landmark's bone, followed up
// through weld joints, must hang from the femur (it is the tibia); the
// ankle landmark must be on that same segment.

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/patient_deformation.h"
#include "core/landmarks/landmark_set.h"

namespace mmm::scaling {

inline constexpr std::string_view kFemoralHead = "femoral_head_centre_r";  // required
inline constexpr std::string_view kPatella = "patella_centre_r";           // required
inline constexpr std::string_view kAnkle = "ankle_centre_r";               // optional

struct ScalingOptions {
  // Length factors (patient / atlas) outside this range are rejected as
  // implausible (adult femur and tibia lengths span about 0.75-1.3 of the
  // Visible Human Female's; the range leaves room for children and error).
  double min_length_factor = 0.5;
  double max_length_factor = 2.0;
  // Landmarks closer than this (mm) to one another carry no length.
  double min_landmark_distance_mm = 1.0;
  // Stature of the atlas subject (mm), for PatientFactors::height_mm (the
  // Visible Human Female: 1.71 m).
  double atlas_height_mm = 1710.0;
  // Newton solve of the three-landmark shape: most iterations, and the
  // tolerance on each residual (mm; the angle times |A - P|).
  int max_iterations = 50;
  double tolerance_mm = 1e-10;
};

struct ScalingEstimate {
  // bone_maps for every bone of the atlas (atlas mm -> patient mm), no neck
  // warp. factors: stature_scale = s, height_mm = s * atlas_height_mm,
  // length[b] = segment_length_factor[b] / s, width[b] = 1 (relative to
  // stature, as patient_deformation.h defines them), pelvis_width = 1, seed 0.
  atlas::PatientDeformation deformation;
  // Bone -> scale of its map along its segment's long axis (patient length /
  // atlas length): L_f, L_t, s for the others; welded bones report the
  // segment they move with.
  std::map<std::string, double> segment_length_factor;
  double stature_scale = 1.0;  // s: the scale across every segment
  // Rotation of the tibia about the knee relative to the atlas (degrees):
  // theta above; 0 with two landmarks and for the uniform baseline.
  double knee_rotation_deg = 0.0;
  // Given landmark name -> |mapped atlas landmark - patient landmark| (mm).
  std::map<std::string, double> landmark_residual_mm;
  // Assumptions the caller should know about (two landmarks only, a frame
  // other than "patient", ...), one sentence each.
  std::vector<std::string> notes;
};

// The anatomical estimate (see the file comment). `landmarks` must hold
// kFemoralHead and kPatella, and may hold kAnkle (others are ignored); the
// result is expressed in the landmarks' frame. Throws InvalidInputError for:
// a missing required landmark (naming it and listing those present); a
// non-finite position or other defect of the set (validate_landmark_set);
// two of the used landmarks closer than min_landmark_distance_mm; an atlas
// lacking one of the needed landmarks (named) or with a structure other than
// femur -> (tibia, patella and ankle landmark on it); a length factor
// outside [min_length_factor, max_length_factor]. Throws SolverError when
// the three-landmark shape solve does not reach the tolerance (the summary
// carries the residuals).
ScalingEstimate estimate_anatomical_scaling(const atlas::Atlas& atlas,
                                            const landmarks::LandmarkSet& landmarks,
                                            const ScalingOptions& options = {});

// The uniform baseline (see the file comment); the same inputs and errors,
// except that three collinear landmarks are rejected (rigid_fit).
ScalingEstimate estimate_uniform_scaling(const atlas::Atlas& atlas,
                                         const landmarks::LandmarkSet& landmarks,
                                         const ScalingOptions& options = {});

}  // namespace mmm::scaling
