#pragma once
// Builds an atlas folder from a recipe (atlas_recipe.h) and the real data:
//
//   1. surfaces given in the atlas frame are read (mirrored about the
//      midline where asked: the left biceps femoris long head becomes the
//      right one);
//   2. the OpenSim model is posed at its default coordinates and each body is
//      registered into the atlas frame (bone_registration.h) by the method
//      the recipe names: hip_and_sacrum (pelvis: both hip centres onto the
//      acetabular sphere centre and its mirror image, the sacrum mesh onto
//      the subject's sacrum), head_and_condyles (femur: head centre onto the
//      femoral-head cartilage sphere, distal femur onto the distal
//      cartilage), surface (e.g. tibia onto the subject's tibia) or follow;
//   3. OpenSim meshes are mapped, holes closed and remeshed; joints (frames
//      and the rest-pose coordinate values that reproduce the subject's pose),
//      muscle paths (action lines) and markers are mapped through their
//      body's registration;
//   4. muscles are cleaned of rest-pose penetration into bones (vertices
//      pushed out, the displacement spread smoothly to their neighbours),
//      action lines are fitted into their muscle (action_line_fit.h),
//      attachment areas are found where each muscle meets a bone near its
//      action lines' ends, landmarks are placed, lower resolutions made;
//   5. cartilages and ligaments are read and measured against their bones
//      (structure_build.h);
//   6. meshes (binary PLY) and atlas.yaml are written.
//
// Deterministic: the same recipe and data give byte-identical files.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_recipe.h"
#include "core/atlas/structure_build.h"
#include "core/atlas/wrap_surface_fit.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct AtlasBuildOptions {
  std::filesystem::path data_dir;  // folder the recipe's data paths are relative to
};

struct BodyRegistrationReport {
  std::string body;
  std::string method;
  double scale = 1.0;  // cube root of det of the map (mm of atlas per mm of model)
  double rms_mm = 0.0;
  double mean_distance_mm = 0.0;
  int pairs = 0;
  std::vector<std::pair<std::string, double>> anchor_residuals_mm;
};

struct MuscleBuildReport {
  std::string name;
  int faces = 0;
  double volume_mm3 = 0.0;
  double max_penetration_before_mm = 0.0;  // deepest vertex inside a bone before cleaning
  int vertices_moved = 0;
  double volume_change_percent = 0.0;  // by the cleaning
};

struct ActionLineBuildReport {
  std::string muscle;
  std::string line;
  double inside_before = 0.0;  // fraction inside the muscle as mapped from the model
  double inside_after = 0.0;   // after fitting (action_line_fit.h)
  int points_added = 0;
  bool origin_on_contact = false;
  bool insertion_on_contact = false;
};

struct JointBuildReport {
  std::string name;
  std::vector<std::pair<std::string, double>> rest_values;  // rad or mm
  double frame_mismatch_mm = 0.0;   // |child frame - parent frame * M(q_rest)| origin distance
  double frame_mismatch_deg = 0.0;  // rotation left over
};

struct AtlasBuildReport {
  std::vector<BodyRegistrationReport> registrations;
  std::vector<MuscleBuildReport> muscles;
  std::vector<JointBuildReport> joints;
  std::vector<ActionLineBuildReport> action_lines;
  std::vector<WrapSurfaceFitReport> wrap_surfaces;
  std::vector<StructureBuildReport> structures;
  std::vector<std::string> notes;  // what was skipped or approximated, one sentence each
  double seconds = 0.0;
};

// A point on a bone's surface, the bone it lies on and how far it is from
// the point it was found for.
struct BonePoint {
  std::string bone;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // atlas (mm)
  double distance_mm = 0.0;
};

// The surface point nearest to `point` on `bone` or on any bone welded to it
// (kinematic_chain.h: welded_together): a landmark of the pelvis is looked for
// on the whole pelvis, whose hip bones, sacrum and coccyx are separate bones.
// How a marker_on_bone landmark is placed; the landmark then names the bone
// it lies on. `surfaces` holds each bone's surface (atlas frame, mm); bones
// without one are skipped. Throws InvalidInputError when none of the
// segment's bones has a surface.
BonePoint closest_on_segment(const Atlas& atlas,
                             const std::map<std::string, mesh::IndexedMesh>& surfaces,
                             std::string_view bone, const Eigen::Vector3d& point);

// Builds the atlas of `recipe` into `out_dir` (created; an existing atlas
// there is replaced only once the new one is complete). Throws IoError for a
// missing or unreadable data file (naming it) and InvalidInputError when the
// recipe asks for something the data cannot give (an OpenSim body, joint,
// muscle or marker that does not exist).
AtlasBuildReport build_atlas(const AtlasRecipe& recipe, const AtlasBuildOptions& options,
                             const std::filesystem::path& out_dir);

}  // namespace mmm::atlas
