#pragma once
// OpenSim marker sets (the <MarkerSet> XML the Scale tool places on a model)
// and the marker weights of an inverse-kinematics setup (<IKMarkerTask>).
//
//   <OpenSimDocument Version="20302">
//     <MarkerSet name="gait2392_Scale"><objects>
//       <Marker name="R.ASIS">
//         <body> pelvis </body>                         (3.x; 4.x:
//         <socket_parent_frame>/bodyset/pelvis</socket_parent_frame>)
//         <location> 0.0148 -0.0076 0.1334 </location>  (m, in the body frame)
//         <fixed> false </fixed>
//       </Marker>
//     ...

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::opensim {

// One marker of a marker-set file. (osim_model.h's Marker is the richer
// model-side type with a resolved frame; this one is what a marker-set file
// states.)
struct MarkerDefinition {
  std::string name;
  // Body the marker is attached to: <body> (3.x) or <socket_parent_frame>
  // (4.x) with a leading "/bodyset/" (or "/") removed: "pelvis", "ground".
  std::string body;
  Eigen::Vector3d location = Eigen::Vector3d::Zero();  // in the body frame (m)
  bool fixed = false;  // kept in place by the Scale tool's marker placement
};

// Reads the markers of a marker-set file, in file order. Accepted roots:
// <OpenSimDocument> holding a <MarkerSet> (or a <Model> holding one, so an
// .osim file works too), or a bare <MarkerSet>.
//
// Throws IoError(file, "line N: <Marker name=\"x\">: what, expected vs got;
// hint") for: a missing or unreadable file; malformed XML; no <MarkerSet>; a
// <Marker> without a name, without <body>/<socket_parent_frame>, or without
// <location>; a location that is not 3 finite numbers; a <fixed> that is not
// true/false; a marker name used twice.
std::vector<MarkerDefinition> read_marker_set(const std::filesystem::path& file);

// Same, from the XML text in memory; `name_for_messages` is the path put in
// error messages.
std::vector<MarkerDefinition> parse_marker_set(std::string_view xml,
                                               const std::filesystem::path& name_for_messages);

// How the IK tool uses one marker (<IKMarkerTask>); OpenSim's defaults.
struct IkMarkerWeight {
  bool apply = true;    // <apply>: false leaves the marker out of the solve
  double weight = 1.0;  // <weight>: relative weight of its squared error (>= 0)
};

// Reads the <IKMarkerTask> elements of an OpenSim IK setup file
// (<InverseKinematicsTool><IKTaskSet><objects>) or of a bare task-set file
// (<IKTaskSet> as root or under <OpenSimDocument>), keyed by marker name.
// An <IKTaskSet file="tasks.xml"> is followed, relative to the setup's
// folder. <IKCoordinateTask>s are skipped.
//
// Throws IoError for: a missing or unreadable file; malformed XML; no
// <IKTaskSet>; a task without a name or named twice; an <apply> that is not
// true/false; a <weight> that is not a finite number >= 0.
std::map<std::string, IkMarkerWeight> read_ik_task_weights(const std::filesystem::path& setup);

// Same, from the XML text in memory. `name_for_messages` is the path put in
// error messages; a referenced task-set file is looked up in its folder.
std::map<std::string, IkMarkerWeight> parse_ik_task_weights(
    std::string_view xml, const std::filesystem::path& name_for_messages);

}  // namespace mmm::opensim
