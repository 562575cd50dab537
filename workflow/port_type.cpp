#include "workflow/port_type.h"

#include <array>

namespace mmm::workflow {
namespace {

constexpr std::array<PortTypeInfo, 15> kPortTypes = {{
    {PortType::kNumber, "Number", "A real number (JSON number text)", ".json"},
    {PortType::kInteger, "Integer", "A 64-bit integer (JSON number text)", ".json"},
    {PortType::kString, "String", "UTF-8 text (JSON string)", ".json"},
    {PortType::kBool, "Bool", "true or false (JSON)", ".json"},
    {PortType::kFile, "File", "An opaque file, stored byte for byte", ""},
    {PortType::kReport, "Report", "A JSON document for people and programs", ".json"},
    {PortType::kMesh, "Mesh",
     "Triangle surface in mm, binary little-endian PLY with double coordinates", ".ply"},
    {PortType::kAtlas, "Atlas",
     "Musculoskeletal atlas: bones, muscles, attachment areas, action lines, joints, landmarks "
     "(its folder packed as a core/directory_bundle.h bundle)",
     ".atlas"},
    {PortType::kLandmarkSet, "LandmarkSet", "Named 3D points (mm) with provenance, JSON", ".json"},
    {PortType::kRadiographPair, "RadiographPair",
     "Two calibrated X-ray views: images and 3x4 projection matrices", ".radiographs"},
    {PortType::kMarkerTrajectories, "MarkerTrajectories",
     "Motion-capture marker positions per frame (TRC content)", ".trc"},
    {PortType::kBonePoses, "BonePoses", "Rigid pose of every bone per frame", ".json"},
    {PortType::kMuscleFrames, "MuscleFrames",
     "A wrapped motion, binary: bone poses, each muscle's rest surface, its surface and action "
     "lines per stored frame",
     ".frames"},
    {PortType::kFibreSet, "FibreSet", "Muscle fibres as polylines (mm)", ".json"},
    {PortType::kOutlineCorrections, "OutlineCorrections",
     "An operator's verdict on bone outlines projected onto radiographs: accepted, or "
     "corrected by edge points per bone and view (pixels), JSON",
     ".json"},
}};

}  // namespace

std::span<const PortTypeInfo> all_port_types() { return kPortTypes; }

const PortTypeInfo& port_type_info(PortType type) {
  return kPortTypes[static_cast<std::size_t>(type)];
}

std::optional<PortType> port_type_from_name(std::string_view name) {
  for (const PortTypeInfo& info : kPortTypes) {
    if (info.name == name) return info.type;
  }
  return std::nullopt;
}

std::string port_type_names() {
  std::string names;
  for (const PortTypeInfo& info : kPortTypes) {
    if (!names.empty()) names += ", ";
    names += info.name;
  }
  return names;
}

bool is_value_type(PortType type) {
  return type == PortType::kNumber || type == PortType::kInteger || type == PortType::kString ||
         type == PortType::kBool;
}

}  // namespace mmm::workflow
