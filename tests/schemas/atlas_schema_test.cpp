// schemas/atlas.schema.yaml, the structural contract of atlas.yaml, agrees
// with what core/atlas/atlas_io writes and reads.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "tests/support/test_data.h"
#include "workflow/definition/yaml_schema.h"

namespace mmm::workflow {
namespace {

using ::testing::HasSubstr;

YamlSchema atlas_schema() {
  return YamlSchema::from_file(mmm::test::source_dir() / "schemas/atlas.schema.yaml");
}

std::vector<std::string> violations_of(const std::string& manifest) {
  std::vector<std::string> out;
  for (const SchemaViolation& v : atlas_schema().validate(YAML::Load(manifest))) {
    out.push_back(std::to_string(v.where.line) + ":" + std::to_string(v.where.column) + " " +
                  v.text());
  }
  return out;
}

Eigen::Isometry3d turned(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& origin) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  pose.translation() = origin;
  return pose;
}

// Every kind of element, every function kind, every path point kind and
// every wrap shape (the meshes are not needed to write a manifest).
atlas::Atlas every_kind_of_element() {
  using namespace atlas;  // NOLINT(google-build-using-namespace): test-local brevity
  Atlas a;
  a.name = "schema_test";
  a.description = "every element kind";
  a.frame_description = "x right, y anterior, z superior";
  a.provenance = {"atlas_schema_test"};
  Bone pelvis;
  pelvis.name = "pelvis";
  pelvis.tags = {"bone"};
  pelvis.meshes = {{"full", "meshes/pelvis/full.ply", 12}, {"lod1", "meshes/pelvis/lod1.ply", 0}};
  Bone femur;
  femur.name = "femur_r";
  femur.meshes = {{"full", "meshes/femur_r/full.ply", 320}};
  femur.frame = turned(0.3, {1, 2, 3}, {80, 0, -50});
  femur.parent_joint = "hip_r";
  Bone tibia;
  tibia.name = "tibia_r";
  tibia.parent_joint = "knee_r";
  a.bones = {pelvis, femur, tibia};

  Joint hip;
  hip.name = "hip_r";
  hip.type = JointType::kPin;
  hip.parent = "pelvis";
  hip.child = "femur_r";
  hip.parent_frame = turned(0.1, {0, 0, 1}, {80, 0, -50});
  hip.coordinates = {{"hip_flexion_r", CoordinateKind::kRotational, {-0.5, 2.1}, 0.0, 0.1}};
  Joint knee;
  knee.name = "knee_r";
  knee.type = JointType::kCustom;
  knee.parent = "femur_r";
  knee.child = "tibia_r";
  knee.coordinates = {{"knee_angle_r", CoordinateKind::kRotational, {-2.1, 0.2}, 0.0, 0.0},
                      {"knee_shift_r", CoordinateKind::kTranslational, {-1, 1}, 0.0, 0.0}};
  const opensim::SimmSpline spline({-2.0, 0.0, 2.0}, {-1.0, 0.5, 1.0});
  knee.axes = {
      {true, Eigen::Vector3d::UnitZ(), "knee_angle_r", opensim::LinearFunction{1.0, 0.0}},
      {true, Eigen::Vector3d::UnitX(), "", opensim::Constant{0.0}},
      {true, Eigen::Vector3d::UnitY(), "", opensim::PolynomialFunction{{0.5, 0.0}}},
      {false, Eigen::Vector3d::UnitX(), "knee_angle_r", spline},
      {false, Eigen::Vector3d::UnitY(), "knee_angle_r", opensim::MultiplierFunction(spline, 1.1)},
      {false, Eigen::Vector3d::UnitZ(), "knee_shift_r",
       opensim::PiecewiseLinearFunction({-1.0, 1.0}, {-1.0, 1.0})}};
  a.joints = {hip, knee};

  Muscle muscle;
  muscle.name = "vastus_r";
  muscle.tags = {"right"};
  muscle.meshes = {{"full", "meshes/vastus_r/full.ply", 80}};
  muscle.architecture = FibreArchitecture::kFanned;
  muscle.max_isometric_force_n = 1000;
  WrapObstacle sphere{
      "s", WrapShape::kSphere, "femur_r", turned(0, {1, 0, 0}, {0, 0, 0}), {10, 0, 0}, "all"};
  WrapObstacle cylinder{
      "c", WrapShape::kCylinder, "femur_r", turned(1, {0, 1, 0}, {1, 2, 3}), {10, 0, 40}, "-z"};
  WrapObstacle ellipsoid{
      "e", WrapShape::kEllipsoid, "tibia_r", turned(2, {1, 1, 1}, {4, 5, 6}), {10, 20, 30}, "x"};
  muscle.wrap_obstacles = {sphere, cylinder, ellipsoid};
  ActionLine line;
  line.name = "vastus_r";
  line.wrap_obstacles = {"c", "e"};
  PathPoint origin;
  origin.bone = "femur_r";
  origin.name = "P1";
  PathPoint via;
  via.bone = "femur_r";
  via.kind = PathPointKind::kConditional;
  via.coordinate = "knee_angle_r";
  via.range = {-2.0, -1.0};
  PathPoint insertion;
  insertion.bone = "tibia_r";
  insertion.kind = PathPointKind::kMoving;
  insertion.moving_coordinates = {"knee_angle_r", "", "hip_flexion_r"};
  insertion.moving_functions = {spline, opensim::Constant{3.0}, opensim::LinearFunction{2, 1}};
  line.points = {origin, via, insertion};
  muscle.action_lines = {line};
  muscle.origins = {{"femur_r", {0, 1, 2}, 3.5, {1, 2, 3}}};
  muscle.insertions = {{"tibia_r", {}, 0.0, {0, 0, 0}}};
  a.muscles = {muscle};
  a.landmarks = {{"femoral_head_centre_r", "femur_r", {1, 2, 3}, {"right"}, "head centre"},
                 {"patella_centre_r", "tibia_r", {4, 5, 6}, {}, ""}};
  a.markers = {{"R.ASIS", "pelvis", {7, 8, 9}, true}, {"R.Knee", "femur_r", {1, 1, 1}, false}};
  a.structures = {
      {"acl_r", mmm::atlas::StructureKind::kLigament, {"ligament"}, {}, {"femur_r", "tibia_r"}}};
  a.regions = {{"right_thigh", {"right"}, {"femur_r"}, {"vastus_r"}, {"acl_r"}}};
  return a;
}

std::string written_manifest() {
  const mmm::test::ScratchDir dir("atlas_schema");
  atlas::write_atlas_manifest(every_kind_of_element(), dir.path());
  return mmm::test::read_text(dir / atlas::kManifestFile);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in:\n" << text;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(AtlasSchemaTest, SchemaCompiles) { EXPECT_NO_THROW((void)atlas_schema()); }

TEST(AtlasSchemaTest, WrittenManifestIsValid) {
  const std::string manifest = written_manifest();
  EXPECT_THAT(violations_of(manifest), ::testing::IsEmpty()) << manifest;
}

TEST(AtlasSchemaTest, HandWrittenManifestWithDefaultsIsValid) {
  const std::string manifest = R"(mmm_atlas: 1
name: tiny
bones:
  - {name: pelvis}
  - {name: femur_r, parent_joint: hip_r}
joints:
  - {name: hip_r, type: weld, parent: pelvis, child: femur_r}
muscles:
  - name: psoas_r
    action_lines:
      - name: psoas_r
        points:
          - {bone: pelvis, position: [0, 0, 0]}
          - {bone: femur_r, position: [0, 0, -10], kind: fixed}
)";
  EXPECT_THAT(violations_of(manifest), ::testing::IsEmpty());
}

TEST(AtlasSchemaTest, UnknownKeyIsRejectedAtItsElement) {
  const std::string manifest = replaced(written_manifest(), "  - name: femur_r\n    tags: []",
                                        "  - name: femur_r\n    tagz: []");
  const std::vector<SchemaViolation> violations = atlas_schema().validate(YAML::Load(manifest));
  ASSERT_EQ(violations.size(), 1U) << ::testing::PrintToString(violations_of(manifest));
  EXPECT_EQ(violations[0].path, "bones[1]");
  EXPECT_THAT(violations[0].message, HasSubstr("unknown key 'tagz'; did you mean 'tags'?"));
}

TEST(AtlasSchemaTest, WrongTypeIsRejectedAtItsPath) {
  const std::string manifest = replaced(written_manifest(), "fixed: true", "fixed: yes");
  const std::vector<SchemaViolation> violations = atlas_schema().validate(YAML::Load(manifest));
  ASSERT_EQ(violations.size(), 1U);
  EXPECT_EQ(violations[0].path, "markers[0].fixed");
  EXPECT_THAT(violations[0].message, HasSubstr("expected boolean, got string 'yes'"));
}

TEST(AtlasSchemaTest, StructuralMistakesAreRejected) {
  const std::string manifest = written_manifest();
  // Another format version.
  EXPECT_THAT(violations_of(replaced(manifest, "mmm_atlas: 1", "mmm_atlas: 2")),
              ::testing::ElementsAre(HasSubstr("mmm_atlas: expected 1, got integer 2")));
  // An unknown enum value.
  EXPECT_THAT(violations_of(replaced(manifest, "type: custom", "type: hinge")),
              ::testing::ElementsAre(HasSubstr("joints[1].type: expected one of 'weld', "
                                               "'pin', 'ball', 'custom', got string 'hinge'")));
  // A missing required key of a path point.
  EXPECT_THAT(violations_of(replaced(manifest, "kind: conditional, coordinate: knee_angle_r",
                                     "kind: conditional")),
              ::testing::ElementsAre(HasSubstr("muscles[0].action_lines[0].points[1]: matches "
                                               "none of the 4 alternatives")));
  // A function of an unknown kind.
  EXPECT_THAT(violations_of(replaced(manifest, "kind: constant", "kind: konstant")),
              ::testing::ElementsAre(HasSubstr("joints[1].axes[1].function: matches none of "
                                               "the 6 alternatives")));
  // A negative face index.
  EXPECT_THAT(violations_of(replaced(manifest, "faces: [0, 1, 2]", "faces: [0, -1, 2]")),
              ::testing::ElementsAre(HasSubstr("muscles[0].origins[0].faces[1]: -1 is below "
                                               "the minimum 0")));
}

}  // namespace
}  // namespace mmm::workflow
