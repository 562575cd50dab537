#pragma once
// The wrapped motion as one typed artifact (port type MuscleFrames): what a
// later stage needs of either wrapping pathway without reading its ParaView
// animation back. Bone poses per frame, and per muscle its rest surface
// (topology and rest positions), its surface in every stored frame and its
// action-line paths. Both pathways write it; decompose_fibres reads it.
//
// Frames: every `stride`-th frame of the motion, the same frames as the
// animation (every frame of 38 muscles over a 121-frame walk would be
// 100-300 MB). Each stored frame keeps its index in the motion.
//
// Binary, little-endian (core/binary_bytes.h):
//   "mmm.MuscleFrames" (16 bytes), uint32 version (1), string pathway,
//   uint32 motion frames, uint32 stored frames F, F x (uint32 motion index,
//   float64 time s), uint32 bones B, B x string name, F x B x 12 float64
//   (rotation row-major, then translation mm: rest -> frame), uint32 muscles,
//   per muscle: string name, uint32 vertices n, uint32 faces m, n x 3
//   float64 rest positions (mm), m x 3 uint32 faces, F x n x 3 float32
//   positions (mm), uint32 lines, per line: string name, F x (uint32 points,
//   points x 3 float64). Strings are a uint32 length and UTF-8 bytes.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/wrapping/muscle_wrapping.h"

namespace mmm::wrapping {

struct FramedLine {
  std::string name;
  std::vector<std::vector<Eigen::Vector3d>> paths;  // per stored frame (mm)
};

struct FramedMuscle {
  std::string name;
  mesh::IndexedMesh rest;                   // every frame's positions belong to it
  std::vector<Eigen::MatrixX3f> positions;  // per stored frame (mm)
  std::vector<FramedLine> lines;
};

struct MuscleFrames {
  std::string pathway;  // "energy" or "volumetric"
  int motion_frames = 0;
  std::vector<int> frame_index;  // per stored frame: its frame of the motion
  std::vector<double> times;     // per stored frame (s)
  std::vector<std::string> bone_names;
  std::vector<std::vector<Eigen::Isometry3d>> bone_poses;  // [stored frame][bone]
  std::vector<FramedMuscle> muscles;

  // The pose of `bone` in stored frame `frame`; throws InvalidInputError
  // naming the bone when the artifact has none of that name.
  [[nodiscard]] Eigen::Isometry3d pose(const std::string& bone, std::size_t frame) const;
  // The muscle of that name, or nullptr.
  [[nodiscard]] const FramedMuscle* find_muscle(std::string_view name) const;
};

// Every `stride`-th frame of `wrapped` (stride >= 1), first frame included.
MuscleFrames muscle_frames(const MuscleWrapping& wrapped, int stride, std::string pathway);

std::string encode_muscle_frames(const MuscleFrames& frames);

// Throws InvalidInputError starting with `what` and naming the field for bytes
// that are not this format (magic, version), truncated, counts beyond the
// bytes, a string over 256 bytes, non-finite numbers, a rotation that is not
// one, a face index out of range, motion indices or times not increasing,
// or bytes after the end.
MuscleFrames decode_muscle_frames(std::string_view bytes, const std::string& what);

}  // namespace mmm::wrapping
