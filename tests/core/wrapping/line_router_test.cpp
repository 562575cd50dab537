// Action lines routed over a motion: with nothing in the way the global path
// is the straight line of the obstacle-set method (same length, same moment
// arm), and a line whose straight path runs through the femur goes around
// it, every point keeping its clearance, following the hip's motion frame by
// frame without jumps.

#include "core/wrapping/line_router.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>

#include "core/errors.h"
#include "core/mesh/signed_distance.h"
#include "core/motion/skeleton.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::wrapping {
namespace {

struct ToyRouting {
  test::ToyLeg leg = test::toy_leg();
  motion::Skeleton skeleton;
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> surfaces;
  std::vector<RoutingBone> bones;
  std::vector<std::string> bone_names;

  // The toy's muscle with one straight line from `origin` on `origin_bone`
  // to `insertion` on `insertion_bone` (atlas frame, mm).
  ToyRouting(const std::string& origin_bone, const Eigen::Vector3d& origin,
             const std::string& insertion_bone, const Eigen::Vector3d& insertion) {
    atlas::ActionLine& line = leg.atlas.muscles.front().action_lines.front();
    line.wrap_obstacles.clear();
    line.points.front().bone = origin_bone;
    line.points.front().position = origin;
    line.points.back().bone = insertion_bone;
    line.points.back().position = insertion;
    skeleton = motion::skeleton_from_atlas(leg.atlas);
    for (const atlas::Bone& bone : leg.atlas.bones) {
      surfaces[bone.name] =
          std::make_unique<mesh::SignedDistance>(leg.meshes.at(bone.name).at("full"));
      bones.push_back({surfaces[bone.name].get(), *skeleton.body_index(bone.name)});
      bone_names.push_back(bone.name);
    }
  }

  LineRouter router(PathMethod method) const {
    RouterOptions options;
    options.method = method;
    const atlas::Muscle& muscle = leg.atlas.muscles.front();
    return {leg.atlas,
            muscle,
            muscle.action_lines.front(),
            skeleton,
            method == PathMethod::kGlobal ? bones : std::vector<RoutingBone>{},
            options};
  }

  // Whether the straight path a-b passes through a bone (sampled every mm).
  bool straight_line_enters_a_bone(const ActionLinePath& path, const Eigen::VectorXd& q) const {
    ActionLinePath samples;
    const Eigen::Vector3d a = path.points.front();
    const Eigen::Vector3d b = path.points.back();
    const int n = static_cast<int>((b - a).norm());
    for (int i = 0; i <= n; ++i) samples.points.emplace_back(a + (b - a) * i / n);
    return path.points.size() == 2 && clearance(samples, q) < 0.0;
  }

  // Smallest signed distance of the path's interior points to any bone (mm).
  double clearance(const ActionLinePath& path, const Eigen::VectorXd& q) const {
    motion::SkeletonPose pose(skeleton);
    pose.set(q);
    double smallest = 1e9;
    for (std::size_t i = 1; i + 1 < path.points.size(); ++i) {
      for (const RoutingBone& bone : bones) {
        smallest =
            std::min(smallest, bone.sdf->at(pose.body_pose(bone.body).inverse() * path.points[i]));
      }
    }
    return smallest;
  }
};

TEST(LineRouterTest, WithNothingInTheWayTheGlobalPathIsTheStraightLine) {
  // In front of the thigh, 30 mm and more from every bone.
  const ToyRouting toy("femur_r", {140, 5, -150}, "tibia_r", {130, 40, -480});
  LineRouter straight = toy.router(PathMethod::kObstacleSet);
  LineRouter global = toy.router(PathMethod::kGlobal);
  const int knee = *toy.skeleton.coordinate_index("knee_angle_r");
  const int hip = *toy.skeleton.coordinate_index("hip_flexion_r");
  for (const double angle : {0.0, 0.2}) {
    Eigen::VectorXd q = toy.skeleton.default_coordinates();
    q(knee) = angle;
    const ActionLinePath a = straight.route(q);
    const ActionLinePath b = global.route(q);
    EXPECT_NEAR(b.length, a.length, 1e-9) << angle;
    EXPECT_EQ(global.last_contacts(), 0);
    EXPECT_EQ(b.point_names.front(), "origin");
    EXPECT_EQ(b.point_names.back(), "insertion");
    // The same derivative of the same length (central differences of steps
    // 0.01 and 1e-4 rad: O(h^2) apart).
    EXPECT_NEAR(global.moment_arm(q, knee), straight.moment_arm(q, knee), 1e-3) << angle;
    EXPECT_NEAR(global.moment_arm(q, hip), 0.0, 1e-6);  // both ends below the hip
  }
}

TEST(LineRouterTest, ALineThroughTheFemurGoesAroundItFrameByFrame) {
  // From beside the pelvis, in front, to behind the femur: the straight line
  // runs through the femoral shaft.
  const ToyRouting toy("pelvis", {82, 60, -60}, "femur_r", {82, -40, -400});
  LineRouter straight = toy.router(PathMethod::kObstacleSet);
  LineRouter global = toy.router(PathMethod::kGlobal);
  const int hip = *toy.skeleton.coordinate_index("hip_flexion_r");
  const GlobalPathOptions defaults;
  bool crossed = false;
  double previous_length = 0.0;
  // The hip turning in small steps, as frames of a motion (each warm-started).
  for (int step = 0; step <= 20; ++step) {
    Eigen::VectorXd q = toy.skeleton.default_coordinates();
    q(hip) = 0.02 * step;
    const ActionLinePath a = straight.route(q);
    const ActionLinePath b = global.route(q);
    EXPECT_GE(b.length, a.length - 1e-9);
    EXPECT_GT(toy.clearance(b, q), defaults.clearance_mm - 0.05) << "hip " << q(hip);
    if (toy.straight_line_enters_a_bone(a, q)) {
      crossed = true;
      EXPECT_GT(b.length, a.length);
      EXPECT_GT(global.last_contacts(), 0);
    }
    if (step > 0) {
      EXPECT_LT(std::abs(b.length - previous_length), 15.0) << "no jump between steps";
    }
    previous_length = b.length;
  }
  EXPECT_TRUE(crossed) << "the straight line never met a bone: the test checks nothing";
}

TEST(LineRouterTest, InvalidSetUpIsAnError) {
  const ToyRouting toy("femur_r", {140, 5, -150}, "tibia_r", {130, 40, -480});
  const atlas::Muscle& muscle = toy.leg.atlas.muscles.front();
  RouterOptions options;
  options.moment_arm_step_rad = 0.0;
  EXPECT_THROW(
      LineRouter(toy.leg.atlas, muscle, muscle.action_lines.front(), toy.skeleton, {}, options),
      InvalidInputError);
  options = RouterOptions{};
  EXPECT_THROW(LineRouter(toy.leg.atlas, muscle, muscle.action_lines.front(), toy.skeleton,
                          {{nullptr, 0}}, options),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping
