#include "core/wrapping/muscle_frames.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace mmm::wrapping {

Eigen::Isometry3d MuscleFrames::pose(const std::string& bone, std::size_t frame) const {
  const auto at = std::ranges::find(bone_names, bone);
  if (at == bone_names.end()) {
    throw InvalidInputError("the wrapped motion has no bone '" + bone +
                            "'; hint: wrap the same atlas");
  }
  return bone_poses.at(frame)[static_cast<std::size_t>(at - bone_names.begin())];
}

const FramedMuscle* MuscleFrames::find_muscle(std::string_view name) const {
  const auto at = std::ranges::find(muscles, name, &FramedMuscle::name);
  return at == muscles.end() ? nullptr : &*at;
}

MuscleFrames muscle_frames(const MuscleWrapping& wrapped, int stride, std::string pathway) {
  if (stride < 1)
    throw InvalidInputError("muscle_frames: stride " + std::to_string(stride) + " < 1");
  MuscleFrames out;
  out.pathway = std::move(pathway);
  out.motion_frames = static_cast<int>(wrapped.times.size());
  for (int k = 0; k < out.motion_frames; k += stride) {
    out.frame_index.push_back(k);
    out.times.push_back(wrapped.times(k));
    out.bone_poses.push_back(wrapped.bone_poses.at(static_cast<std::size_t>(k)));
  }
  out.bone_names = wrapped.bone_names;
  for (const WrappedMuscle& muscle : wrapped.muscles) {
    FramedMuscle& framed = out.muscles.emplace_back();
    framed.name = muscle.name;
    framed.rest = muscle.rest;
    for (const int k : out.frame_index)
      framed.positions.push_back(muscle.positions.at(static_cast<std::size_t>(k)));
    for (const WrappedLine& line : muscle.lines) {
      FramedLine& l = framed.lines.emplace_back();
      l.name = line.name;
      for (const int k : out.frame_index)
        l.paths.push_back(line.paths.at(static_cast<std::size_t>(k)));
    }
  }
  return out;
}

}  // namespace mmm::wrapping
