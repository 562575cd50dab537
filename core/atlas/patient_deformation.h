#pragma once
// A known, anatomically plausible non-uniform deformation of an atlas: the
// ground truth of a synthetic patient.
//
// Each bone gets an affine map anchored at its proximal joint centre:
//   map_b(x) = c'_b + s * (I + (l_b - 1) a a^T + (w_b - 1) (I - a a^T)) (x - c_b)
// with c_b the centre of the joint attaching b to its parent, a the unit
// axis from c_b to the centre of b's distal joint (its long axis; joint
// centres are the joints' child frames at rest: gait2392 puts the knee's
// parent frame at the femur's origin and moves the knee by its coupled
// translations, so the parent frames would give the femur no axis), s the
// global scale (stature), l_b the segment-length factor and w_b the width
// factor. c'_b = map_parent(c_b) keeps the chain connected. The root (the
// pelvis) scales about its frame origin, its width (x, mediolateral) by the
// pelvis-width factor. A bone welded to another follows that bone's map.
// The femoral neck-shaft angle changes too: on the bone hanging from the
// root by a ball-like joint with a distal joint (the femur), the head and
// neck turn by an angle d about the anteroposterior axis through the neck
// base (pivot 45 mm lateral of the head centre), the turn fading from the
// head to the pivot and over 30-60 mm down the shaft; the whole bone then
// shifts so that the head centre stays in the acetabulum (d > 0: the neck
// turns up, coxa valga). This part is not affine: points on that bone are
// mapped by map_on_bone (warp, then the bone's affine map).
// Muscles, which span several bones, move by a partition of unity of the
// bone maps, weighted by inverse squared distance to each bone's surface
// (w = 1 / (d^2 + eps^2)), so they stretch smoothly with the segments they
// lie along. Landmarks, markers, action-line points, attachment-area
// centroids, wrap obstacles and joint frames follow their bone's map.

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct PatientOptions {
  std::uint64_t seed = 1;
  // Target stature (mm); when absent, drawn around the atlas's own.
  std::optional<double> height_mm;
  // Stature of the atlas subject (the Visible Human Female: 1.71 m).
  double atlas_height_mm = 1710.0;
  // Standard deviations of the factors (relative), drawn from normal
  // distributions clipped at 2.5 sigma (human ranges: adult segment-length
  // ratios vary by a few percent at fixed stature, widths by more).
  double stature_sd = 0.06;
  double segment_length_sd = 0.03;
  double width_sd = 0.05;
  double pelvis_width_sd = 0.05;
  // Neck-shaft angle change (degrees): adults span about 120-140 degrees,
  // SD ~5 around the mean.
  double neck_angle_sd_deg = 4.0;
  // Muscle blending: eps in w = 1 / (d^2 + eps^2) (mm).
  double blend_radius_mm = 10.0;
  // Local shape (LocalWarp below) on the long bones (femur, tibia): what no
  // smooth global map of the atlas produces. Off by default, so that a seed
  // gives the same patient as before; drawn after every other factor.
  bool local_shape = false;
  double torsion_sd_deg = 7.0;  // twist of the distal end about the long axis
  double bowing_sd_mm = 4.0;    // mid-shaft bend, per transverse direction
  int bumps_per_bone = 3;
  double bump_sd_mm = 1.5;       // radial height of a bump (either sign)
  double bump_length_mm = 25.0;  // its extent along the bone (Gaussian sigma)
  double bump_angle_deg = 40.0;  // its extent around the bone (Gaussian sigma)
};

// The drawn factors, kept with the patient as its ground truth.
struct PatientFactors {
  std::uint64_t seed = 0;
  double height_mm = 0.0;
  double stature_scale = 1.0;
  double pelvis_width = 1.0;
  double neck_angle_deg = 0.0;                // change of the femoral neck-shaft angle
  std::map<std::string, double> length;       // bone -> segment-length factor
  std::map<std::string, double> width;        // bone -> width factor
  std::map<std::string, double> torsion_deg;  // long bone -> twist (local shape only)
  std::map<std::string, double> bowing_mm;    // long bone -> largest mid-shaft bend
};

// Local shape of a long bone, in atlas coordinates, applied before the
// bone's affine map. With s = clamp((x - proximal) . axis / length, 0, 1):
//   torsion  the point turns about the axis line by s * torsion_rad
//   bowing   + sin(pi s) * bow (bow perpendicular to the axis)
//   bumps    + sum_k h_k exp(-(t - t_k)^2 / 2 l^2 - (phi - phi_k)^2 / 2 a^2) r
//            t the position along the axis (mm), phi the angle around it, r
//            the unit radial direction: a swelling (h > 0) or a dent of one
//            side of the shaft, fading along and around it.
struct LocalWarp {
  Eigen::Vector3d proximal = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = -Eigen::Vector3d::UnitZ();      // unit, toward the distal joint
  Eigen::Vector3d reference = Eigen::Vector3d::UnitX();  // unit, perpendicular: phi = 0
  double length = 0.0;                                   // mm
  double torsion_rad = 0.0;
  Eigen::Vector3d bow = Eigen::Vector3d::Zero();  // mm
  struct Bump {
    double along_mm = 0.0;
    double angle_rad = 0.0;
    double height_mm = 0.0;
  };
  std::vector<Bump> bumps;
  double bump_length_mm = 25.0;
  double bump_angle_rad = 0.7;

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& point) const;
};

// The femoral neck turn (see the file comment), in atlas coordinates.
struct NeckWarp {
  std::string bone;  // empty: none
  Eigen::Vector3d head = Eigen::Vector3d::Zero();
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();     // AP, unit
  Eigen::Vector3d lateral = Eigen::Vector3d::UnitX();  // unit
  Eigen::Vector3d distal = -Eigen::Vector3d::UnitZ();  // unit, along the bone
  double angle_rad = 0.0;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  // keeps the head centre in place

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& point) const;
};

// The deformation: one affine map per bone (atlas mm -> patient mm), after
// the neck warp on the femur.
struct PatientDeformation {
  PatientFactors factors;
  std::map<std::string, Eigen::Affine3d> bone_maps;
  NeckWarp neck;
  std::map<std::string, LocalWarp> local;  // long bone -> its local shape (empty: none)

  [[nodiscard]] Eigen::Vector3d map_on_bone(const std::string& bone,
                                            const Eigen::Vector3d& point) const;
};

// Draws the factors (deterministic for a seed) and builds the maps. Throws
// InvalidInputError for an atlas without a root bone or with a joint whose
// bones are unknown, or a height outside 1000-2300 mm.
PatientDeformation make_patient_deformation(const Atlas& atlas, const PatientOptions& options);

// The deformed atlas: every point-like element mapped (names, tags and
// structure unchanged; mesh file names unchanged — the caller writes the
// deformed meshes with deform_bone_mesh / deform_muscle_mesh).
Atlas deform_atlas(const Atlas& atlas, const PatientDeformation& deformation);

// A bone's mesh mapped by its bone map.
mesh::IndexedMesh deform_bone_mesh(const PatientDeformation& deformation, const std::string& bone,
                                   const mesh::IndexedMesh& surface);

// A muscle's mesh mapped by the distance-weighted blend of the bone maps;
// `bones` are the atlas's bone surfaces (any resolution) by name.
mesh::IndexedMesh deform_muscle_mesh(const PatientDeformation& deformation,
                                     const std::map<std::string, mesh::IndexedMesh>& bones,
                                     const mesh::IndexedMesh& surface, double blend_radius_mm);

}  // namespace mmm::atlas
