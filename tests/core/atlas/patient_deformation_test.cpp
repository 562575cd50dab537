#include "core/atlas/patient_deformation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"

namespace mmm::atlas {
namespace {

Joint joint_between(const std::string& name, const std::string& parent, const std::string& child,
                    const Eigen::Vector3d& centre, JointType type = JointType::kPin) {
  Joint joint;
  joint.name = name;
  joint.type = type;
  joint.parent = parent;
  joint.child = child;
  joint.parent_frame.translation() = centre;
  joint.child_frame.translation() = centre;
  return joint;
}

Bone bone_named(const std::string& name, const std::string& parent_joint) {
  Bone bone;
  bone.name = name;
  bone.parent_joint = parent_joint;
  return bone;
}

PatientOptions seeded(std::uint64_t seed, std::optional<double> height_mm = std::nullopt) {
  PatientOptions options;
  options.seed = seed;
  options.height_mm = height_mm;
  return options;
}

// pelvis (root, origin at 0) -hip (0,0,-50)-> thigh -knee (0,0,-450)-> shank
// -ankle (0,0,-850)-> foot; a kneecap welded to the shank.
Atlas leg() {
  Atlas atlas;
  atlas.bones = {bone_named("pelvis", ""), bone_named("thigh", "hip"), bone_named("shank", "knee"),
                 bone_named("foot", "ankle"), bone_named("kneecap", "patellar")};
  atlas.joints = {joint_between("hip", "pelvis", "thigh", {0, 0, -50}),
                  joint_between("knee", "thigh", "shank", {0, 0, -450}),
                  joint_between("ankle", "shank", "foot", {0, 0, -850}),
                  joint_between("patellar", "shank", "kneecap", {0, 30, -440}, JointType::kWeld)};
  Landmark knee_centre;
  knee_centre.name = "knee_centre";
  knee_centre.bone = "shank";
  knee_centre.position = {0, 0, -450};
  atlas.landmarks.push_back(knee_centre);
  return atlas;
}

TEST(PatientDeformationTest, SegmentsScaleByTheirFactorsAndStayConnected) {
  const Atlas atlas = leg();
  const PatientDeformation deformation = make_patient_deformation(atlas, seeded(7));
  const PatientFactors& f = deformation.factors;
  const auto on = [&](const std::string& bone, const Eigen::Vector3d& p) {
    return deformation.map_on_bone(bone, p);
  };
  const Eigen::Vector3d hip(0, 0, -50);
  const Eigen::Vector3d knee(0, 0, -450);
  const Eigen::Vector3d ankle(0, 0, -850);
  // Joint centres map to the same place from both sides (1e-9 mm: rounding).
  EXPECT_LT((on("pelvis", hip) - on("thigh", hip)).norm(), 1e-9);
  EXPECT_LT((on("thigh", knee) - on("shank", knee)).norm(), 1e-9);
  EXPECT_LT((on("shank", ankle) - on("foot", ankle)).norm(), 1e-9);
  // Segment lengths: 400 mm each, times stature and segment factors.
  EXPECT_NEAR((on("thigh", knee) - on("thigh", hip)).norm(),
              400 * f.stature_scale * f.length.at("thigh"), 1e-9);
  EXPECT_NEAR((on("shank", ankle) - on("shank", knee)).norm(),
              400 * f.stature_scale * f.length.at("shank"), 1e-9);
  // Widths: a point 20 mm off the thigh axis moves to 20 * s * w.
  const Eigen::Vector3d side =
      on("thigh", Eigen::Vector3d(20, 0, -250)) - on("thigh", Eigen::Vector3d(0, 0, -250));
  EXPECT_NEAR(side.norm(), 20 * f.stature_scale * f.width.at("thigh"), 1e-9);
  // The welded kneecap follows the shank.
  EXPECT_TRUE(deformation.bone_maps.at("kneecap").isApprox(deformation.bone_maps.at("shank")));
  // Factors stay within 2.5 sigma of 1.
  for (const auto& [bone, length] : f.length) EXPECT_NEAR(length, 1.0, 2.5 * 0.03 + 1e-12) << bone;
}

TEST(PatientDeformationTest, SameSeedSamePatientAndHeightIsHonoured) {
  const Atlas atlas = leg();
  const PatientDeformation a = make_patient_deformation(atlas, seeded(3));
  const PatientDeformation b = make_patient_deformation(atlas, seeded(3));
  const PatientDeformation c = make_patient_deformation(atlas, seeded(4));
  EXPECT_EQ(a.factors.length, b.factors.length);
  EXPECT_NE(a.factors.length, c.factors.length);
  const PatientDeformation tall = make_patient_deformation(atlas, seeded(3, 1881.0));
  EXPECT_DOUBLE_EQ(tall.factors.stature_scale, 1881.0 / 1710.0);
  EXPECT_THROW(make_patient_deformation(atlas, seeded(3, 400.0)), InvalidInputError);
}

TEST(PatientDeformationTest, DeformedAtlasMovesLandmarksAndJointFrames) {
  const Atlas atlas = leg();
  const PatientDeformation deformation = make_patient_deformation(atlas, seeded(11));
  const Atlas patient = deform_atlas(atlas, deformation);
  const Eigen::Vector3d expected = deformation.map_on_bone("shank", {0, 0, -450});
  EXPECT_LT((patient.find_landmark("knee_centre")->position - expected).norm(), 1e-9);
  EXPECT_LT((patient.find_joint("knee")->child_frame.translation() - expected).norm(), 1e-9);
  // Frames stay rigid (orthonormal rotations).
  const Eigen::Matrix3d r = patient.find_joint("knee")->parent_frame.linear();
  EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
}

TEST(PatientDeformationTest, MuscleBetweenTwoBonesBlendsTheirMaps) {
  const Atlas atlas = leg();
  const PatientDeformation deformation = make_patient_deformation(atlas, seeded(5));
  // A sphere sitting on the thigh's axis far from the shank follows the
  // thigh map almost exactly.
  const mesh::IndexedMesh thigh_bone = mesh::make_box({-10, -10, -440}, {10, 10, -60});
  const mesh::IndexedMesh shank_bone = mesh::make_box({-10, -10, -840}, {10, 10, -460});
  const mesh::IndexedMesh muscle = mesh::make_icosphere(2, 15.0, {25, 0, -150});
  const mesh::IndexedMesh moved =
      deform_muscle_mesh(deformation, {{"thigh", thigh_bone}, {"shank", shank_bone}}, muscle, 10.0);
  const mesh::IndexedMesh by_thigh = deform_bone_mesh(deformation, "thigh", muscle);
  // Within 0.5 mm: the shank's weight there is (d_thigh^2 + 100) / (d_shank^2 + 100)
  // ~ 1e-3 of the thigh's, times a few mm of difference between the maps.
  EXPECT_LT((moved.V - by_thigh.V).rowwise().norm().maxCoeff(), 0.5);
  EXPECT_GT(mesh::signed_volume(moved), 0.0);
}

}  // namespace
}  // namespace mmm::atlas

namespace mmm::atlas {
namespace {

TEST(PatientDeformationTest, FemoralNeckTurnsByItsDrawnAngleAndTheHeadStaysInTheSocket) {
  // The leg with a ball hip (three coordinates): its thigh gets the neck warp.
  Atlas atlas = leg();
  Joint& hip = atlas.joints.front();
  hip.coordinates.resize(3);
  hip.coordinates[0].name = "flexion";
  hip.coordinates[1].name = "adduction";
  hip.coordinates[2].name = "rotation";
  // Only the neck angle varies: the affine maps are then translations.
  PatientOptions options = seeded(11, 1710.0);
  options.segment_length_sd = options.width_sd = options.pelvis_width_sd = 0.0;
  double largest = 0.0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    options.seed = seed;
    const PatientDeformation deformation = make_patient_deformation(atlas, options);
    ASSERT_EQ(deformation.neck.bone, "thigh");
    const double drawn = deformation.factors.neck_angle_deg;
    largest = std::max(largest, std::abs(drawn));
    // Within 2.5 SD of 4 degrees (the draw is clipped there).
    EXPECT_LE(std::abs(drawn), 10.0 + 1e-9);
    const auto on = [&](const std::string& bone, const Eigen::Vector3d& p) {
      return deformation.map_on_bone(bone, p);
    };
    const Eigen::Vector3d head(0, 0, -50);
    const Eigen::Vector3d pivot = head + 45.0 * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d knee(0, 0, -450);
    // The head centre stays where the pelvis puts it; the chain stays joined.
    EXPECT_LT((on("pelvis", head) - on("thigh", head)).norm(), 1e-9);
    EXPECT_LT((on("thigh", knee) - on("shank", knee)).norm(), 1e-9);
    // The neck axis (pivot -> head) turns by the drawn angle about the AP axis
    // relative to the shaft (pivot -> knee); rounding only (1e-9 degrees).
    const auto angle_deg = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
    };
    const double before = angle_deg(head - pivot, knee - pivot);
    const double after =
        angle_deg(on("thigh", head) - on("thigh", pivot), on("thigh", knee) - on("thigh", pivot));
    EXPECT_NEAR(std::abs(after - before), std::abs(drawn), 1e-9) << "seed " << seed;
    // The shaft far from the neck is not bent: only shifted.
    const Eigen::Vector3d shaft_a(0, 0, -200);
    const Eigen::Vector3d shaft_b(10, 0, -300);
    EXPECT_LT(((on("thigh", shaft_a) - on("thigh", shaft_b)) - (shaft_a - shaft_b)).norm(), 1e-9);
  }
  // Five draws of SD 4 degrees: at least one well away from zero.
  EXPECT_GT(largest, 1.0);
}

}  // namespace
}  // namespace mmm::atlas

namespace mmm::atlas {
namespace {

TEST(PatientDeformationTest, LocalShapeKeepsTheJointsAndEveryOtherFactor) {
  const Atlas atlas = leg();
  PatientOptions options = seeded(7);
  const PatientDeformation plain = make_patient_deformation(atlas, options);
  options.local_shape = true;
  const PatientDeformation local = make_patient_deformation(atlas, options);
  // The same proportions: local shape is drawn after everything else.
  EXPECT_EQ(plain.factors.length, local.factors.length);
  EXPECT_EQ(plain.factors.width, local.factors.width);
  EXPECT_DOUBLE_EQ(plain.factors.neck_angle_deg, local.factors.neck_angle_deg);
  ASSERT_FALSE(local.local.empty());
  for (const auto& [bone, warp] : local.local) {
    SCOPED_TRACE(bone);
    EXPECT_TRUE(local.factors.torsion_deg.contains(bone));
    // The joint centres at both ends are on the axis: they do not move.
    const Eigen::Vector3d distal = warp.proximal + warp.length * warp.axis;
    EXPECT_LT((warp.apply(warp.proximal) - warp.proximal).norm(), 1e-9);
    EXPECT_LT((warp.apply(distal) - distal).norm(), 1e-9);
    // Mid-shaft on the axis: moved by the bow alone.
    const Eigen::Vector3d middle = warp.proximal + 0.5 * warp.length * warp.axis;
    EXPECT_LT((warp.apply(middle) - middle - warp.bow).norm(), 1e-9);
  }
}

TEST(PatientDeformationTest, TorsionTurnsTheDistalEndByItsAngle) {
  LocalWarp warp;
  warp.proximal = Eigen::Vector3d::Zero();
  warp.axis = -Eigen::Vector3d::UnitZ();
  warp.length = 400.0;
  warp.torsion_rad = 0.2;
  const Eigen::Vector3d lateral(30.0, 0.0, -400.0);
  const Eigen::Vector3d turned = warp.apply(lateral);
  EXPECT_NEAR(turned.z(), -400.0, 1e-9);
  EXPECT_NEAR(std::atan2(turned.y(), turned.x()), -0.2, 1e-9);  // about -z: clockwise from above
  EXPECT_NEAR(turned.head<2>().norm(), 30.0, 1e-9);
}

}  // namespace
}  // namespace mmm::atlas
