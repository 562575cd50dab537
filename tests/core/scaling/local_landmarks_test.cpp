// Local landmarks (bone_energy.h step 1b, local_field.h) and the
// implausible-stretch warning (atlas_scaling.h).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/scaling/atlas_scaling.h"
#include "core/scaling/local_field.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::scaling {
namespace {

using Eigen::Affine3d;
using Eigen::Vector3d;
using ::testing::HasSubstr;

TEST(LocalFieldTest, MeetsItsPointsAndVanishesBeyondTheRadiusAndAtPins) {
  const Vector3d local(0, 0, 0);
  const Vector3d pin(30, 0, 0);
  const Vector3d far(0, 0, 200);
  const LocalField field = fit_local_field({{local, Vector3d(0, 4, 0), 60.0, {}, {}},
                                            {pin, Vector3d(9, 9, 9), 0.0, {}, {}},
                                            {far, Vector3d(9, 9, 9), 0.0, {}, {}}});
  // The far pin is out of reach: two centres, the local point and the near pin.
  ASSERT_EQ(field.centres.size(), 2U);
  // Interpolation is exact (a 2 x 2 solve): 1e-12 mm.
  EXPECT_LT((field.displacement(local) - Vector3d(0, 4, 0)).norm(), 1e-12);
  EXPECT_LT(field.displacement(pin).norm(), 1e-12);
  EXPECT_EQ(field.displacement(Vector3d(0, 0, -61)), Vector3d::Zero());
  EXPECT_EQ(field.displacement(far), Vector3d::Zero());
  // The gradient agrees with central differences (h = 1e-4 mm: error ~h^2).
  const Vector3d at(10, 5, -7);
  const double h = 1e-4;
  for (int axis = 0; axis < 3; ++axis) {
    const Vector3d step = h * Vector3d::Unit(axis);
    const Vector3d numeric =
        (field.displacement(at + step) - field.displacement(at - step)) / (2 * h);
    EXPECT_LT((field.gradient(at).col(axis) - numeric).norm(), 1e-7);
  }
  EXPECT_TRUE(fit_local_field({{pin, Vector3d::Zero(), 0.0, {}, {}}}).empty());
  EXPECT_THROW(fit_local_field({{local, Vector3d(NAN, 0, 0), 60.0, {}, {}}}), InvalidInputError);
}

// The toy leg with a heel on the talus, tagged local as in the default recipe.
test::ToyLeg leg_with_heel() {
  test::ToyLeg leg = test::toy_leg();
  atlas::Landmark heel;
  heel.name = "heel_r";
  heel.bone = "talus_r";
  heel.position = Vector3d(70, -19, -832);
  heel.tags = {"landmark", "local"};
  leg.atlas.landmarks.push_back(heel);
  for (atlas::Landmark& landmark : leg.atlas.landmarks) {
    if (landmark.name == "lateral_epicondyle_r") landmark.tags = {"landmark", "local"};
  }
  return leg;
}

Affine3d patient_map() {
  Affine3d map = Affine3d::Identity();
  map.linear() = 1.05 * Eigen::AngleAxisd(0.2, Vector3d(0.1, 1, -0.3).normalized()).matrix();
  map.translation() = Vector3d(-30, 20, 880);
  return map;
}

landmarks::LandmarkSet mapped_landmarks(const atlas::Atlas& a, const Affine3d& map,
                                        const std::vector<std::string>& names) {
  landmarks::LandmarkSet set;
  for (const std::string& name : names) {
    set.landmarks.push_back({name, map * a.find_landmark(name)->position, {}, {}});
  }
  return set;
}

const std::vector<std::string> kWithHeel = {"femoral_head_centre_r", "patella_centre_r",
                                            "ankle_centre_r", "heel_r"};

TEST(LocalLandmarksTest, AHeelWhereTheMapPutsItChangesNothingAndWarnsOfNothing) {
  const test::ToyLeg leg = leg_with_heel();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  const ScaledAtlas scaled =
      scale_atlas(*prepared, mapped_landmarks(leg.atlas, patient_map(), kWithHeel));
  EXPECT_TRUE(scaled.warnings.empty());
  EXPECT_TRUE(scaling_report_json(scaled)["warnings"].empty());
  // 1e-6 mm: the closed form, exact up to rounding.
  EXPECT_LT(scaled.landmark_residual_mm.at("heel_r"), 1e-6);
}

TEST(LocalLandmarksTest, AHeel40MmOffIsMetLocallyAndWarnedAbout) {
  const test::ToyLeg leg = leg_with_heel();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  landmarks::LandmarkSet set = mapped_landmarks(leg.atlas, patient_map(), kWithHeel);
  set.landmarks.back().position_mm += patient_map().linear() * Vector3d(0, -40, 0);
  const ScaledAtlas scaled = scale_atlas(*prepared, set);
  // Met through the local field: 0.01 mm, since on the toy's coarse talus
  // (a 642-vertex ellipsoid) the heel's anchor spreads too far to stand for
  // it and the field is fitted at the point itself (local_field.h).
  EXPECT_LT(scaled.landmark_residual_mm.at("heel_r"), 0.01);
  ASSERT_FALSE(scaled.warnings.empty());
  const StretchWarning& warning = scaled.warnings.front();
  EXPECT_EQ(warning.bone, "talus_r");
  EXPECT_EQ(warning.part, "local");
  EXPECT_EQ(warning.direction, "antero-posterior (y)");
  EXPECT_GT(warning.factor, 1.35);
  EXPECT_THAT(warning.message, HasSubstr("talus_r: near its local landmarks is stretched x"));
  const nlohmann::json report = scaling_report_json(scaled);
  EXPECT_EQ(report["warnings"][0]["bone"], "talus_r");
  // The rest of the leg is untouched: femur and tibia as the map puts them
  // (1e-6 mm), the talus's affine part too (the heel is local).
  for (const BoneScaling& bone : scaled.bones) {
    if (bone.bone == "talus_r") {
      EXPECT_EQ(bone.local_points, 1);
      EXPECT_LT((bone.affine.linear() - patient_map().linear()).norm(), 1e-9);
    }
  }
  const Eigen::MatrixX3d& tibia = scaled.meshes.at("tibia_r").at("full").V;
  const Eigen::MatrixX3d& rest = leg.meshes.at("tibia_r").at("full").V;
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    ASSERT_LT((tibia.row(i).transpose() - patient_map() * Vector3d(rest.row(i).transpose())).norm(),
              1e-6);
  }
}

TEST(LocalLandmarksTest, ALocalEpicondyleWidensTheKneeNotTheHip) {
  const test::ToyLeg leg = leg_with_heel();
  const auto prepared = prepare_atlas(leg.atlas, leg.meshes);
  landmarks::LandmarkSet set = mapped_landmarks(
      leg.atlas, patient_map(),
      {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r", "lateral_epicondyle_r"});
  // 4 mm farther out than the map says.
  set.landmarks.back().position_mm += patient_map().linear() * Vector3d(4, 0, 0);
  const ScaledAtlas scaled = scale_atlas(*prepared, set);
  EXPECT_LT(scaled.landmark_residual_mm.at("lateral_epicondyle_r"), 1e-6);
  EXPECT_TRUE(scaled.warnings.empty());
  // The proximal femur (more than 60 mm from the epicondyle) stays where the
  // map puts it; the knee end moves.
  const Eigen::MatrixX3d& femur = scaled.meshes.at("femur_r").at("full").V;
  const Eigen::MatrixX3d& rest = leg.meshes.at("femur_r").at("full").V;
  const Vector3d epicondyle = leg.atlas.find_landmark("lateral_epicondyle_r")->position;
  double far_moved = 0.0;
  double near_moved = 0.0;
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    const Vector3d v = rest.row(i).transpose();
    const double moved = (femur.row(i).transpose() - patient_map() * v).norm();
    double& largest = (v - epicondyle).norm() > 60.0 ? far_moved : near_moved;
    largest = std::max(largest, moved);
  }
  EXPECT_LT(far_moved, 1e-6);
  // The knee centre, 18 mm away, stays put (a pinned joint centre), so the
  // surface beside the epicondyle moves a little less than its 4.2 mm.
  EXPECT_GT(near_moved, 2.0);
}

}  // namespace
}  // namespace mmm::scaling
