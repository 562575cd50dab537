#pragma once
// The volumetric pathway over a fused motion: every muscle in one conforming
// tetrahedral model (labelled_lattice.h, coarse_embedding.h) moved by the
// bones (tet_simulation.h), with the same result as the energy pathway
// (wrapping::MuscleWrapping), so that the metrics, action lines, animation
// and report are written by the same code.
//
// Per muscle, its surface is the boundary of its fine tetrahedra. At rest,
// surface nodes in a bone (the lattice's staircase) are moved out onto it.
// Element nodes inside a bone follow it (an element reaching into a bone
// moves with it), except within anchor_joint_clearance_mm of a bone that
// moves otherwise (a joint) or where an element reaches into two bones. A
// muscle's boundary nodes within attachment_reach_mm of one of its
// attachment areas (atlas, on the bone's full mesh) follow that bone rigidly; an area farther
// from the muscle is reached through a tendon the lattice does not hold, and
// is left out (the muscle's end follows the tissue around it). Per frame:
// the bones' poses from the motion, one simulation step (warm-started from
// the frame before), the action lines routed as in the energy pathway (path
// lengths and moment arms), and the measurements: volume error per muscle,
// depth of its surface in the bones, its depth in the other muscles beyond
// rest (optional), bending change.
// Between the rest pose and the first frame (usually far apart),
// first_frame_intermediate_poses steps at coordinates in between.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/motion/motion_fusion.h"
#include "core/volumetric/labelled_lattice.h"
#include "core/volumetric/tet_simulation.h"
#include "core/wrapping/line_router.h"
#include "core/wrapping/muscle_wrapping.h"

namespace mmm::volumetric {

// How touching muscles meet: one body sharing its interface nodes, or
// separate bodies (coarse_embedding.h, embed_muscles_separately) whose
// interface nodes are tied in pairs, stuck or sliding (tet_simulation.h).
enum class MuscleInterfaces { kShared, kStick, kSlide };
std::string_view interfaces_name(MuscleInterfaces interfaces);
// std::nullopt for a name other than shared, stick, slide.
std::optional<MuscleInterfaces> interfaces_from_name(std::string_view name);

struct MuscleSimulationOptions {
  LatticeOptions lattice;  // when no lattice is given
  int coarsening = 2;      // element cell = coarsening x lattice cell
  MuscleInterfaces interfaces = MuscleInterfaces::kShared;
  double attachment_reach_mm = 4.0;
  // At rest, muscle surface nodes inside a bone or nearer than this are moved
  // out onto the bone's surface plus this.
  double rest_clearance_mm = 0.2;
  // Element nodes inside a bone at rest follow it (an element reaching into a
  // bone moves with it); false: only the bone contacts hold the elements.
  bool anchor_elements_in_bones = true;
  // Not those within this distance of a bone that moves otherwise (a
  // joint's other side), where tissue slides over both: the contacts hold
  // them. 0: every one.
  double anchor_joint_clearance_mm = 10.0;
  SimulationOptions simulation{.volume_weight = 10.0, .iterations = 2};
  int first_frame_intermediate_poses = 8;
  std::vector<std::string> muscles;  // empty: every muscle of the lattice (or atlas)
  bool muscle_penetration = true;    // measure the depth in the other muscles
  wrapping::RouterOptions routing;
  std::vector<std::string> moment_arm_coordinates = {
      "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r"};
  int threads = 0;  // 0: the machine's
};

struct MuscleSimulation {
  wrapping::MuscleWrapping motion;   // the energy pathway's result type
  std::vector<FrameStats> frames;    // the simulation's own, per frame
  std::vector<MuscleCells> lattice;  // what the lattice did to each muscle's volume
  double spacing_mm = 0.0;
  int coarsening = 1;
  Eigen::Index element_nodes = 0;
  Eigen::Index elements = 0;
  Eigen::Index output_nodes = 0;
  std::size_t interface_pairs = 0;      // separate muscles: tied node pairs
  double max_interface_gap_mm = 0.0;    // across an interface, worst frame
  double max_interface_slide_mm = 0.0;  // along it
  int checked_nodes = 0;
  int driven_nodes = 0;                     // attachment nodes
  int anchored_element_nodes = 0;           // element nodes inside a bone at rest, following it
  int rest_moved_nodes = 0;                 // surface nodes moved out of the bones at rest
  double rest_moved_out_of_bones_mm = 0.0;  // the largest such move
  int rest_inverted_output = 0;             // fine tetrahedra inverted by those moves
  std::vector<int> driven_per_muscle;       // in muscle order
  // Per muscle, the largest distance from one of its attachment areas to
  // its surface (mm), and the areas farther than attachment_reach_mm, left
  // out (reached through a tendon the lattice does not hold).
  std::vector<double> attachment_gap_mm;
  std::vector<int> attachments_left_out;
  int max_inverted = 0;             // worst frame
  double setup_seconds = 0.0;       // lattice (when built here), embedding, factorisation
  double simulation_seconds = 0.0;  // the steps, all frames
  double lines_seconds = 0.0;       // action lines, all frames
  double measure_seconds = 0.0;     // metrics, all frames
};

// `lattice`: the study's stored lattice (build_muscle_lattice) or nullptr to
// build one from the atlas. Throws InvalidInputError for a motion without
// frames or none of the skeleton's coordinates, an unknown muscle, a
// lattice whose muscles are not the atlas's, or bad options.
MuscleSimulation simulate_muscles(const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                                  const motion::FusedMotion& motion,
                                  const MuscleSimulationOptions& options = {},
                                  const LabelledLattice* lattice = nullptr);

}  // namespace mmm::volumetric
