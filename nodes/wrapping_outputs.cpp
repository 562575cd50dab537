#include "nodes/wrapping_outputs.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/atlas/structure_carriage.h"
#include "core/bounded_json.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/vtp_series.h"
#include "core/motion/motion_io.h"
#include "core/wrapping/muscle_frames.h"
#include "core/wrapping/wrapping_summary.h"
#include "nodes/number_text.h"

namespace mmm::nodes {

std::string metrics_csv(const wrapping::MuscleWrapping& wrapped) {
  std::string csv =
      "muscle,frame,time_s,volume_error_percent,max_depth_mm,vertices_inside,vertices_deeper,"
      "deepest_bone,muscle_depth_mm,muscle_vertices_deeper,deepest_muscle,"
      "smoothness_change_percent,contacts,hull_contacts,path_contacts,contact_rounds,volume_"
      "iterations,converged,ms\n";
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    for (std::size_t f = 0; f < muscle.frames.size(); ++f) {
      const wrapping::MuscleFrameMetrics& m = muscle.frames[f];
      csv +=
          muscle.name + "," + std::to_string(f) + "," +
          fixed(wrapped.times(static_cast<Eigen::Index>(f)), 4) + "," +
          fixed(m.volume_error_percent, 8) + "," + fixed(m.max_depth_mm, 3) + "," +
          std::to_string(m.vertices_inside) + "," + std::to_string(m.vertices_deeper) + "," +
          m.deepest_bone + "," +
          (wrapped.muscle_penetration ? fixed(m.muscle_depth_mm, 3) : std::string()) + "," +
          (wrapped.muscle_penetration ? std::to_string(m.muscle_vertices_deeper) : std::string()) +
          "," +
          (m.deepest_muscle >= 0 ? wrapped.muscles[static_cast<std::size_t>(m.deepest_muscle)].name
                                 : std::string()) +
          "," + fixed(m.smoothness_change_percent, 2) + "," + std::to_string(m.contacts) + "," +
          std::to_string(m.hull_contacts) + "," + std::to_string(m.path_contacts) + "," +
          std::to_string(m.contact_rounds) + "," + std::to_string(m.volume_iterations) + "," +
          (m.converged ? "1" : "0") + "," + fixed(1000.0 * m.seconds, 2) + "\n";
    }
  }
  return csv;
}

std::string lines_csv(const wrapping::MuscleWrapping& wrapped) {
  std::string csv = "muscle,line,frame,time_s,length_mm";
  for (const std::string& coordinate : wrapped.moment_arm_coordinates)
    csv += ",moment_arm_" + coordinate + "_mm";
  csv += "\n";
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    for (const wrapping::WrappedLine& line : muscle.lines) {
      for (std::size_t f = 0; f < line.lengths_mm.size(); ++f) {
        csv += muscle.name + "," + line.name + "," + std::to_string(f) + "," +
               fixed(wrapped.times(static_cast<Eigen::Index>(f)), 4) + "," +
               fixed(line.lengths_mm[f], 3);
        for (Eigen::Index c = 0; c < line.moment_arms_mm.cols(); ++c) {
          const double arm = line.moment_arms_mm(static_cast<Eigen::Index>(f), c);
          csv += "," + (std::isfinite(arm) ? fixed(arm, 3) : std::string());
        }
        csv += "\n";
      }
    }
  }
  return csv;
}

std::string animation_bundle(const workflow::NodeContext& context,
                             const wrapping::MuscleWrapping& wrapped, const atlas::Atlas& atlas,
                             const std::filesystem::path& atlas_dir, const std::string& bone_level,
                             int stride) {
  const std::filesystem::path folder = context.scratch_dir() / "animation";
  std::filesystem::remove_all(folder);
  mesh::VtpSeriesWriter series(folder, "wrapping");
  std::vector<mesh::IndexedMesh> bones;
  for (const std::string& name : wrapped.bone_names) {
    const atlas::Bone* bone = atlas.find_bone(name);
    const atlas::MeshLevel* chosen = &bone->meshes.front();
    for (const atlas::MeshLevel& level : bone->meshes) {
      if (level.level == bone_level) chosen = &level;
    }
    bones.push_back(mesh::read_mesh(atlas_dir / chosen->file));
  }
  const std::vector<atlas::CarriedStructure> structures =
      atlas::carried_structures(atlas, atlas_dir, bone_level);
  for (Eigen::Index k = 0; k < wrapped.times.size(); k += stride) {
    const double t = wrapped.times(k);
    const auto frame = static_cast<int>(k / stride);
    const auto f = static_cast<std::size_t>(k);
    for (std::size_t b = 0; b < bones.size(); ++b) {
      mesh::IndexedMesh moved = bones[b];
      const Eigen::Isometry3d& pose = wrapped.bone_poses[f][b];
      for (Eigen::Index v = 0; v < moved.V.rows(); ++v) {
        moved.V.row(v) = (pose * Eigen::Vector3d(moved.V.row(v).transpose())).transpose();
      }
      series.add_surface(t, frame, wrapped.bone_names[b], moved);
    }
    const auto pose_of = [&](const std::string& bone) -> std::optional<Eigen::Isometry3d> {
      const auto at = std::ranges::find(wrapped.bone_names, bone);
      if (at == wrapped.bone_names.end()) return std::nullopt;
      return wrapped.bone_poses[f][static_cast<std::size_t>(at - wrapped.bone_names.begin())];
    };
    for (const atlas::CarriedStructure& structure : structures) {
      if (auto moved = atlas::carried_surface(structure, pose_of)) {
        series.add_surface(t, frame, structure.name, *moved);
      }
    }
    mesh::Polylines lines;
    std::vector<Eigen::Vector3d> points;
    for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
      mesh::IndexedMesh surface = muscle.rest;
      surface.V = muscle.positions[f].cast<double>();
      series.add_surface(t, frame, muscle.name, surface);
      for (const wrapping::WrappedLine& line : muscle.lines) {
        std::vector<int> indices;
        for (const Eigen::Vector3d& p : line.paths[f]) {
          indices.push_back(static_cast<int>(points.size()));
          points.push_back(p);
        }
        lines.lines.push_back(std::move(indices));
      }
    }
    lines.points.resize(static_cast<Eigen::Index>(points.size()), 3);
    for (std::size_t i = 0; i < points.size(); ++i)
      lines.points.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
    if (!lines.lines.empty()) series.add_polylines(t, frame, "action_lines", lines);
  }
  series.finish();
  return pack_directory(folder);
}

motion::FusedMotion atlas_motion_input(const workflow::NodeContext& context,
                                       const std::string& node) {
  nlohmann::json json;
  try {
    json = parse_json(context.input_bytes("motion"));
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError(node + ": input 'motion' is not JSON (" + std::string(e.what()) +
                            "); hint: connect fuse_motion's 'motion' output");
  }
  motion::FusedMotion fused = motion::motion_from_json(json, node + ": input 'motion'");
  if (json.value("model_kind", "") != "atlas") {
    throw InvalidInputError(node +
                            ": input 'motion' drives an OpenSim model, not an atlas; hint: give "
                            "fuse_motion the atlas input (and the model to retarget from)");
  }
  return fused;
}

workflow::NodeSpec& add_wrapping_outputs(workflow::NodeSpec& spec) {
  using workflow::port::File;
  return spec
      .param<std::int64_t>("animation_stride", 5,
                           "The animation and the wrapped motion hold every n-th frame (ASCII "
                           ".vtp: every frame of 38 muscles over a 2 s walk is several GB)",
                           {.min = 1, .max = 1000})
      .param<std::string>("bone_level", "lod2",
                          "Atlas mesh level of the bones drawn in the animation")
      .output<workflow::port::MuscleFrames>(
          "wrapped",
          "The wrapped motion, binary: bone poses and every muscle's rest surface, surface and "
          "action lines per stored frame (decompose_fibres reads it)")
      .output<File>("animation",
                    "Folder bundle of a ParaView animation (wrapping.pvd + .vtp per frame)")
      .output<File>(
          "metrics",
          "CSV per muscle and frame: volume error, penetration, contacts, smoothness, time")
      .output<File>("lines", "CSV per action line and frame: length and moment arms (hip, knee)")
      .output<File>("plot", "SVG: volume error, penetration depth, time and bending per frame");
}

void set_wrapping_outputs(workflow::NodeContext& context, const wrapping::MuscleWrapping& wrapped,
                          const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                          const std::string& plot_title, const std::string& pathway) {
  context.set_output("metrics", metrics_csv(wrapped));
  context.set_output("lines", lines_csv(wrapped));
  context.set_output("plot", wrapping::wrapping_metrics_svg(wrapped, plot_title));
  const int stride = static_cast<int>(context.integer("animation_stride"));
  context.set_output(
      "wrapped", wrapping::encode_muscle_frames(wrapping::muscle_frames(wrapped, stride, pathway)));
  context.set_output("animation", animation_bundle(context, wrapped, atlas, atlas_dir,
                                                   context.text("bone_level"), stride));
}

}  // namespace mmm::nodes
