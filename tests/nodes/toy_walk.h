#pragma once
// The toy leg (tests/support/toy_leg_atlas.h) walking: three pelvis markers
// added, written into a node harness, and its motion from fuse_motion over
// the real trial (0.5 s to end_time), for the wrapping nodes' tests.

#include <gtest/gtest.h>
#include <Eigen/Core>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/mesh/io/pvd.h"
#include "core/mesh/io/vtp.h"
#include "core/wrapping/muscle_frames.h"
#include "nodes/fuse_motion.h"
#include "tests/support/test_data.h"

#include "tests/nodes/node_harness.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::nodes::test {

// The toy leg with three pelvis markers (retargeting measures the patient
// against the trial), written into the harness, and its motion over the
// walk from 0.5 s to end_time.
struct ToyLegAndWalk {
  mmm::test::ToyLeg leg;
  workflow::ArtifactRef atlas;
  workflow::ArtifactRef motion;
};

// A second vastus beside the first, overlapping it by `overlap` mm at rest.
inline void add_neighbour(mmm::test::ToyLeg& leg, double overlap,
                          const Eigen::Vector3d& side = Eigen::Vector3d::UnitX()) {
  atlas::Muscle neighbour = leg.atlas.muscles.front();
  const std::string first = neighbour.name;
  neighbour.name = "vastus_b_r";
  const Eigen::Vector3d shift = (20.0 - overlap) * side;
  for (atlas::MeshLevel& level : neighbour.meshes) {
    level.file = "meshes/vastus_b_r/" + level.level + ".ply";
    mesh::IndexedMesh moved = leg.meshes.at(first).at(level.level);
    moved.V.rowwise() += shift.transpose();
    leg.meshes[neighbour.name][level.level] = moved;
  }
  for (atlas::ActionLine& line : neighbour.action_lines) {
    line.name = neighbour.name;
    for (atlas::PathPoint& point : line.points) point.position += shift;
  }
  for (atlas::AttachmentArea& area : neighbour.origins) area.centroid += shift;
  neighbour.wrap_obstacles.clear();
  leg.atlas.muscles.push_back(neighbour);
}

// An insertion area for the toy vastus: the 8 tibia faces nearest its
// action line's insertion point (the toy leg has only an origin).
inline void add_insertion(mmm::test::ToyLeg& leg) {
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  const Eigen::Vector3d end = muscle.action_lines.front().points.back().position;
  const mesh::IndexedMesh& tibia = leg.meshes.at("tibia_r").at("full");
  atlas::AttachmentArea area;
  area.bone = "tibia_r";
  std::vector<std::pair<double, int>> by_distance;
  for (Eigen::Index f = 0; f < tibia.F.rows(); ++f) {
    const Eigen::Vector3d centroid =
        (tibia.V.row(tibia.F(f, 0)) + tibia.V.row(tibia.F(f, 1)) + tibia.V.row(tibia.F(f, 2)))
            .transpose() /
        3.0;
    by_distance.emplace_back((centroid - end).norm(), static_cast<int>(f));
  }
  std::sort(by_distance.begin(), by_distance.end());
  for (std::size_t i = 0; i < std::min<std::size_t>(8, by_distance.size()); ++i) {
    area.faces.push_back(by_distance[i].second);
  }
  area.centroid = end;
  muscle.insertions = {area};
}

// neighbour_overlap < 0: no neighbour.
inline ToyLegAndWalk toy_leg_and_walk(
    NodeHarness& harness, double end_time, double neighbour_overlap = -1.0,
    bool with_insertion = false, const Eigen::Vector3d& neighbour_side = Eigen::Vector3d::UnitX()) {
  ToyLegAndWalk result{mmm::test::toy_leg(), {}, {}};
  if (with_insertion) add_insertion(result.leg);
  if (neighbour_overlap >= 0.0) add_neighbour(result.leg, neighbour_overlap, neighbour_side);
  for (const auto& [name, x] : {std::pair{"R.ASIS", 150.0}, {"L.ASIS", -60.0}}) {
    result.leg.atlas.markers.push_back({name, "pelvis", Eigen::Vector3d(x, 30, 20), true});
  }
  result.leg.atlas.markers.push_back({"V.Sacral", "pelvis", Eigen::Vector3d(45, -120, 30), true});
  atlas::write_atlas_with_meshes(result.leg.atlas, result.leg.meshes, harness.folder() / "toy");
  result.atlas = harness.add(workflow::PortType::kAtlas, pack_directory(harness.folder() / "toy"));
  const auto fused = harness.run<FuseMotion>(
      {{"atlas", result.atlas},
       {"model",
        harness.add_file(workflow::PortType::kFile,
                         mmm::test::gait2392_pipelines() / "reference" / "subject01_simbody.osim")},
       {"trial", harness.add_file(workflow::PortType::kFile,
                                  mmm::test::gait2392_pipelines() / "subject01_walk1.trc")}},
      {{"start_time", 0.5}, {"end_time", end_time}});
  result.motion = fused.at("motion");
  return result;
}

// The outputs both wrapping nodes write: one metrics row per muscle and
// frame, the action lines with the knee's moment arm, an SVG plot, and every
// `stride`-th frame of `muscle`, the femur and the lines in the ParaView
// animation.
inline void expect_wrapping_outputs(NodeHarness& harness,
                                    const std::map<std::string, workflow::ArtifactRef>& outputs,
                                    int frames, long muscles, const std::string& muscle,
                                    int stride) {
  const std::string metrics = mmm::test::read_text(outputs.at("metrics").path);
  EXPECT_EQ(std::count(metrics.begin(), metrics.end(), '\n'), 1 + frames * muscles);
  EXPECT_EQ(metrics.rfind("muscle,frame,time_s,volume_error_percent,max_depth_mm", 0), 0U);
  const std::string lines = mmm::test::read_text(outputs.at("lines").path);
  EXPECT_NE(lines.find("moment_arm_knee_angle_r_mm"), std::string::npos);
  EXPECT_EQ(mmm::test::read_text(outputs.at("plot").path).rfind("<svg", 0), 0U);
  const std::filesystem::path animation = harness.folder() / "animation";
  std::filesystem::remove_all(animation);
  unpack_directory(mmm::test::read_text(outputs.at("animation").path), animation, "animation");
  long muscle_frames = 0;
  for (const mesh::PvdEntry& entry : mesh::read_pvd(animation / "wrapping.pvd")) {
    if (entry.file.filename().string().rfind(muscle + "_", 0) == 0) ++muscle_frames;
  }
  EXPECT_EQ(muscle_frames, (frames + stride - 1) / stride);
  EXPECT_TRUE(std::filesystem::exists(animation / "wrapping" / "action_lines_0000.vtp"));
  EXPECT_TRUE(std::filesystem::exists(animation / "wrapping" / "femur_r_0000.vtp"));
  // The wrapped motion holds the animation's frames: the same muscle surfaces
  // (vertex for vertex) and the bones' poses.
  const wrapping::MuscleFrames wrapped = wrapping::decode_muscle_frames(
      mmm::test::read_text(outputs.at("wrapped").path), "output 'wrapped'");
  EXPECT_EQ(wrapped.motion_frames, frames);
  ASSERT_EQ(static_cast<long>(wrapped.times.size()), muscle_frames);
  EXPECT_EQ(static_cast<long>(wrapped.muscles.size()), muscles);
  const wrapping::FramedMuscle* framed = wrapped.find_muscle(muscle);
  ASSERT_NE(framed, nullptr);
  const mesh::IndexedMesh drawn = mesh::read_vtp(animation / "wrapping" / (muscle + "_0001.vtp"));
  ASSERT_EQ(drawn.V.rows(), framed->rest.V.rows());
  EXPECT_LT((drawn.V - framed->positions[1].cast<double>()).cwiseAbs().maxCoeff(), 1e-2);
  EXPECT_EQ(wrapped.pose("femur_r", 0).matrix().rows(), 4);
}

}  // namespace mmm::nodes::test
