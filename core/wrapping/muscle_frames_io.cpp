// encode_muscle_frames / decode_muscle_frames of muscle_frames.h.

#include <array>
#include <string>

#include "core/binary_bytes.h"
#include "core/wrapping/muscle_frames.h"

namespace mmm::wrapping {
namespace {

constexpr std::string_view kMagic = "mmm.MuscleFrames";
constexpr std::uint32_t kVersion = 1;

void put_pose(BinaryWriter& out, const Eigen::Isometry3d& pose) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.put(pose.linear()(r, c));
  for (int r = 0; r < 3; ++r) out.put(pose.translation()(r));
}

Eigen::Isometry3d get_pose(BinaryReader& in, const std::string& field) {
  Eigen::Matrix3d rotation;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation(r, c) = in.finite<double>(field);
  Eigen::Vector3d translation;
  for (int r = 0; r < 3; ++r) translation(r) = in.finite<double>(field);
  const double off =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (off > 1e-6 || rotation.determinant() < 0.0) {
    in.fail(field, "is not a rotation (|R'R - I| = " + std::to_string(off) + ")");
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = translation;
  return pose;
}

FramedMuscle get_muscle(BinaryReader& in, std::size_t frames, std::size_t index) {
  FramedMuscle muscle;
  const std::string where = "muscle " + std::to_string(index);
  muscle.name = in.string(where + " name");
  const std::string field = "muscle '" + muscle.name + "'";
  if (muscle.name.empty()) in.fail(where, "has no name");
  const std::uint32_t vertices = in.count(field + " vertices", 3 * sizeof(double));
  const auto faces = in.get<std::uint32_t>(field + " faces");
  in.need(faces, 3 * sizeof(std::uint32_t), field + " faces");
  in.need(static_cast<std::uint64_t>(frames) * vertices, 3 * sizeof(float), field + " positions");
  muscle.rest.V.resize(vertices, 3);
  for (Eigen::Index v = 0; v < vertices; ++v)
    for (int c = 0; c < 3; ++c) muscle.rest.V(v, c) = in.finite<double>(field + " rest vertex");
  muscle.rest.F.resize(faces, 3);
  for (Eigen::Index f = 0; f < faces; ++f) {
    for (int c = 0; c < 3; ++c) {
      const auto corner = in.get<std::uint32_t>(field + " face");
      if (corner >= vertices) {
        in.fail(field + " face " + std::to_string(f),
                "refers to vertex " + std::to_string(corner) + " of " + std::to_string(vertices));
      }
      muscle.rest.F(f, c) = static_cast<int>(corner);
    }
  }
  for (std::size_t k = 0; k < frames; ++k) {
    Eigen::MatrixX3f& p = muscle.positions.emplace_back(vertices, 3);
    for (Eigen::Index v = 0; v < vertices; ++v)
      for (int c = 0; c < 3; ++c) p(v, c) = in.finite<float>(field + " positions");
  }
  const std::uint32_t lines = in.count(field + " lines", sizeof(std::uint32_t));
  for (std::uint32_t l = 0; l < lines; ++l) {
    FramedLine& line = muscle.lines.emplace_back();
    line.name = in.string(field + " line name");
    const std::string line_field = field + " line '" + line.name + "'";
    for (std::size_t k = 0; k < frames; ++k) {
      const std::uint32_t points = in.count(line_field + " points", 3 * sizeof(double));
      std::vector<Eigen::Vector3d>& path = line.paths.emplace_back(points);
      for (Eigen::Vector3d& point : path)
        for (int c = 0; c < 3; ++c) point(c) = in.finite<double>(line_field + " point");
    }
  }
  return muscle;
}

}  // namespace

std::string encode_muscle_frames(const MuscleFrames& frames) {
  BinaryWriter out;
  out.put_raw(kMagic);
  out.put(kVersion);
  out.put_string(frames.pathway);
  out.put(static_cast<std::uint32_t>(frames.motion_frames));
  out.put(static_cast<std::uint32_t>(frames.times.size()));
  for (std::size_t k = 0; k < frames.times.size(); ++k) {
    out.put(static_cast<std::uint32_t>(frames.frame_index[k]));
    out.put(frames.times[k]);
  }
  out.put(static_cast<std::uint32_t>(frames.bone_names.size()));
  for (const std::string& name : frames.bone_names) out.put_string(name);
  for (const std::vector<Eigen::Isometry3d>& poses : frames.bone_poses)
    for (const Eigen::Isometry3d& pose : poses) put_pose(out, pose);
  out.put(static_cast<std::uint32_t>(frames.muscles.size()));
  for (const FramedMuscle& muscle : frames.muscles) {
    out.put_string(muscle.name);
    out.put(static_cast<std::uint32_t>(muscle.rest.V.rows()));
    out.put(static_cast<std::uint32_t>(muscle.rest.F.rows()));
    for (Eigen::Index v = 0; v < muscle.rest.V.rows(); ++v)
      for (int c = 0; c < 3; ++c) out.put(muscle.rest.V(v, c));
    for (Eigen::Index f = 0; f < muscle.rest.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) out.put(static_cast<std::uint32_t>(muscle.rest.F(f, c)));
    for (const Eigen::MatrixX3f& p : muscle.positions)
      for (Eigen::Index v = 0; v < p.rows(); ++v)
        for (int c = 0; c < 3; ++c) out.put(p(v, c));
    out.put(static_cast<std::uint32_t>(muscle.lines.size()));
    for (const FramedLine& line : muscle.lines) {
      out.put_string(line.name);
      for (const std::vector<Eigen::Vector3d>& path : line.paths) {
        out.put(static_cast<std::uint32_t>(path.size()));
        for (const Eigen::Vector3d& point : path)
          for (int c = 0; c < 3; ++c) out.put(point(c));
      }
    }
  }
  return std::move(out).take();
}

MuscleFrames decode_muscle_frames(std::string_view bytes, const std::string& what) {
  BinaryReader in(bytes, what);
  if (in.raw(std::min(bytes.size(), kMagic.size()), "header") != kMagic) {
    in.fail("header",
            "is not \"mmm.MuscleFrames\"; hint: connect a wrapping node's 'wrapped' output");
  }
  const auto version = in.get<std::uint32_t>("version");
  if (version != kVersion) {
    in.fail("version", std::to_string(version) + " is not " + std::to_string(kVersion) +
                           "; hint: run the wrapping again with this mmm");
  }
  MuscleFrames frames;
  frames.pathway = in.string("pathway", 64);
  frames.motion_frames = static_cast<int>(in.get<std::uint32_t>("motion frames"));
  const std::uint32_t stored = in.count("stored frames", sizeof(std::uint32_t) + sizeof(double));
  if (stored > static_cast<std::uint32_t>(frames.motion_frames)) {
    in.fail("stored frames", std::to_string(stored) + " is more than the motion's " +
                                 std::to_string(frames.motion_frames));
  }
  for (std::uint32_t k = 0; k < stored; ++k) {
    const auto index = in.get<std::uint32_t>("frame index");
    const auto time = in.finite<double>("frame time");
    if (index >= static_cast<std::uint32_t>(frames.motion_frames) ||
        (k > 0 &&
         (static_cast<int>(index) <= frames.frame_index.back() || time <= frames.times.back()))) {
      in.fail("frame " + std::to_string(k),
              "index " + std::to_string(index) + " or time is out of order or beyond the motion");
    }
    frames.frame_index.push_back(static_cast<int>(index));
    frames.times.push_back(time);
  }
  const std::uint32_t bones = in.count("bones", sizeof(std::uint32_t));
  for (std::uint32_t b = 0; b < bones; ++b) frames.bone_names.push_back(in.string("bone name"));
  in.need(static_cast<std::uint64_t>(stored) * bones, 12 * sizeof(double), "bone poses");
  for (std::uint32_t k = 0; k < stored; ++k) {
    std::vector<Eigen::Isometry3d>& poses = frames.bone_poses.emplace_back();
    for (std::uint32_t b = 0; b < bones; ++b)
      poses.push_back(get_pose(
          in, "pose of bone '" + frames.bone_names[b] + "' in frame " + std::to_string(k)));
  }
  const std::uint32_t muscles = in.count("muscles", 3 * sizeof(std::uint32_t));
  for (std::uint32_t m = 0; m < muscles; ++m) frames.muscles.push_back(get_muscle(in, stored, m));
  if (!in.at_end()) in.fail("end", "is followed by more bytes; hint: the file is not this format");
  return frames;
}

}  // namespace mmm::wrapping
