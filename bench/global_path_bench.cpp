// Global muscle paths over bone meshes (core/wrapping/global_path.h): one
// segment around a sphere mesh, cold and warm started; and a walk: the
// first 25 action lines of the default atlas (gait2392's paths on the
// Visible Human Female's bones, obstacles left out) over 120 frames of
// subject01's walk (the reference inverse kinematics), every bone a
// surface, each frame warm started from the last.

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/mesh/primitives.h"
#include "core/motion/skeleton.h"
#include "core/opensim/mot.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/global_path.h"

namespace {

namespace wrapping = mmm::wrapping;
using Eigen::Vector3d;

constexpr int kLines = 25;
constexpr int kFrames = 120;

const mmm::mesh::SignedDistance& sphere() {
  static const mmm::mesh::SignedDistance sdf(mmm::mesh::make_icosphere(5, 30.0));
  return sdf;
}

// A wrap of ~85 degrees around a 30 mm sphere (1 mm clearance).
const Vector3d kFrom(-40, -5, 3);
const Vector3d kTo(40, -6, -2);

void BM_SegmentAroundSphereCold(benchmark::State& state) {
  const std::vector<wrapping::PosedSurface> surfaces = {{&sphere(), Eigen::Isometry3d::Identity()}};
  int iterations = 0;
  for (auto _ : state) {
    const wrapping::GlobalSegment segment = wrapping::global_segment(kFrom, kTo, surfaces);
    iterations = segment.iterations;
    benchmark::DoNotOptimize(segment.length);
  }
  state.counters["ceres_iterations"] = iterations;
}
BENCHMARK(BM_SegmentAroundSphereCold)->Unit(benchmark::kMicrosecond);

// The previous frame's path, with the insertion 2 mm away.
void BM_SegmentAroundSphereWarm(benchmark::State& state) {
  const std::vector<wrapping::PosedSurface> surfaces = {{&sphere(), Eigen::Isometry3d::Identity()}};
  const wrapping::GlobalSegment previous =
      wrapping::global_segment(kFrom, kTo + Vector3d(1, 1.5, -0.5), surfaces);
  int iterations = 0;
  for (auto _ : state) {
    const wrapping::GlobalSegment segment =
        wrapping::global_segment(kFrom, kTo, surfaces, {}, previous.points);
    iterations = segment.iterations;
    benchmark::DoNotOptimize(segment.length);
  }
  state.counters["ceres_iterations"] = iterations;
}
BENCHMARK(BM_SegmentAroundSphereWarm)->Unit(benchmark::kMicrosecond);

struct Walk {
  mmm::atlas::Atlas atlas;
  mmm::motion::Skeleton skeleton;
  std::vector<std::unique_ptr<mmm::mesh::SignedDistance>> bones;
  std::vector<int> bodies;
  std::vector<std::pair<const mmm::atlas::Muscle*, mmm::atlas::ActionLine>> lines;
  std::vector<Eigen::VectorXd> frames;
};

const Walk& walk() {
  static const Walk data = [] {
    Walk w;
    const char* dir = std::getenv("MMM_BENCH_ATLAS");
    const std::filesystem::path atlas_dir = dir != nullptr ? dir : "build/atlas/vhf_right_leg";
    w.atlas = mmm::atlas::read_atlas(atlas_dir);
    w.skeleton = mmm::motion::skeleton_from_atlas(w.atlas);
    for (const mmm::atlas::Bone& bone : w.atlas.bones) {
      const std::optional<int> body = w.skeleton.body_index(bone.name);
      if (!body || bone.meshes.empty()) continue;
      w.bones.push_back(std::make_unique<mmm::mesh::SignedDistance>(
          mmm::atlas::load_mesh(atlas_dir, bone.meshes)));
      w.bodies.push_back(*body);
    }
    for (const mmm::atlas::Muscle& muscle : w.atlas.muscles) {
      for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
        if (w.lines.size() == kLines) break;
        w.lines.emplace_back(&muscle, line);
        w.lines.back().second.wrap_obstacles.clear();
      }
    }
    const mmm::opensim::StorageTable motion =
        mmm::opensim::read_mot(std::filesystem::path(MMM_DATA_DIR) / "gait2392" / "Pipelines" /
                               "reference" / "subject01_walk1_ik.mot");
    const double first = motion.times(0);
    const double last = motion.times(motion.times.size() - 1);
    for (int f = 0; f < kFrames; ++f) {
      const Eigen::RowVectorXd row = motion.interpolate(first + (last - first) * f / (kFrames - 1));
      Eigen::VectorXd q = w.skeleton.default_coordinates();
      for (int c = 0; c < w.skeleton.num_coordinates(); ++c) {
        const mmm::motion::SkeletonCoordinate& coordinate =
            w.skeleton.coordinates[static_cast<std::size_t>(c)];
        const std::optional<Eigen::Index> column = motion.column_index(coordinate.name);
        if (!column) continue;
        q(c) = coordinate.unit == mmm::motion::CoordinateUnit::kAngle
                   ? row(*column) * std::numbers::pi / 180.0
                   : row(*column) * 1000.0;  // m -> mm
      }
      w.frames.push_back(q);
    }
    return w;
  }();
  return data;
}

void BM_WalkTwentyFiveLines(benchmark::State& state) {
  const Walk& w = walk();
  double solves = 0;
  double iterations = 0;
  for (auto _ : state) {
    solves = iterations = 0;
    std::vector<wrapping::GlobalPath> previous(w.lines.size());
    for (std::size_t f = 0; f < w.frames.size(); ++f) {
      mmm::motion::SkeletonPose pose(w.skeleton);
      pose.set(w.frames[f]);
      std::vector<wrapping::PosedSurface> surfaces;
      for (std::size_t b = 0; b < w.bones.size(); ++b) {
        surfaces.push_back({w.bones[b].get(), pose.body_pose(w.bodies[b])});
      }
      for (std::size_t i = 0; i < w.lines.size(); ++i) {
        state.PauseTiming();
        const std::vector<Vector3d> fixed =
            wrapping::action_line_path(w.atlas, *w.lines[i].first, w.lines[i].second, w.skeleton,
                                       w.frames[f])
                .points;
        state.ResumeTiming();
        previous[i] = wrapping::global_path(fixed, surfaces, {}, f > 0 ? &previous[i] : nullptr);
        for (const wrapping::GlobalSegment& segment : previous[i].segments) {
          solves += segment.iterations > 0 ? 1 : 0;
          iterations += segment.iterations;
        }
      }
    }
  }
  state.counters["paths"] = static_cast<double>(w.lines.size() * w.frames.size());
  state.counters["solves"] = solves;
  state.counters["iterations_per_solve"] = solves > 0 ? iterations / solves : 0.0;
}
BENCHMARK(BM_WalkTwentyFiveLines)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
