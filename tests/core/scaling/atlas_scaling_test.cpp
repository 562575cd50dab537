// The energy stage of atlas scaling on analytic cases: affine anchors and
// the bone energy recover a known affine map exactly, the point terms bend
// a bone smoothly when no affine map fits, muscles stay on the bones they
// touch and come out of a bone they would enter, and a small leg atlas with
// meshes is carried through a known similarity with every element.

#include "core/scaling/atlas_scaling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"
#include "core/scaling/affine_anchor.h"
#include "core/scaling/bone_energy.h"
#include "core/scaling/muscle_energy.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::scaling {
namespace {

using Eigen::Affine3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

Affine3d skewed_affine() {
  Affine3d map = Affine3d::Identity();
  map.linear() << 1.10, 0.05, -0.02,  //
      -0.03, 0.92, 0.04,              //
      0.01, 0.06, 1.05;
  map.linear() = Eigen::AngleAxisd(0.4, Vector3d(1, -2, 0.5).normalized()).matrix() * map.linear();
  map.translation() = Vector3d(12, -30, 7);
  return map;
}

using test::ellipsoid;
using test::toy_leg;
using test::ToyLeg;

Eigen::MatrixX3d mapped(const Affine3d& map, const Eigen::MatrixX3d& V) {
  return (V * map.linear().transpose()).rowwise() + map.translation().transpose();
}

TEST(AffineAnchorTest, ReconstructsAffinelyMappedPointsOnNearAndFarFromTheSurface) {
  const mesh::IndexedMesh surface = ellipsoid(Vector3d(5, -3, 40), Vector3d(20, 15, 60));
  const AnchorBuilder builder(surface.V);
  const Affine3d map = skewed_affine();
  const Eigen::MatrixX3d moved = mapped(map, surface.V);
  for (const Vector3d& point :
       {Vector3d(surface.V.row(10).transpose()), Vector3d(25.5, -3, 40),  // just outside
        Vector3d(5, -3, 40),                                              // the centre
        Vector3d(60, 50, 150)}) {                                         // far away
    const AffineAnchor anchor = builder.anchor(point);
    double sum = 0;
    for (const double w : anchor.weights) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-9);
    EXPECT_LT((reconstruct(anchor, surface.V) - point).norm(), 1e-6);
    EXPECT_LT((reconstruct(anchor, moved) - map * point).norm(), 1e-6) << point.transpose();
  }
  EXPECT_THROW((void)builder.anchor(Vector3d(std::nan(""), 0, 0)), InvalidInputError);
}

std::vector<PointTerm> terms_for(const mesh::IndexedMesh& bone, const std::vector<Vector3d>& points,
                                 const Affine3d& to) {
  const AnchorBuilder builder(bone.V);
  std::vector<PointTerm> terms;
  for (std::size_t i = 0; i < points.size(); ++i) {
    terms.push_back(
        {"p" + std::to_string(i), builder.anchor(points[i]), points[i], to * points[i], 100.0});
  }
  return terms;
}

TEST(BoneEnergyTest, AKnownAffineMapIsRecoveredExactly) {
  const mesh::IndexedMesh bone = ellipsoid(Vector3d(0, 0, -200), Vector3d(25, 20, 200));
  const Affine3d truth = skewed_affine();
  // Five landmarks around the bone, spread in every direction (on, inside
  // and off the surface).
  const std::vector<PointTerm> terms =
      terms_for(bone,
                {Vector3d(25, 0, -200), Vector3d(0, 20, -120), Vector3d(-30, 0, -280),
                 Vector3d(0, -15, -50), Vector3d(0, 0, -390)},
                truth);
  const BoneSolution solution = solve_bone(bone, Affine3d::Identity(), terms);
  EXPECT_TRUE(solution.solved);
  EXPECT_EQ(solution.free_directions, 0);
  EXPECT_FALSE(solution.bent);
  EXPECT_LT((solution.vertices - mapped(truth, bone.V)).rowwise().norm().maxCoeff(), 1e-4);
  EXPECT_LT((solution.affine.linear() - truth.linear()).norm(), 1e-5);
  for (const double r : solution.residual_mm) EXPECT_LT(r, 1e-4);
}

TEST(BoneEnergyTest, DirectionsTheLandmarksLeaveOpenKeepThePrior) {
  const mesh::IndexedMesh bone = ellipsoid(Vector3d(0, 0, -200), Vector3d(25, 20, 200));
  const Affine3d truth = skewed_affine();
  // Three landmarks and a fourth 0.5 mm from the first: a plane, whose
  // normal direction the near pair must not decide.
  const std::vector<PointTerm> terms = terms_for(bone,
                                                 {Vector3d(25, 0, -200), Vector3d(-25, 0, -150),
                                                  Vector3d(0, 0, -390), Vector3d(25, 0.5, -200)},
                                                 truth);
  Affine3d skewed_prior = truth;
  skewed_prior.linear() *= 1.02;
  const BoneSolution from_skewed = solve_bone(bone, skewed_prior, terms);
  EXPECT_GT(from_skewed.free_directions, 0);
  for (const double r : from_skewed.residual_mm) EXPECT_LT(r, 0.5);
  // The direction across the plane (y) keeps the prior's scale.
  EXPECT_NEAR((from_skewed.affine.linear() * Vector3d::UnitY()).norm(),
              (skewed_prior.linear() * Vector3d::UnitY()).norm(), 0.02);
}

TEST(BoneEnergyTest, APriorThatMeetsEveryTermIsTheClosedFormMinimum) {
  const mesh::IndexedMesh bone = ellipsoid(Vector3d(0, 0, 0), Vector3d(20, 20, 80));
  const Affine3d truth = skewed_affine();
  const std::vector<PointTerm> terms =
      terms_for(bone, {Vector3d(0, 0, 70), Vector3d(15, 0, 0)}, truth);
  const BoneSolution solution = solve_bone(bone, truth, terms);
  EXPECT_FALSE(solution.solved);
  EXPECT_LT((solution.vertices - mapped(truth, bone.V)).norm(), 1e-9);
}

TEST(BoneEnergyTest, TermsNoAffineMapMeetsBendTheSurfaceSmoothly) {
  const mesh::IndexedMesh bone = ellipsoid(Vector3d(0, 0, 0), Vector3d(15, 15, 100), 4);
  // Both ends fixed and the surface point at the middle pulled out by 5 mm.
  Eigen::Index middle = 0;
  for (Eigen::Index i = 0; i < bone.V.rows(); ++i) {
    if (std::abs(bone.V(i, 2)) < std::abs(bone.V(middle, 2)) && bone.V(i, 0) > 10) middle = i;
  }
  const Vector3d pulled = bone.V.row(middle).transpose();
  std::vector<PointTerm> terms = terms_for(
      bone, {Vector3d(0, 0, 100), Vector3d(0, 0, -100), Vector3d(0, 15, 60), Vector3d(-15, 0, -60)},
      Affine3d::Identity());
  const AnchorBuilder builder(bone.V);
  terms.push_back({"pulled", builder.anchor(pulled), pulled, pulled + Vector3d(5, 0, 0), 100.0});
  const BoneSolution solution = solve_bone(bone, Affine3d::Identity(), terms);
  ASSERT_TRUE(solution.solved);
  // The pulled point goes most of the way, the ends stay.
  EXPECT_GT(solution.vertices(middle, 0) - pulled.x(), 4.0);
  for (std::size_t t = 0; t + 1 < terms.size(); ++t) EXPECT_LT(solution.residual_mm[t], 0.5);
  // What the affine part cannot explain is a smooth, local bend: the detail
  // displacement d fades with distance from the pulled point (mean over
  // vertices within 15 mm vs beyond 60 mm).
  const Eigen::MatrixX3d affine_part = mapped(solution.affine, bone.V);
  double near_sum = 0, far_sum = 0;
  int near_count = 0, far_count = 0;
  for (Eigen::Index i = 0; i < bone.V.rows(); ++i) {
    const double distance = (bone.V.row(i).transpose() - pulled).norm();
    const double move = (solution.vertices.row(i) - affine_part.row(i)).norm();
    if (distance < 15) near_sum += move, ++near_count;
    if (distance > 60) far_sum += move, ++far_count;
  }
  ASSERT_GT(near_count, 0);
  ASSERT_GT(far_count, 0);
  EXPECT_GT(near_sum / near_count, 3.0 * far_sum / far_count);
}

TEST(BoneEnergyTest, NonFiniteTargetIsRejected) {
  const mesh::IndexedMesh bone = ellipsoid(Vector3d::Zero(), Vector3d(10, 10, 10), 2);
  std::vector<PointTerm> terms = terms_for(bone, {Vector3d(0, 0, 10)}, Affine3d::Identity());
  terms[0].target.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)solve_bone(bone, Affine3d::Identity(), terms), InvalidInputError);
}

// A muscle lying along a bone, `gap` mm off it, and a second bone on its
// other side, `far_gap` mm off it.
struct MuscleScene {
  explicit MuscleScene(double gap, double far_gap)
      : muscle(ellipsoid(Vector3d(15 + gap + 10, 0, 0), Vector3d(10, 10, 80), 3)),
        far_bone(ellipsoid(Vector3d(15 + gap + 20 + far_gap + 15, 0, 0), Vector3d(15, 15, 100), 3)),
        far_anchors(far_bone.V),
        far_distance(far_bone) {}

  mesh::IndexedMesh bone = ellipsoid(Vector3d(0, 0, 0), Vector3d(15, 15, 100), 3);
  mesh::IndexedMesh muscle;
  mesh::IndexedMesh far_bone;
  AnchorBuilder bone_anchors{bone.V};
  AnchorBuilder far_anchors;
  mesh::SignedDistance bone_distance{bone};
  mesh::SignedDistance far_distance;

  std::vector<BoneAtRest> at_rest() {
    return {{"bone", &bone, &bone, &bone_anchors, &bone_distance},
            {"far", &far_bone, &far_bone, &far_anchors, &far_distance}};
  }
};

TEST(MuscleEnergyTest, TheBlendOfEqualMapsIsThatMapAndTouchingVerticesStayOnTheBone) {
  MuscleScene scene(0.5, 40.0);
  const PreparedMuscle prepared = prepare_muscle("m", scene.muscle, scene.at_rest());
  ASSERT_GT(prepared.attached.size(), 10u);
  const Affine3d map = skewed_affine();
  const Eigen::MatrixX3d bone_v = mapped(map, scene.bone.V);
  const Eigen::MatrixX3d far_v = mapped(map, scene.far_bone.V);
  const mesh::SignedDistance bone_d({bone_v, scene.bone.F});
  const mesh::SignedDistance far_d({far_v, scene.far_bone.F});
  const MuscleSolution solution =
      solve_muscle(prepared, {{&map, &bone_v, &bone_d}, {&map, &far_v, &far_d}});
  EXPECT_LT((solution.vertices - mapped(map, scene.muscle.V)).rowwise().norm().maxCoeff(), 1e-6);
  EXPECT_LT(solution.attachment_rms_mm, 1e-6);
  EXPECT_NEAR(solution.volume_ratio, map.linear().determinant(), 1e-9);
}

TEST(MuscleEnergyTest, AMuscleTheBlendWouldPushIntoABoneComesOutOfIt) {
  // Between two bones, 2 and 3 mm off them (in the band, not attached); the
  // first bone moves 25 mm into the muscle, the other stays: the blend lags
  // behind the moving bone on the muscle's inner side and squeezes the outer
  // side into the still bone.
  MuscleScene scene(2.0, 3.0);
  const PreparedMuscle prepared = prepare_muscle("m", scene.muscle, scene.at_rest());
  EXPECT_TRUE(prepared.attached.empty());
  EXPECT_FALSE(prepared.band.empty());
  const Affine3d moved(Eigen::Translation3d(25, 0, 0));
  const Affine3d still = Affine3d::Identity();
  const Eigen::MatrixX3d bone_v = mapped(moved, scene.bone.V);
  const mesh::SignedDistance bone_d({bone_v, scene.bone.F});
  const std::vector<ScaledBone> bones = {{&moved, &bone_v, &bone_d},
                                         {&still, &scene.far_bone.V, &scene.far_distance}};
  MuscleEnergyOptions no_push;
  no_push.max_penetration_iterations = 0;
  const MuscleSolution before = solve_muscle(prepared, bones, no_push);
  const MuscleSolution after = solve_muscle(prepared, bones);
  EXPECT_GT(before.excess_depth_after_mm, 0.5);
  EXPECT_GT(after.penetrating_before, 0);
  EXPECT_LE(after.excess_depth_after_mm, 0.1);
  // Checked independently of the band bookkeeping: no muscle vertex deeper
  // than 0.2 mm in either bone (neither touched the muscle at rest).
  double deepest = 0;
  for (Eigen::Index i = 0; i < after.vertices.rows(); ++i) {
    const Vector3d x = after.vertices.row(i).transpose();
    deepest = std::max({deepest, -bone_d.at(x), -scene.far_distance.at(x)});
  }
  EXPECT_LT(deepest, 0.2);
  // Pushing out keeps the volume to within a few percent.
  EXPECT_NEAR(after.volume_ratio, before.volume_ratio, 0.05);
}

landmarks::LandmarkSet station_landmarks(const atlas::Atlas& a, const Affine3d& map) {
  landmarks::LandmarkSet set;
  for (const char* name : {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"}) {
    set.landmarks.push_back({name, map * a.find_landmark(name)->position, {}, {}});
  }
  return set;
}

Affine3d similarity() {
  Affine3d map = Affine3d::Identity();
  map.linear() = 1.07 * Eigen::AngleAxisd(0.3, Vector3d(0.2, 1, -0.4).normalized()).matrix();
  map.translation() = Vector3d(-40, 25, 900);
  return map;
}

TEST(AtlasScalingTest, AKnownSimilarityCarriesEveryElementExactly) {
  const ToyLeg leg = toy_leg();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  const Affine3d map = similarity();
  const ScaledAtlas scaled = scale_atlas(*prepared, station_landmarks(leg.atlas, map));
  constexpr double kExact = 1e-6;
  for (const auto& [element, levels] : leg.meshes) {
    for (const auto& [level, surface] : levels) {
      SCOPED_TRACE(::testing::Message() << element << " " << level);
      const Eigen::MatrixX3d& placed = scaled.meshes.at(element).at(level).V;
      EXPECT_LT((placed - mapped(map, surface.V)).rowwise().norm().maxCoeff(), kExact);
      EXPECT_EQ(scaled.meshes.at(element).at(level).F, surface.F);
    }
  }
  for (const auto& [name, residual] : scaled.landmark_residual_mm)
    EXPECT_LT(residual, kExact) << name;
  const atlas::Atlas& out = scaled.atlas;
  EXPECT_LT((out.landmarks[3].position - map * leg.atlas.landmarks[3].position).norm(), kExact);
  EXPECT_LT((out.markers[0].position - map * leg.atlas.markers[0].position).norm(), kExact);
  for (std::size_t p = 0; p < 2; ++p) {
    EXPECT_LT((out.muscles[0].action_lines[0].points[p].position -
               map * leg.atlas.muscles[0].action_lines[0].points[p].position)
                  .norm(),
              kExact);
  }
  EXPECT_LT(
      (out.muscles[0].origins[0].centroid - map * leg.atlas.muscles[0].origins[0].centroid).norm(),
      kExact);
  const atlas::WrapObstacle& wrap = out.muscles[0].wrap_obstacles[0];
  EXPECT_LT((wrap.pose.translation() - map * Vector3d(85, 10, -430)).norm(), kExact);
  EXPECT_NEAR(wrap.radii.x(), 20 * 1.07, 1e-9);
  EXPECT_LT((wrap.pose.linear() - map.linear() / 1.07).norm(), 1e-9);
  for (std::size_t j = 0; j < leg.atlas.joints.size(); ++j) {
    EXPECT_LT((out.joints[j].child_frame.translation() -
               map * leg.atlas.joints[j].child_frame.translation())
                  .norm(),
              kExact);
  }
  for (const BoneScaling& bone : scaled.bones) {
    EXPECT_FALSE(bone.solved) << bone.bone << ": the first stage meets every term";
    EXPECT_NEAR(bone.stretches.x(), 1.07, 1e-9) << bone.bone;
  }
  EXPECT_NEAR(scaled.muscles[0].solution.volume_ratio, std::pow(1.07, 3), 1e-9);
  EXPECT_GT(scaled.muscles[0].solution.attached_vertices, 0);
}

TEST(AtlasScalingTest, AFurtherLandmarkBendsItsBoneOntoIt) {
  const ToyLeg leg = toy_leg();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  const Affine3d map = similarity();
  landmarks::LandmarkSet set = station_landmarks(leg.atlas, map);
  // The femur is 4 mm wider at the epicondyle than the similarity says.
  const Vector3d epicondyle = map * Vector3d(107, 10, -440);
  set.landmarks.push_back({"lateral_epicondyle_r", epicondyle, {}, {}});
  set.landmarks.push_back({"not_in_the_atlas", Vector3d(0, 0, 0), {}, {}});
  const ScaledAtlas scaled = scale_atlas(*prepared, set);
  for (const auto& [name, residual] : scaled.landmark_residual_mm) EXPECT_LT(residual, 0.5) << name;
  EXPECT_EQ(scaled.unused_landmarks, std::vector<std::string>{"not_in_the_atlas"});
  const auto femur = std::find_if(scaled.bones.begin(), scaled.bones.end(),
                                  [](const BoneScaling& b) { return b.bone == "femur_r"; });
  ASSERT_NE(femur, scaled.bones.end());
  EXPECT_TRUE(femur->solved);
  // The chain stays connected: the tibia hangs where the femur puts the knee.
  const Vector3d knee_on_femur = scaled.atlas.joints[1].parent_frame.translation();
  const Vector3d knee_on_tibia = scaled.atlas.joints[1].child_frame.translation();
  EXPECT_LT((knee_on_femur - knee_on_tibia).norm(), 0.5);
}

std::string scaling_error(const ToyLeg& leg, const landmarks::LandmarkSet& set) {
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  try {
    (void)scale_atlas(*prepared, set);
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "(no InvalidInputError)";
}

TEST(AtlasScalingTest, BadLandmarksAreRejectedWithTheirNames) {
  const ToyLeg leg = toy_leg();
  landmarks::LandmarkSet missing = station_landmarks(leg.atlas, Affine3d::Identity());
  missing.landmarks.erase(missing.landmarks.begin() + 1);
  EXPECT_NE(scaling_error(leg, missing).find("patella_centre_r"), std::string::npos);
  landmarks::LandmarkSet coincident = station_landmarks(leg.atlas, Affine3d::Identity());
  coincident.landmarks[1].position_mm = coincident.landmarks[0].position_mm;
  EXPECT_NE(scaling_error(leg, coincident), "(no InvalidInputError)");
  landmarks::LandmarkSet nan = station_landmarks(leg.atlas, Affine3d::Identity());
  nan.landmarks[2].position_mm.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(scaling_error(leg, nan).find("ankle_centre_r"), std::string::npos);
}

TEST(AtlasScalingTest, AnAtlasMissingAMeshIsNamed) {
  ToyLeg leg = toy_leg();
  leg.meshes.erase("tibia_r");
  try {
    (void)prepare_atlas(leg.atlas, leg.meshes);
    FAIL() << "no error";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("tibia_r"), std::string::npos);
  }
}

TEST(AtlasScalingTest, TheReportCarriesResidualsFactorsAndMuscles) {
  const ToyLeg leg = toy_leg();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  const ScaledAtlas scaled = scale_atlas(*prepared, station_landmarks(leg.atlas, similarity()));
  const nlohmann::json report = scaling_report_json(scaled);
  EXPECT_EQ(report["landmark_residual_mm"].size(), 3u);
  EXPECT_EQ(report["bones"].size(), 5u);
  EXPECT_EQ(report["bones"][1]["bone"], "femur_r");
  EXPECT_NEAR(report["bones"][1]["length_factor"].get<double>(), 1.07, 1e-9);
  EXPECT_EQ(report["muscles"][0]["muscle"], "vastus_r");
}

}  // namespace
}  // namespace mmm::scaling
