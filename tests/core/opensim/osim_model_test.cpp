#include "core/opensim/osim_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::opensim {
namespace {

// Offsets composed from a few products of numbers of order 1.
constexpr double kOffsetRoundOff = 1e-12;

// A small OpenSim 4 model touching every feature the reader extracts.
const std::string kTinyModel = R"(<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
  <Model name="tiny">
    <Ground name="ground"/>
    <gravity>0 -9.81 0</gravity>
    <credits>Nobody</credits>
    <length_units>meters</length_units>
    <BodySet name="bodyset"><objects>
      <Body name="thigh">
        <attached_geometry>
          <Mesh name="thigh_geom"><socket_frame>..</socket_frame><scale_factors>1 2 3</scale_factors><mesh_file>thigh.vtp</mesh_file></Mesh>
        </attached_geometry>
        <WrapObjectSet><objects>
          <WrapCylinder name="cyl"><xyz_body_rotation>0 0.1 0</xyz_body_rotation><translation>0 -0.4 0</translation><quadrant>-y</quadrant><active>true</active><radius>0.05</radius><length>0.2</length></WrapCylinder>
          <WrapSphere name="ball"><radius>0.03</radius></WrapSphere>
          <WrapEllipsoid name="egg"><dimensions>0.1 0.2 0.3</dimensions><active>false</active></WrapEllipsoid>
          <WrapTorus name="ring"><inner_radius>0.01</inner_radius><outer_radius>0.05</outer_radius></WrapTorus>
        </objects></WrapObjectSet>
        <mass>7.5</mass>
        <mass_center>0 -0.2 0</mass_center>
        <inertia>0.1 0.02 0.1 0 0 0.001</inertia>
      </Body>
      <Body name="shank"><mass>3</mass><mass_center>0 -0.2 0</mass_center><inertia>0.05 0.01 0.05 0 0 0</inertia></Body>
    </objects></BodySet>
    <JointSet><objects>
      <PinJoint name="hip">
        <socket_parent_frame>ground_offset</socket_parent_frame>
        <socket_child_frame>/bodyset/thigh</socket_child_frame>
        <coordinates>
          <Coordinate name="hip_flexion"><default_value>0.2</default_value><range>-1 2</range><clamped>true</clamped><locked>false</locked></Coordinate>
        </coordinates>
        <frames>
          <PhysicalOffsetFrame name="ground_offset"><socket_parent>/ground</socket_parent><translation>0 1 0</translation><orientation>0 0 0.5</orientation></PhysicalOffsetFrame>
          <PhysicalOffsetFrame name="rotated_child"><socket_parent>ground_offset</socket_parent><translation>1 0 0</translation><orientation>0.3 0 0</orientation></PhysicalOffsetFrame>
        </frames>
      </PinJoint>
      <CustomJoint name="knee">
        <socket_parent_frame>thigh_offset</socket_parent_frame>
        <socket_child_frame>shank</socket_child_frame>
        <coordinates><Coordinate name="knee_angle"><range>-2 0.2</range></Coordinate></coordinates>
        <frames>
          <PhysicalOffsetFrame name="thigh_offset"><socket_parent>knee_base</socket_parent><translation>0 -0.1 0</translation><orientation>0 0 0</orientation></PhysicalOffsetFrame>
          <PhysicalOffsetFrame name="knee_base"><socket_parent>/bodyset/thigh</socket_parent><translation>0 -0.3 0</translation><orientation>0 0 0</orientation></PhysicalOffsetFrame>
        </frames>
        <SpatialTransform>
          <TransformAxis name="rotation1"><coordinates>knee_angle</coordinates><axis>0 0 1</axis><LinearFunction name="function"><coefficients>1 0</coefficients></LinearFunction></TransformAxis>
          <TransformAxis name="rotation2"><coordinates></coordinates><axis>0 1 0</axis><Constant name="function"><value>0</value></Constant></TransformAxis>
          <TransformAxis name="rotation3"><coordinates></coordinates><axis>1 0 0</axis><Constant name="function"><value>0</value></Constant></TransformAxis>
          <TransformAxis name="translation1"><coordinates>knee_angle</coordinates><axis>1 0 0</axis><SimmSpline name="function"><x>-2 -1 0 0.2</x><y>0.01 0.005 0 -0.001</y></SimmSpline></TransformAxis>
          <TransformAxis name="translation2"><coordinates>knee_angle</coordinates><axis>0 1 0</axis><MultiplierFunction name="function"><function><PiecewiseLinearFunction><x>-2 0.2</x><y>-0.01 0</y></PiecewiseLinearFunction></function><scale>2</scale></MultiplierFunction></TransformAxis>
          <TransformAxis name="translation3"><coordinates></coordinates><axis>0 0 1</axis><PolynomialFunction name="function"><coefficients>0 0.001</coefficients></PolynomialFunction></TransformAxis>
        </SpatialTransform>
      </CustomJoint>
    </objects></JointSet>
    <ForceSet><objects>
      <Thelen2003Muscle name="vasti">
        <appliesForce>true</appliesForce>
        <GeometryPath name="geometrypath">
          <PathPointSet><objects>
            <PathPoint name="vasti-P1"><socket_parent_frame>/bodyset/thigh</socket_parent_frame><location>0.01 -0.1 0.02</location></PathPoint>
            <ConditionalPathPoint name="vasti-P2"><socket_parent_frame>/bodyset/thigh</socket_parent_frame><location>0.03 -0.38 0</location><socket_coordinate>/jointset/knee/knee_angle</socket_coordinate><range>-2 -1</range></ConditionalPathPoint>
            <MovingPathPoint name="vasti-P3"><socket_parent_frame>/bodyset/shank</socket_parent_frame>
              <socket_x_coordinate>/jointset/knee/knee_angle</socket_x_coordinate>
              <socket_y_coordinate>/jointset/knee/knee_angle</socket_y_coordinate>
              <socket_z_coordinate>/jointset/knee/knee_angle</socket_z_coordinate>
              <x_location><SimmSpline><x>-2 0</x><y>0.02 0.04</y></SimmSpline></x_location>
              <y_location><Constant><value>0.03</value></Constant></y_location>
              <z_location><LinearFunction><coefficients>0.01 0.002</coefficients></LinearFunction></z_location>
            </MovingPathPoint>
          </objects></PathPointSet>
          <PathWrapSet><objects><PathWrap name="w1"><wrap_object>cyl</wrap_object><method>midpoint</method><range>1 2</range></PathWrap></objects></PathWrapSet>
        </GeometryPath>
        <max_isometric_force>1000</max_isometric_force>
        <optimal_fiber_length>0.09</optimal_fiber_length>
        <tendon_slack_length>0.2</tendon_slack_length>
        <pennation_angle_at_optimal>0.05</pennation_angle_at_optimal>
      </Thelen2003Muscle>
      <CoordinateActuator name="not_a_path"><coordinate>hip_flexion</coordinate></CoordinateActuator>
    </objects></ForceSet>
    <MarkerSet><objects>
      <Marker name="KNEE"><socket_parent_frame>/bodyset/thigh</socket_parent_frame><location>0 -0.4 0.05</location><fixed>true</fixed></Marker>
      <Marker name="ROT"><socket_parent_frame>/jointset/hip/rotated_child</socket_parent_frame><location>0 1 0</location></Marker>
    </objects></MarkerSet>
  </Model>
</OpenSimDocument>
)";

// The same kind of model in the OpenSim 3.x layout (joint inside the child body).
const std::string kOldModel = R"(<?xml version="1.0" encoding="UTF-8"?>
<OpenSimDocument Version="30000">
  <Model name="old">
    <BodySet><objects>
      <Body name="ground"><mass>0</mass><Joint/></Body>
      <Body name="femur">
        <mass>9</mass><mass_center>0 -0.17 0</mass_center>
        <inertia_xx>0.1</inertia_xx><inertia_yy>0.03</inertia_yy><inertia_zz>0.1</inertia_zz>
        <inertia_xy>0</inertia_xy><inertia_xz>0</inertia_xz><inertia_yz>0.002</inertia_yz>
        <Joint>
          <CustomJoint name="hip">
            <parent_body>ground</parent_body>
            <location_in_parent>0 0.9 0</location_in_parent>
            <orientation_in_parent>0 0 0</orientation_in_parent>
            <location>0 0.01 0</location>
            <orientation>0 0 0</orientation>
            <CoordinateSet><objects>
              <Coordinate name="hip_flexion"><motion_type>rotational</motion_type><default_value>0.1</default_value><range>-2 2</range></Coordinate>
            </objects></CoordinateSet>
            <SpatialTransform>
              <TransformAxis name="rotation1"><function><LinearFunction><coefficients>1 0</coefficients></LinearFunction></function><coordinates>hip_flexion</coordinates><axis>0 0 1</axis></TransformAxis>
              <TransformAxis name="rotation2"><function><Constant><value>0</value></Constant></function><coordinates></coordinates><axis>0 1 0</axis></TransformAxis>
              <TransformAxis name="rotation3"><function><Constant><value>0</value></Constant></function><coordinates></coordinates><axis>1 0 0</axis></TransformAxis>
              <TransformAxis name="translation1"><function><Constant><value>0</value></Constant></function><coordinates></coordinates><axis>1 0 0</axis></TransformAxis>
              <TransformAxis name="translation2"><function><Constant><value>0</value></Constant></function><coordinates></coordinates><axis>0 1 0</axis></TransformAxis>
              <TransformAxis name="translation3"><function><Constant><value>0</value></Constant></function><coordinates></coordinates><axis>0 0 1</axis></TransformAxis>
            </SpatialTransform>
          </CustomJoint>
        </Joint>
        <VisibleObject>
          <GeometrySet><objects><DisplayGeometry><geometry_file>femur.vtp</geometry_file><scale_factors>1 1 2</scale_factors></DisplayGeometry></objects></GeometrySet>
          <scale_factors>1.1 1.1 1.1</scale_factors>
        </VisibleObject>
        <WrapObjectSet><objects><WrapSphere name="head"><radius>0.025</radius></WrapSphere></objects></WrapObjectSet>
      </Body>
    </objects></BodySet>
    <ForceSet><objects>
      <Thelen2003Muscle name="m">
        <isDisabled>true</isDisabled>
        <GeometryPath><PathPointSet><objects>
          <PathPoint name="p1"><location>0 0.9 0</location><body>ground</body></PathPoint>
          <ConditionalPathPoint name="p2"><location>0 -0.05 0</location><body>femur</body><coordinate>hip_flexion</coordinate><range>0 1</range></ConditionalPathPoint>
          <PathPoint name="p3"><location>0 -0.1 0</location><body>femur</body></PathPoint>
        </objects></PathPointSet></GeometryPath>
        <max_isometric_force>100</max_isometric_force>
        <pennation_angle>0.1</pennation_angle>
      </Thelen2003Muscle>
    </objects></ForceSet>
    <MarkerSet><objects><Marker name="M1"><body>femur</body><location>0 -0.2 0</location><fixed>false</fixed></Marker></objects></MarkerSet>
  </Model>
</OpenSimDocument>
)";

// kTinyModel with the first occurrence of `from` replaced by `to`.
std::string tiny_with(std::string_view from, std::string_view to) {
  std::string xml = kTinyModel;
  const std::size_t at = xml.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the model";
  if (at != std::string::npos) xml.replace(at, from.size(), to);
  return xml;
}

// 1-based line of the first occurrence of `needle`.
int line_of(std::string_view xml, std::string_view needle) {
  const std::size_t at = xml.find(needle);
  return 1 + static_cast<int>(
                 std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

// parse_osim(xml) must throw IoError whose message holds every fragment.
void expect_io_error(const std::string& xml, std::initializer_list<std::string> fragments) {
  try {
    parse_osim(xml, "bad.osim");
    ADD_FAILURE() << "expected IoError";
  } catch (const IoError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("bad.osim: ", 0), 0U) << message;
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "missing '" << fragment << "' in: " << message;
    }
  }
}

TEST(OsimModelTest, ReadsModelPropertiesAndBodies) {
  const OsimModel model = parse_osim(kTinyModel, "tiny.osim");
  EXPECT_EQ(model.source, "tiny.osim");
  EXPECT_EQ(model.version, 40000);
  EXPECT_EQ(model.name, "tiny");
  EXPECT_EQ(model.credits, "Nobody");
  EXPECT_EQ(model.length_units, "meters");
  EXPECT_EQ(model.gravity, Eigen::Vector3d(0, -9.81, 0));
  ASSERT_EQ(model.bodies.size(), 3U);
  EXPECT_TRUE(model.bodies[0].is_ground);
  EXPECT_EQ(model.bodies[0].name, "ground");

  const Body* thigh = model.find_body("thigh");
  ASSERT_NE(thigh, nullptr);
  EXPECT_FALSE(thigh->is_ground);
  EXPECT_EQ(thigh->mass, 7.5);
  EXPECT_EQ(thigh->mass_center, Eigen::Vector3d(0, -0.2, 0));
  EXPECT_EQ(thigh->inertia, (std::array<double, 6>{0.1, 0.02, 0.1, 0, 0, 0.001}));
  ASSERT_EQ(thigh->geometry.size(), 1U);
  EXPECT_EQ(thigh->geometry[0].mesh_file, "thigh.vtp");
  EXPECT_EQ(thigh->geometry[0].scale_factors, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(thigh->geometry[0].frame, "thigh");

  ASSERT_EQ(thigh->wrap_objects.size(), 4U);
  const WrapObject& cylinder = thigh->wrap_objects[0];
  EXPECT_EQ(cylinder.shape, WrapShape::kCylinder);
  EXPECT_EQ(cylinder.body, "thigh");
  EXPECT_EQ(cylinder.radius, 0.05);
  EXPECT_EQ(cylinder.length, 0.2);
  EXPECT_EQ(cylinder.quadrant, "-y");
  EXPECT_EQ(cylinder.xyz_body_rotation, Eigen::Vector3d(0, 0.1, 0));
  EXPECT_EQ(cylinder.translation, Eigen::Vector3d(0, -0.4, 0));
  EXPECT_EQ(thigh->wrap_objects[1].shape, WrapShape::kSphere);
  EXPECT_EQ(thigh->wrap_objects[1].radius, 0.03);
  EXPECT_EQ(thigh->wrap_objects[1].quadrant, "all");
  EXPECT_EQ(thigh->wrap_objects[2].shape, WrapShape::kEllipsoid);
  EXPECT_EQ(thigh->wrap_objects[2].dimensions, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_FALSE(thigh->wrap_objects[2].active);
  EXPECT_EQ(thigh->wrap_objects[3].shape, WrapShape::kTorus);
  EXPECT_EQ(thigh->wrap_objects[3].outer_radius, 0.05);
  EXPECT_EQ(model.find_wrap_object("ring"), &thigh->wrap_objects[3]);
  EXPECT_EQ(model.find_body("nope"), nullptr);
}

TEST(OsimModelTest, ResolvesOffsetFramesAndCoordinates) {
  const OsimModel model = parse_osim(kTinyModel, "tiny.osim");
  ASSERT_EQ(model.joints.size(), 2U);
  const Joint* hip = model.find_joint("hip");
  ASSERT_NE(hip, nullptr);
  EXPECT_EQ(hip->type, "PinJoint");
  EXPECT_EQ(hip->parent.name, "ground_offset");
  EXPECT_EQ(hip->parent.body, "ground");
  EXPECT_EQ(hip->parent.translation, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(hip->parent.orientation, Eigen::Vector3d(0, 0, 0.5));
  EXPECT_EQ(hip->child.body, "thigh");
  EXPECT_TRUE(hip->spatial_transform.empty());

  const Coordinate* flexion = model.find_coordinate("hip_flexion");
  ASSERT_NE(flexion, nullptr);
  EXPECT_EQ(flexion->joint, "hip");
  EXPECT_EQ(flexion->default_value, 0.2);
  EXPECT_EQ(flexion->range, (std::array<double, 2>{-1, 2}));
  EXPECT_TRUE(flexion->clamped);
  EXPECT_FALSE(flexion->locked);
  EXPECT_EQ(flexion->motion_type, MotionType::kRotational);

  // knee parent: thigh_offset -> knee_base -> thigh, translations add up.
  const Joint* knee = model.find_joint("knee");
  ASSERT_NE(knee, nullptr);
  EXPECT_EQ(knee->parent.body, "thigh");
  EXPECT_NEAR((knee->parent.translation - Eigen::Vector3d(0, -0.4, 0)).norm(), 0.0,
              kOffsetRoundOff);
  EXPECT_EQ(knee->child.body, "shank");
  EXPECT_EQ(model.find_coordinate("knee_angle")->motion_type, MotionType::kRotational);
  EXPECT_EQ(model.find_coordinate("knee_angle")->range, (std::array<double, 2>{-2, 0.2}));
  EXPECT_EQ(model.find_coordinate("missing"), nullptr);

  // A frame offset from a rotated frame: origin at t1 + R1 t2, rotation R1 R2.
  const Marker* marker = model.find_marker("ROT");
  ASSERT_NE(marker, nullptr);
  EXPECT_EQ(marker->frame.body, "ground");
  const Eigen::Matrix3d r1 = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d r2 = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).matrix();
  EXPECT_NEAR(
      (marker->frame.translation - Eigen::Vector3d(std::cos(0.5), 1 + std::sin(0.5), 0)).norm(),
      0.0, kOffsetRoundOff);
  EXPECT_NEAR((marker->frame.rotation() - r1 * r2).norm(), 0.0, kOffsetRoundOff);
  EXPECT_NEAR((marker->frame.to_body(marker->location) -
               (marker->frame.translation + r1 * r2 * Eigen::Vector3d(0, 1, 0)))
                  .norm(),
              0.0, kOffsetRoundOff);
}

TEST(OsimModelTest, ReadsCustomJointSpatialTransform) {
  const OsimModel model = parse_osim(kTinyModel, "tiny.osim");
  const Joint* knee = model.find_joint("knee");
  ASSERT_NE(knee, nullptr);
  ASSERT_EQ(knee->spatial_transform.size(), 6U);
  const TransformAxis& rotation1 = knee->spatial_transform[0];
  EXPECT_EQ(rotation1.name, "rotation1");
  EXPECT_EQ(rotation1.coordinates, std::vector<std::string>{"knee_angle"});
  EXPECT_EQ(rotation1.axis, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(rotation1.function.type_name(), "LinearFunction");
  EXPECT_TRUE(knee->spatial_transform[1].coordinates.empty());
  const TransformAxis& translation1 = knee->spatial_transform[3];
  EXPECT_EQ(translation1.function.type_name(), "SimmSpline");
  EXPECT_EQ(translation1.function.evaluate(-1.0), 0.005);  // a knot: exact
  const TransformAxis& translation2 = knee->spatial_transform[4];
  EXPECT_EQ(translation2.function.type_name(), "MultiplierFunction");
  EXPECT_DOUBLE_EQ(translation2.function.evaluate(-2.0), -0.02);  // 2 x -0.01
  EXPECT_DOUBLE_EQ(knee->spatial_transform[5].function.evaluate(7.0), 0.001);
}

TEST(OsimModelTest, ReadsMusclePathAndMarkers) {
  const OsimModel model = parse_osim(kTinyModel, "tiny.osim");
  ASSERT_EQ(model.muscles.size(), 1U);  // the CoordinateActuator has no path
  const Muscle* vasti = model.find_muscle("vasti");
  ASSERT_NE(vasti, nullptr);
  EXPECT_EQ(vasti->type, "Thelen2003Muscle");
  EXPECT_TRUE(vasti->applies_force);
  EXPECT_TRUE(vasti->has_muscle_parameters);
  EXPECT_EQ(vasti->max_isometric_force, 1000.0);
  EXPECT_EQ(vasti->optimal_fiber_length, 0.09);
  EXPECT_EQ(vasti->tendon_slack_length, 0.2);
  EXPECT_EQ(vasti->pennation_angle_at_optimal, 0.05);
  ASSERT_EQ(vasti->path_points.size(), 3U);
  const PathPoint& origin = vasti->path_points[0];
  EXPECT_EQ(origin.kind, PathPointKind::kPathPoint);
  EXPECT_EQ(origin.frame.body, "thigh");
  EXPECT_EQ(origin.location, Eigen::Vector3d(0.01, -0.1, 0.02));
  const PathPoint& conditional = vasti->path_points[1];
  EXPECT_EQ(conditional.kind, PathPointKind::kConditional);
  EXPECT_EQ(conditional.coordinate, "knee_angle");
  EXPECT_EQ(conditional.range, (std::array<double, 2>{-2, -1}));
  const PathPoint& moving = vasti->path_points[2];
  EXPECT_EQ(moving.kind, PathPointKind::kMoving);
  EXPECT_EQ(moving.frame.body, "shank");
  EXPECT_EQ(moving.x_coordinate, "knee_angle");
  EXPECT_EQ(moving.z_coordinate, "knee_angle");
  EXPECT_DOUBLE_EQ(moving.x_location.evaluate(-1.0), 0.03);
  // Location at the default knee angle 0: (0.04, 0.03, 0.002).
  EXPECT_NEAR((moving.location - Eigen::Vector3d(0.04, 0.03, 0.002)).norm(), 0.0, kOffsetRoundOff);
  ASSERT_EQ(vasti->path_wraps.size(), 1U);
  EXPECT_EQ(vasti->path_wraps[0].wrap_object, "cyl");
  EXPECT_EQ(vasti->path_wraps[0].method, "midpoint");
  EXPECT_EQ(vasti->path_wraps[0].range, (std::array<int, 2>{1, 2}));

  ASSERT_EQ(model.markers.size(), 2U);
  const Marker* knee = model.find_marker("KNEE");
  ASSERT_NE(knee, nullptr);
  EXPECT_EQ(knee->frame.body, "thigh");
  EXPECT_EQ(knee->frame.name, "thigh");
  EXPECT_EQ(knee->location, Eigen::Vector3d(0, -0.4, 0.05));
  EXPECT_TRUE(knee->fixed);
  EXPECT_EQ(model.find_muscle("not_a_path"), nullptr);
}

TEST(OsimModelTest, ReadsOpenSim3Layout) {
  const OsimModel model = parse_osim(kOldModel, "old.osim");
  EXPECT_EQ(model.version, 30000);
  ASSERT_EQ(model.bodies.size(), 2U);
  EXPECT_TRUE(model.bodies[0].is_ground);
  const Body* femur = model.find_body("femur");
  ASSERT_NE(femur, nullptr);
  EXPECT_EQ(femur->inertia, (std::array<double, 6>{0.1, 0.03, 0.1, 0, 0, 0.002}));
  ASSERT_EQ(femur->geometry.size(), 1U);
  EXPECT_EQ(femur->geometry[0].mesh_file, "femur.vtp");
  // VisibleObject scale times DisplayGeometry scale.
  EXPECT_NEAR((femur->geometry[0].scale_factors - Eigen::Vector3d(1.1, 1.1, 2.2)).norm(), 0.0,
              kOffsetRoundOff);
  ASSERT_EQ(femur->wrap_objects.size(), 1U);
  EXPECT_EQ(femur->wrap_objects[0].radius, 0.025);

  ASSERT_EQ(model.joints.size(), 1U);
  const Joint& hip = model.joints[0];
  EXPECT_EQ(hip.name, "hip");
  EXPECT_EQ(hip.parent.body, "ground");
  EXPECT_EQ(hip.parent.translation, Eigen::Vector3d(0, 0.9, 0));
  EXPECT_EQ(hip.child.body, "femur");
  EXPECT_EQ(hip.child.translation, Eigen::Vector3d(0, 0.01, 0));
  ASSERT_EQ(hip.spatial_transform.size(), 6U);
  EXPECT_EQ(hip.spatial_transform[0].function.type_name(), "LinearFunction");
  const Coordinate* flexion = model.find_coordinate("hip_flexion");
  ASSERT_NE(flexion, nullptr);
  EXPECT_EQ(flexion->motion_type, MotionType::kRotational);
  EXPECT_EQ(flexion->default_value, 0.1);

  ASSERT_EQ(model.muscles.size(), 1U);
  EXPECT_FALSE(model.muscles[0].applies_force);  // isDisabled true
  EXPECT_EQ(model.muscles[0].pennation_angle_at_optimal, 0.1);
  ASSERT_EQ(model.muscles[0].path_points.size(), 3U);
  EXPECT_EQ(model.muscles[0].path_points[0].frame.body, "ground");
  EXPECT_EQ(model.muscles[0].path_points[1].coordinate, "hip_flexion");
  ASSERT_EQ(model.markers.size(), 1U);
  EXPECT_EQ(model.markers[0].frame.body, "femur");
}

// ---------------------------------------------------------------- errors

TEST(OsimModelErrorTest, MissingFile) {
  try {
    read_osim("/nonexistent/model.osim");
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("no such file"), std::string::npos) << error.what();
  }
}

TEST(OsimModelErrorTest, MalformedXmlReportsTinyxmlLine) {
  const std::string xml =
      "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<Model>\n"
      "<BodySet>\n</Model>\n</OpenSimDocument>\n";
  // tinyxml2 reports the mismatch at the line of the element left open (<BodySet>).
  expect_io_error(xml, {"malformed XML", "line 4", "BodySet"});
}

TEST(OsimModelErrorTest, NotAnOpenSimDocumentOrNoModel) {
  expect_io_error("<VTKFile type=\"PolyData\"/>", {"<VTKFile", "expected <OpenSimDocument>"});
  expect_io_error("<OpenSimDocument Version=\"40000\">\n  <MarkerSet/>\n</OpenSimDocument>",
                  {"line 1", "has no <Model>"});
}

TEST(OsimModelErrorTest, OldOrMissingVersion) {
  expect_io_error(R"(<OpenSimDocument Version="20302"><Model/></OpenSimDocument>)",
                  {"Version 20302", "2.x", "save it"});
  expect_io_error(R"(<OpenSimDocument><Model/></OpenSimDocument>)", {"no Version attribute"});
  expect_io_error(R"(<OpenSimDocument Version="4.0"><Model/></OpenSimDocument>)",
                  {"not an integer"});
}

TEST(OsimModelErrorTest, PathPointOnUnknownBody) {
  const std::string xml =
      tiny_with("<socket_parent_frame>/bodyset/thigh</socket_parent_frame><location>0.01",
                "<socket_parent_frame>/bodyset/thighh</socket_parent_frame><location>0.01");
  expect_io_error(xml, {"line " + std::to_string(line_of(xml, "/bodyset/thighh")),
                        "PathPoint name=\"vasti-P1\"", "thighh", "bodies are: ground thigh shank"});
}

TEST(OsimModelErrorTest, NonNumericAndNonFiniteVectors) {
  std::string xml =
      tiny_with("<mass_center>0 -0.2 0</mass_center>", "<mass_center>0 abc 0</mass_center>");
  expect_io_error(
      xml, {"line " + std::to_string(line_of(xml, "abc")), "<mass_center> of <Body name=\"thigh\">",
            "value 2 is 'abc', not a number"});
  xml = tiny_with("<location>0.01 -0.1 0.02</location>", "<location>nan -0.1 0.02</location>");
  expect_io_error(xml, {"line " + std::to_string(line_of(xml, "nan -0.1")),
                        "<location> of <PathPoint", "finite"});
}

TEST(OsimModelErrorTest, VectorWithWrongCount) {
  std::string xml =
      tiny_with("<inertia>0.1 0.02 0.1 0 0 0.001</inertia>", "<inertia>0.1 0.02 0.1 0 0</inertia>");
  expect_io_error(xml, {"holds 5 values, expected 6", "Ixx Iyy Izz Ixy Ixz Iyz"});
  xml = tiny_with("<location>0.01 -0.1 0.02</location>", "<location>0.01 -0.1</location>");
  expect_io_error(xml, {"holds 2 values, expected 3 (x y z)"});
}

TEST(OsimModelErrorTest, BadSimmSplines) {
  std::string xml = tiny_with("<x>-2 -1 0 0.2</x>", "<x>-2 -1 0</x>");
  expect_io_error(xml, {"line " + std::to_string(line_of(xml, "<SimmSpline name=\"function\">")),
                        "SimmSpline", "3 x values but 4 y values"});
  xml = tiny_with("<x>-2 -1 0 0.2</x>", "<x>-2 0 -1 0.2</x>");
  expect_io_error(xml, {"strictly increase", "x[2]"});
}

TEST(OsimModelErrorTest, UnknownFunctionType) {
  const std::string xml = tiny_with(R"(<Constant name="function"><value>0</value></Constant>)",
                                    R"(<Sine name="function"><amplitude>1</amplitude></Sine>)");
  expect_io_error(xml, {"'Sine' is not supported", "SimmSpline"});
}

TEST(OsimModelErrorTest, UnknownReferences) {
  expect_io_error(tiny_with("<socket_coordinate>/jointset/knee/knee_angle<",
                            "<socket_coordinate>/jointset/knee/knee_angel<"),
                  {"knee_angel", "no joint of the model defines"});
  expect_io_error(tiny_with("<wrap_object>cyl<", "<wrap_object>cylinder<"),
                  {"'cylinder'", "WrapObjectSet"});
  expect_io_error(
      tiny_with("<socket_parent_frame>thigh_offset<", "<socket_parent_frame>thigh_ofset<"),
      {"thigh_ofset", "neither a body nor a PhysicalOffsetFrame"});
  expect_io_error(tiny_with("<socket_parent>/bodyset/thigh</socket_parent>",
                            "<socket_parent>thigh_offset</socket_parent>"),
                  {"cycle"});
}

TEST(OsimModelErrorTest, BadBooleanAndDuplicates) {
  expect_io_error(
      tiny_with("<clamped>true</clamped>", "<clamped>yes</clamped>"),
      {"'yes', expected true or false", "<clamped> of <Coordinate name=\"hip_flexion\">"});
  expect_io_error(tiny_with("<Body name=\"shank\">", "<Body name=\"thigh\">"),
                  {"'thigh' is used twice"});
}

// ---------------------------------------------------------------- real data

std::filesystem::path subject01() {
  return test::data_dir() / "gait2392" / "Pipelines" / "reference" / "subject01_simbody.osim";
}

TEST(OsimModelRealDataTest, Gait2392BodiesJointsAndHeader) {
  const OsimModel model = read_osim(test::gait2392_model());
  EXPECT_EQ(model.version, 40000);
  EXPECT_EQ(model.name, "3DGaitModel2392");
  EXPECT_NE(model.credits.find("Delp"), std::string::npos);
  EXPECT_NE(model.publications.find("Yamaguchi"), std::string::npos);
  EXPECT_EQ(model.length_units, "meters");
  EXPECT_EQ(model.gravity, Eigen::Vector3d(0, -9.8066499999999994, 0));
  // README: 12 bodies; the ground comes on top as bodies[0].
  ASSERT_EQ(model.bodies.size(), 13U);
  EXPECT_TRUE(model.bodies[0].is_ground);
  for (const char* name : {"ground", "pelvis", "femur_r", "tibia_r", "talus_r", "calcn_r", "toes_r",
                           "femur_l", "tibia_l", "talus_l", "calcn_l", "toes_l", "torso"}) {
    EXPECT_NE(model.find_body(name), nullptr) << name;
  }
  const Body* pelvis = model.find_body("pelvis");
  EXPECT_EQ(pelvis->mass, 11.776999999999999);
  ASSERT_EQ(pelvis->geometry.size(), 3U);
  EXPECT_EQ(pelvis->geometry[1].mesh_file, "pelvis.vtp");
  const Body* femur = model.find_body("femur_r");
  ASSERT_EQ(femur->geometry.size(), 1U);
  EXPECT_EQ(femur->geometry[0].mesh_file, "femur_r.vtp");
  EXPECT_EQ(femur->geometry[0].scale_factors, Eigen::Vector3d::Ones());
  EXPECT_TRUE(std::filesystem::exists(test::gait2392_model().parent_path() / "Geometry" /
                                      femur->geometry[0].mesh_file));

  EXPECT_EQ(model.joints.size(), 12U);
  std::size_t coordinates = 0;
  std::size_t rotational = 0;
  for (const Joint& joint : model.joints) {
    for (const Coordinate& coordinate : joint.coordinates) {
      ++coordinates;
      rotational += coordinate.motion_type == MotionType::kRotational ? 1 : 0;
      EXPECT_EQ(coordinate.joint, joint.name);
    }
  }
  EXPECT_EQ(coordinates, 23U);  // "3D, 23 DOF gait model" (credits)
  EXPECT_EQ(rotational, 20U);   // all but pelvis_tx, pelvis_ty, pelvis_tz
  const Joint* hip = model.find_joint("hip_r");
  ASSERT_NE(hip, nullptr);
  EXPECT_EQ(hip->parent.body, "pelvis");
  EXPECT_EQ(hip->parent.translation,
            Eigen::Vector3d(-0.070699999999999999, -0.066100000000000006, 0.083500000000000005));
  EXPECT_EQ(hip->child.body, "femur_r");
  EXPECT_EQ(model.find_joint("ground_pelvis")->parent.body, "ground");
  EXPECT_EQ(model.find_coordinate("pelvis_tx")->motion_type, MotionType::kTranslational);
  EXPECT_EQ(model.find_coordinate("hip_flexion_r")->motion_type, MotionType::kRotational);
  // The generic model carries no markers (they come from the scale setup's marker set).
  EXPECT_TRUE(model.markers.empty());
}

TEST(OsimModelRealDataTest, Gait2392KneeHasCoupledTranslationSplines) {
  const OsimModel model = read_osim(test::gait2392_model());
  const Joint* knee = model.find_joint("knee_r");
  ASSERT_NE(knee, nullptr);
  EXPECT_EQ(knee->type, "CustomJoint");
  EXPECT_EQ(knee->parent.name, "femur_r_offset");
  EXPECT_EQ(knee->parent.body, "femur_r");
  EXPECT_EQ(knee->child.body, "tibia_r");
  ASSERT_EQ(knee->coordinates.size(), 1U);
  const Coordinate& angle = knee->coordinates[0];
  EXPECT_EQ(angle.name, "knee_angle_r");
  EXPECT_EQ(angle.motion_type, MotionType::kRotational);
  EXPECT_EQ(angle.range, (std::array<double, 2>{-2.0943950999999998, 0.17453293}));
  ASSERT_EQ(knee->spatial_transform.size(), 6U);
  EXPECT_EQ(knee->spatial_transform[0].function.type_name(), "LinearFunction");
  for (const std::size_t a : {3U, 4U}) {
    const TransformAxis& axis = knee->spatial_transform[a];
    EXPECT_EQ(axis.coordinates, std::vector<std::string>{"knee_angle_r"});
    EXPECT_NE(axis.function.get_if<SimmSpline>(), nullptr) << axis.name;
  }
  EXPECT_EQ(knee->spatial_transform[3].function.get_if<SimmSpline>()->x().size(), 12U);
  EXPECT_EQ(knee->spatial_transform[4].function.get_if<SimmSpline>()->x().size(), 7U);
  // Value between knots cross-checked in opensim_function_test (exact rational solve).
  EXPECT_NEAR(knee->spatial_transform[4].function.evaluate(0.0), -0.39582069644835033, 1e-12);
  EXPECT_EQ(knee->spatial_transform[3].function.evaluate(-0.349066), -0.001);  // a knot
}

TEST(OsimModelRealDataTest, Gait2392Muscles) {
  const OsimModel model = read_osim(test::gait2392_model());
  ASSERT_EQ(model.muscles.size(), 92U);
  std::size_t points = 0;
  std::size_t conditional = 0;
  std::size_t moving = 0;
  for (const Muscle& muscle : model.muscles) {
    EXPECT_EQ(muscle.type, "Thelen2003Muscle");
    EXPECT_TRUE(muscle.has_muscle_parameters);
    for (const PathPoint& point : muscle.path_points) {
      ++points;
      conditional += point.kind == PathPointKind::kConditional ? 1 : 0;
      moving += point.kind == PathPointKind::kMoving ? 1 : 0;
      EXPECT_NE(model.find_body(point.frame.body), nullptr);
    }
  }
  EXPECT_EQ(points, 288U + 26U + 8U);  // element counts grepped from the file
  EXPECT_EQ(conditional, 26U);
  EXPECT_EQ(moving, 8U);

  const Muscle* glut = model.find_muscle("glut_med1_r");
  ASSERT_NE(glut, nullptr);
  EXPECT_EQ(glut->max_isometric_force, 819.0);
  EXPECT_EQ(glut->optimal_fiber_length, 0.053499999999999999);
  EXPECT_EQ(glut->tendon_slack_length, 0.078);
  EXPECT_EQ(glut->pennation_angle_at_optimal, 0.13962633999999999);
  ASSERT_EQ(glut->path_points.size(), 2U);
  EXPECT_EQ(glut->path_points[0].name, "glut_med1_r-P1");
  EXPECT_EQ(glut->path_points[0].frame.body, "pelvis");
  EXPECT_EQ(glut->path_points[0].location,
            Eigen::Vector3d(-0.040800000000000003, 0.0304, 0.12089999999999999));
  EXPECT_EQ(glut->path_points[1].frame.body, "femur_r");
  EXPECT_EQ(glut->path_points[1].location, Eigen::Vector3d(-0.0218, -0.0117, 0.055500000000000001));

  const Muscle* semimem = model.find_muscle("semimem_r");
  ASSERT_NE(semimem, nullptr);
  const PathPoint& p2 = semimem->path_points[1];
  EXPECT_EQ(p2.kind, PathPointKind::kConditional);
  EXPECT_EQ(p2.coordinate, "knee_angle_r");
  EXPECT_EQ(p2.range, (std::array<double, 2>{-0.55850500000000003, 0.17453299999999999}));

  const Muscle* rect_fem = model.find_muscle("rect_fem_r");
  ASSERT_NE(rect_fem, nullptr);
  const PathPoint& p3 = rect_fem->path_points.back();
  EXPECT_EQ(p3.kind, PathPointKind::kMoving);
  EXPECT_EQ(p3.frame.body, "tibia_r");
  EXPECT_EQ(p3.x_coordinate, "knee_angle_r");
  // Knot values at knee_angle_r = 0 (the default): x 0.0617576, y 0.020984, z 0.0014.
  EXPECT_EQ(p3.x_location.evaluate(0.0), 0.0617576);
  EXPECT_EQ(p3.location.y(), 0.020984);
  EXPECT_NEAR(p3.location.z(), 0.0014, 1e-15);  // a flat 2-point spline: 0.0014 + 0 * slope
}

TEST(OsimModelRealDataTest, Subject01LoadsWithScaledGeometryAndMarkers) {
  const OsimModel model = read_osim(subject01());
  EXPECT_EQ(model.name, "subject01");
  EXPECT_EQ(model.bodies.size(), 13U);
  EXPECT_EQ(model.muscles.size(), 92U);
  EXPECT_EQ(model.markers.size(), 39U);
  const Marker* sternum = model.find_marker("Sternum");
  ASSERT_NE(sternum, nullptr);
  EXPECT_EQ(sternum->frame.body, "torso");
  EXPECT_EQ(sternum->location,
            Eigen::Vector3d(0.12048792, 0.30716102000000001, -0.0032541499999999999));
  EXPECT_FALSE(sternum->fixed);

  const Body* femur = model.find_body("femur_r");
  ASSERT_NE(femur, nullptr);
  ASSERT_EQ(femur->geometry.size(), 1U);
  EXPECT_EQ(femur->geometry[0].scale_factors, Eigen::Vector3d::Constant(1.14724));
  int scaled_meshes = 0;
  for (const Body& body : model.bodies) {
    for (const AttachedMesh& mesh : body.geometry) {
      scaled_meshes += mesh.scale_factors != Eigen::Vector3d::Ones() ? 1 : 0;
    }
  }
  EXPECT_GT(scaled_meshes, 10);

  // Scaled model: moving-point functions wrapped in MultiplierFunctions.
  const PathPoint& p3 = model.find_muscle("rect_fem_r")->path_points.back();
  const auto* multiplier = p3.x_location.get_if<MultiplierFunction>();
  ASSERT_NE(multiplier, nullptr);
  EXPECT_EQ(multiplier->scale(), 0.98852300000000004);
  EXPECT_DOUBLE_EQ(p3.x_location.evaluate(0.0), 0.98852300000000004 * 0.0617576);
  EXPECT_EQ(model.find_muscle("glut_med1_r")->path_points[0].location,
            Eigen::Vector3d(-0.041802739999999998, 0.03114714, 0.12387136));
  // The scaled pelvis translations stay translational (MultiplierFunction of scale 1).
  EXPECT_EQ(model.find_coordinate("pelvis_tx")->motion_type, MotionType::kTranslational);
}

}  // namespace
}  // namespace mmm::opensim
