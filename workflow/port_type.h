#pragma once
// The closed set of data types that flow between workflow nodes.
//
// The engine moves artifacts as bytes: every port type fixes one stable
// serialisation of its values (described below and implemented by the code
// that produces and consumes the type), so an artifact's content hash is the
// SHA-256 of those bytes and equal values always hash alike. Connections are
// checked by type before anything runs.

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace mmm::workflow {

enum class PortType {
  kNumber,              // a double, canonical JSON number text
  kInteger,             // a 64-bit integer, JSON text
  kString,              // UTF-8 text, JSON string
  kBool,                // JSON true/false
  kFile,                // an opaque file: its bytes, unchanged
  kReport,              // a JSON document (keys sorted, 2-space indent)
  kMesh,                // a triangle mesh, binary little-endian PLY (double x y z, int faces), mm
  kAtlas,               // a musculoskeletal atlas (bundle, format set by the atlas data model)
  kLandmarkSet,         // named 3D points with provenance, JSON
  kRadiographPair,      // two calibrated X-ray views: images + 3x4 projection matrices
  kMarkerTrajectories,  // motion-capture markers over time (TRC content)
  kBonePoses,           // per-frame rigid pose of every bone
  kMuscleFrames,        // a wrapped motion: bone poses, muscle surfaces and action lines per
                        // stored frame, binary (core/wrapping/muscle_frames.h)
  kFibreSet,            // muscle fibres as polylines
  kOutlineCorrections,  // an operator's verdict on projected bone outlines, JSON
                        // (core/image/outline_corrections.h)
};

struct PortTypeInfo {
  PortType type;
  std::string_view name;         // as written in workflow files and `mmm nodes`
  std::string_view description;  // what a value is and how it is serialised
  std::string_view extension;    // file extension used when the artifact is exported
};

// Every port type, in declaration order.
std::span<const PortTypeInfo> all_port_types();

const PortTypeInfo& port_type_info(PortType type);
inline std::string_view port_type_name(PortType type) { return port_type_info(type).name; }

// Parses a name as written in a workflow ("Mesh", "LandmarkSet", ...);
// std::nullopt for an unknown name.
std::optional<PortType> port_type_from_name(std::string_view name);

// Whether the type holds a single value (Number, Integer, String, Bool: a
// study input may give it a default, a command line may type it) rather than
// the content of a file.
bool is_value_type(PortType type);

// Comma-separated list of every type name, for error hints.
std::string port_type_names();

// Tags for NodeSpec::input<T>() / output<T>(): port::Mesh etc.
template <PortType T>
struct PortTag {
  static constexpr PortType kType = T;
};
namespace port {
using Number = PortTag<PortType::kNumber>;
using Integer = PortTag<PortType::kInteger>;
using String = PortTag<PortType::kString>;
using Bool = PortTag<PortType::kBool>;
using File = PortTag<PortType::kFile>;
using Report = PortTag<PortType::kReport>;
using Mesh = PortTag<PortType::kMesh>;
using Atlas = PortTag<PortType::kAtlas>;
using LandmarkSet = PortTag<PortType::kLandmarkSet>;
using RadiographPair = PortTag<PortType::kRadiographPair>;
using MarkerTrajectories = PortTag<PortType::kMarkerTrajectories>;
using BonePoses = PortTag<PortType::kBonePoses>;
using MuscleFrames = PortTag<PortType::kMuscleFrames>;
using FibreSet = PortTag<PortType::kFibreSet>;
using OutlineCorrections = PortTag<PortType::kOutlineCorrections>;
}  // namespace port

}  // namespace mmm::workflow
