#pragma once
// The recipe of an atlas: which real surfaces and which OpenSim model it is
// built from, and how the OpenSim bones are brought into the atlas frame.
// `mmm atlas build RECIPE.yaml -o DIR` reads it (schemas/atlas_recipe.schema.yaml
// documents every field; schemas/recipes/vhf_right_leg.yaml is the default).
//
//   mmm_atlas_recipe: 1
//   name: vhf_right_leg
//   opensim: {model: gait2392/gait2392_thelen2003muscle.osim, geometry: gait2392/Geometry,
//             marker_set: gait2392/Pipelines/gait2392_Scale_MarkerSet.xml}
//   midline: sacrum                      # bone whose centroid x is the sagittal plane
//   bones:
//     - {name: femur_r, body: femur_r, opensim_meshes: [femur_r.vtp], region: right_thigh}
//     - {name: tibia_r, body: tibia_r, file: vhf/Right/VHF_Right_Bone_Tibia_smooth.stl, ...}
//   registration:                        # one entry per OpenSim body used
//     femur_r: {method: head_and_condyles, head: ..., condyles: ...}
//   muscles:
//     - {name: gluteus_medius_r, file: ..., action_lines: [glut_med1_r, ...], ...}
//   structures:                          # cartilages and ligaments, carried by bones
//     - {name: acl_r, kind: ligament, file: ..., bones: [femur_r, tibia_r]}
//   landmarks: ...
//   wrap_surfaces:                       # fitted to the bones, see wrap_surface_fit.h
//     - {name: gastroc_at_condyles_r, bone: femur_r, shape: cylinder, around_joint: knee_r,
//        radius_mm: 35, side: posterior, axis_of_joint: knee_r, lines: [med_gas_r, lat_gas_r],
//        replaces: [med_gas_r-P2, lat_gas_r-P2]}
//
// Paths of data files are relative to the data folder (by default
// `../shared/data` beside the checkout; `--data` overrides).

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"

namespace mmm::atlas {

inline constexpr int kRecipeFormat = 1;

struct RecipeOpenSim {
  std::string model;       // .osim, relative to the data folder
  std::string geometry;    // folder of the model's .vtp bone meshes
  std::string marker_set;  // OpenSim marker-set XML (optional: the model's own markers otherwise)
};

struct RecipeBone {
  std::string name;
  std::string body;  // OpenSim body the bone moves with (its registration maps it)
  // Either a surface file (already in the atlas frame, mm) ...
  std::string file;
  bool mirror = false;  // reflect about the midline (a left surface used on the right)
  // ... or meshes of the OpenSim model (in the body frame, m), merged and
  // mapped by the body's registration.
  std::vector<std::string> opensim_meshes;
  // Target edge length when the source mesh is coarser (0: keep as is), mm.
  double remesh_edge_mm = 0.0;
  std::string region;
  std::vector<std::string> tags;
};

// How one OpenSim body is brought into the atlas frame (see bone_registration.h).
struct RecipeRegistration {
  std::string body;
  std::string method;  // "surface", "joint", "head_and_condyles", "hip_and_sacrum", "follow"
  // The OpenSim meshes of the body that are fitted (surface: onto `target`;
  // head_and_condyles: the femur; hip_and_sacrum: the sacrum).
  std::vector<std::string> meshes;
  std::vector<std::string> targets;  // surface: the atlas bones the OpenSim meshes are fitted to
  // surface: a joint whose centre, as placed by the already registered
  // parent body, anchors this (child) body, keeping the chain together.
  std::string joint_anchor;
  // joint: the body is placed by the parent's map and the motion of this
  // one-coordinate joint, the coordinate fitted to the target surfaces.
  std::string joint;
  std::string head;         // head_and_condyles: femoral-head cartilage surface file
  std::string condyles;     // head_and_condyles: distal-femur cartilage surface file
  std::string acetabulum;   // hip_and_sacrum: acetabular cartilage surface file
  std::string sacrum;       // hip_and_sacrum: the atlas bone holding the sacrum
  std::string follow;       // follow: the body whose map this one takes
  bool anisotropic = true;  // refine the similarity by a regularised affine map
};

struct RecipeMuscle {
  std::string name;
  std::string file;
  bool mirror = false;
  std::vector<std::string> action_lines;  // OpenSim muscle names (their paths become action lines)
  // For a muscle the OpenSim model has no path for: [origin bone, insertion
  // bone]. One action line named like the muscle runs from the middle of the
  // muscle's contact with the first bone to that with the second (then kept
  // inside the muscle like any line).
  std::vector<std::string> surface_line;
  FibreArchitecture architecture = FibreArchitecture::kParallel;
  std::string region;
  std::vector<std::string> tags;
};

// A cartilage or ligament surface (already in the atlas frame, mm), carried
// by its bone(s): a cartilage names the bone it covers, a ligament the two
// it joins.
struct RecipeStructure {
  std::string name;
  StructureKind kind = StructureKind::kCartilage;
  std::string file;
  std::vector<std::string> bones;
  std::string region;
  std::vector<std::string> tags;
  // A cartilage whose bone muscles lie over but do not attach to (the
  // femoral head under the hip capsule): bone points within this distance
  // of it take no muscle ends in the action-line fit (0: no such rule).
  double muscle_ends_clear_mm = 0.0;
};

// Named landmarks: how each is found.
struct RecipeLandmark {
  std::string name;
  std::string bone;
  // "sphere_centre" (of a cartilage surface `file`), "centroid" (of the
  // bone's volume), "joint_centre" (of OpenSim joint `joint`, mapped),
  // "marker_on_bone" (the point closest to the mapped marker `marker` on
  // the bone or a bone welded to it, which the landmark then names).
  std::string method;
  std::string file;
  std::string joint;
  std::string marker;
  std::vector<std::string> tags;
  std::string description;
};

// A wrap surface fitted to a bone region (wrap_surface_fit.h): the lines
// named wrap over it, and the path points it replaces (gait2392's
// conditional points that stand in for wrapping) are left out of them.
struct RecipeWrapSurface {
  std::string name;
  std::string bone;
  WrapShape shape = WrapShape::kCylinder;
  // The region's centre: a joint's centre (OpenSim joint name) or a path
  // point of an action line ("iliacus_r-P3"), at rest.
  std::string around_joint;
  std::string around_point;
  double radius_mm = 30.0;
  // Lines wrap on this side only: anterior, posterior, superior, inferior,
  // right, left (atlas frame); empty for all round. Around a joint, only the
  // bone vertices on that side of the centre are fitted (around a path
  // point, which lies on the muscle, all within the radius).
  std::string side;
  std::string axis_of_joint;          // cylinder: start from this joint's first rotation axis
  std::vector<std::string> lines;     // action line names
  std::vector<std::string> replaces;  // path point names removed from those lines
  double clearance_mm = 2.0;          // the lines' own points are kept this far outside
  // Added to the fitted radii: the lines of action run through the middle of
  // their muscles, this far out from the bone (and what lies on it).
  double offset_mm = 0.0;
};

struct RecipeRegion {
  std::string name;
  std::vector<std::string> tags;
};

struct AtlasRecipe {
  std::filesystem::path source;  // the recipe file
  std::string name;
  std::string description;
  std::string frame_description;
  RecipeOpenSim opensim;
  std::string midline_bone;
  std::vector<int> lod_faces;  // face counts of lod1, lod2, ... (decreasing)
  // Muscle vertices deeper than this inside a bone are moved out (mm).
  double penetration_tolerance_mm = 0.5;
  // Attachment areas: bone faces within this distance of the muscle surface
  // and within `attachment_radius_mm` of the action line's end (mm).
  double attachment_distance_mm = 3.0;
  double attachment_radius_mm = 30.0;
  std::vector<RecipeRegion> regions;
  std::vector<RecipeBone> bones;
  std::vector<RecipeRegistration> registrations;
  std::vector<RecipeMuscle> muscles;
  std::vector<RecipeStructure> structures;
  std::vector<RecipeLandmark> landmarks;
  std::vector<RecipeWrapSurface> wrap_surfaces;
};

// Reads and checks a recipe. Throws IoError naming the file, the line and
// the field ("line 12:5: bones[2].body: body 'femr_r' has no entry under
// registration:") for malformed
// YAML, a missing or ill-typed field, an unknown method or architecture,
// duplicate names, and references between the recipe's own elements that do
// not resolve. Files are not opened here.
AtlasRecipe read_atlas_recipe(const std::filesystem::path& file);

}  // namespace mmm::atlas
