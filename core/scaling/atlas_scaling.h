#pragma once
// Atlas scaling (VPHOP D10.2, section 3.2): the whole atlas morphed onto a
// patient's landmarks, every element consistently.
//
// Two stages.
//  1. The anatomical estimate (anatomical_scaling.h): from the station's
//     femoral-head, patella and (optional) ankle centres, per-bone affine
//     maps of the most plausible human through them — the segment lengths
//     and knee angle the landmarks fix, widths and everything unobservable
//     from the stature prior.
//  2. The energy (bone_energy.h, muscle_energy.h). Bones, root first down
//     the kinematic chain: affine-invariant Laplacian detail preservation +
//     landmark terms (every landmark of the set the atlas also has, on its
//     bone) + joint terms (a bone's joint centres stay where its parent, or
//     the first stage, puts them: the chain stays connected) + a weak prior
//     toward the first stage. Landmarks beyond the station's three (ASIS,
//     sacral point, epicondyles, malleoli, ... from a markup import) make
//     the bones' widths observable and are met here; without them the
//     first stage already meets every term and the energy's minimum is that
//     estimate itself (reported as "closed form"). Welded bones move with
//     the bone they are welded to. Muscles: the blend of the bones' maps,
//     then detail preservation + attachment/contiguity + non-penetration.
//
// Every derived element is expressed relative to the scaled geometry and
// reconstructed from it (affine_anchor.h): landmarks, markers, joint
// centres, bone frames, action-line points, attachment centroids and
// wrap-obstacle centres on their bone's full surface; the coarser levels of
// detail on their element's full surface. Cartilages and ligaments follow
// their bones the same way (a ligament's vertices blend the anchors on its
// two bones, structure_carriage.h). Orientations (frames, obstacles)
// turn with the nearest rotation of their bone's affine part, obstacle radii
// and the coupled translations of joints and moving path points scale with
// its cube-root determinant, attachment areas are re-measured on the scaled
// faces.
//
// Preparation (the anchors, blend weights, rest signed distances and the
// muscles' factorisations) depends on the atlas alone: PreparedAtlas is
// built once and scales any number of patients.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_meshes.h"
#include "core/landmarks/landmark_set.h"
#include "core/scaling/anatomical_scaling.h"
#include "core/scaling/bone_energy.h"
#include "core/scaling/muscle_energy.h"

namespace mmm::scaling {

struct AtlasScalingOptions {
  ScalingOptions anatomical;
  BoneEnergyOptions bone;
  MuscleEnergyOptions muscle;
  double landmark_weight = 100.0;    // per mm^2
  double joint_weight = 100.0;       // per mm^2: a bone's joint with its parent
  double distal_joint_weight = 1.0;  // per mm^2: its joints with its children
  // Landmarks tagged "local" in the atlas (surface landmarks: epicondyles,
  // malleoli, heel) act within this radius of themselves (bone_energy.h,
  // step 1b) instead of on the bone's affine part. 60 mm: about the size of
  // a bone's end (the distal femur's condyles, the calcaneus), so an
  // epicondyle moves its condyle and the metaphysis above it, not the shaft.
  double local_radius_mm = 60.0;
  // A bone whose stretch relative to the first stage (singular values of
  // its affine part times the first stage's inverse, or of the local
  // deformation gradient) leaves [stretch_min, stretch_max] in any
  // direction is reported as implausible. Adult bones vary in proportion by
  // about +-15 % around the stature's prediction (Winter 2009, table 4.1,
  // segment lengths over stature); 0.75-1.35 is twice that, so a warning
  // means a misplaced or mislabelled landmark, not an unusual patient.
  double stretch_min = 0.75;
  double stretch_max = 1.35;
  int anchor_vertices = 16;
  int threads = 2;
};

// A cartilage or ligament: each full-level vertex anchored on each of its
// bones' full surfaces, and its weights (structure_carriage.h).
struct PreparedStructure {
  std::vector<std::vector<AffineAnchor>> on_bones;  // [bone][vertex]
  Eigen::MatrixXd weights;                          // vertices x bones
};

// Everything patient-independent, built by prepare_atlas.
struct PreparedAtlas {
  atlas::Atlas atlas;
  atlas::AtlasMeshes meshes;
  std::vector<std::string> bone_names;  // atlas order; the muscles' bone indices
  std::map<std::string, std::unique_ptr<AnchorBuilder>> anchors;  // element -> on its full mesh
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> rest_distance;  // bone -> full
  // element -> level -> one anchor per vertex of that level (on the full mesh).
  std::map<std::string, std::map<std::string, std::vector<AffineAnchor>>> level_anchors;
  std::vector<PreparedMuscle> muscles;                  // atlas order
  std::map<std::string, PreparedStructure> structures;  // by name
  double prepare_seconds = 0.0;
  double anchors_seconds = 0.0;  // of which: anchors and rest distances
};

// Throws InvalidInputError for an atlas whose meshes are missing from
// `meshes` or invalid, SolverError when a muscle's factorisation fails.
std::shared_ptr<const PreparedAtlas> prepare_atlas(atlas::Atlas atlas, atlas::AtlasMeshes meshes,
                                                   const AtlasScalingOptions& options = {});

struct BoneScaling {
  std::string bone;
  bool solved = false;             // false: the first stage met every term, or welded
  bool bent = false;               // the Laplacian detail step ran
  int free_directions = 0;         // affine directions kept from the first stage
  std::string welded_to;           // non-empty for welded bones
  Eigen::Affine3d affine;          // affine part of its placement (atlas -> patient)
  double length_factor = 1.0;      // along its long axis (0 when it has none)
  Eigen::Vector3d stretches;       // singular values of the affine's linear part, largest first
  std::vector<std::string> terms;  // point terms used, in order
  std::vector<double> term_residual_mm;  // |reconstructed - target| per term
  // Singular values of affine.linear() times the first stage's inverse,
  // largest first: 1 where the landmarks agree with the first stage.
  Eigen::Vector3d stretch_vs_first_stage = Eigen::Vector3d::Ones();
  // Smallest and largest singular value of the local deformation gradient
  // (times the first stage's inverse) over the surface the local field
  // moves; 1, 1 without local landmarks.
  double local_stretch_min = 1.0;
  double local_stretch_max = 1.0;
  int local_points = 0;  // local landmarks acting on it (bone_energy.h, step 1b)
};

// A stretch outside [stretch_min, stretch_max] (AtlasScalingOptions).
struct StretchWarning {
  std::string bone;
  std::string part;       // "affine" (the whole bone) or "local" (near its local landmarks)
  std::string direction;  // "medio-lateral (x)", "antero-posterior (y)" or "vertical (z)"
  double factor = 1.0;
  std::string message;  // one sentence for people
};

struct MuscleScaling {
  std::string muscle;
  MuscleSolution solution;
};

struct ScalingTimings {
  double anatomical_s = 0.0;
  double bones_s = 0.0;
  double muscles_s = 0.0;
  double elements_s = 0.0;
  double total_s = 0.0;
};

struct ScaledAtlas {
  atlas::Atlas atlas;
  atlas::AtlasMeshes meshes;
  ScalingEstimate first_stage;
  std::vector<BoneScaling> bones;
  std::vector<MuscleScaling> muscles;
  // Every landmark of the set the atlas has: |scaled atlas landmark - given| (mm).
  std::map<std::string, double> landmark_residual_mm;
  std::vector<std::string> unused_landmarks;  // in the set, not in the atlas
  std::vector<std::string> notes;
  std::vector<StretchWarning> warnings;
  ScalingTimings timings;
};

// Throws what estimate_anatomical_scaling throws (missing, coincident or
// non-finite landmarks, implausible factors), InvalidInputError for a
// landmark of the set on a bone the atlas lacks, SolverError from the energy.
ScaledAtlas scale_atlas(const PreparedAtlas& prepared, const landmarks::LandmarkSet& landmarks,
                        const AtlasScalingOptions& options = {});

// The placed full surfaces and affine parts (atlas -> patient) of every bone.
struct BonePlacement {
  std::map<std::string, Eigen::MatrixX3d> vertices;  // bone -> full-level vertices
  std::map<std::string, Eigen::Affine3d> affine;     // bone -> affine part of its placement
};

// Everything that follows the bones, given where they are: their coarser
// levels, cartilages and ligaments, the muscles (blend, detail, attachment,
// non-penetration) and every derived element. Fills `scaled`'s meshes,
// muscles and atlas and adds to its timings; `scaled.bones` is left to the
// caller (scale_atlas fills it, a later fit of the bones keeps its own).
// Throws InvalidInputError for a bone without a placement or with a vertex
// count other than its full mesh's, SolverError from a muscle solve.
void carry_atlas(const PreparedAtlas& prepared, const BonePlacement& placed,
                 const AtlasScalingOptions& options, ScaledAtlas& scaled);

// The report people read (residuals, per-segment factors, final per-bone
// length factors and stretches, stretch warnings, muscles, timings).
nlohmann::json scaling_report_json(const ScaledAtlas& scaled);

}  // namespace mmm::scaling
