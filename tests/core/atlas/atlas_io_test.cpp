#include "core/atlas/atlas_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/atlas/atlas_check.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::atlas {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

Eigen::Isometry3d pose(const Eigen::Vector3d& origin, double angle, const Eigen::Vector3d& axis) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  frame.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  frame.translation() = origin;
  return frame;
}

// Writes `surface` as binary PLY under dir and returns its level entry.
MeshLevel write_level(const fs::path& dir, const std::string& element, const std::string& level,
                      const mesh::IndexedMesh& surface) {
  const std::string file = "meshes/" + element + "/" + level + ".ply";
  fs::create_directories((dir / file).parent_path());
  mesh::write_mesh(surface, dir / file);
  return {level, file, static_cast<int>(surface.num_faces())};
}

Coordinate coordinate(const std::string& name, std::array<double, 2> range, double rest = 0,
                      CoordinateKind kind = CoordinateKind::kRotational) {
  Coordinate c;
  c.name = name;
  c.kind = kind;
  c.range = range;
  c.rest_value = rest;
  c.default_value = rest / 3;  // some non-representable value
  return c;
}

TransformAxis axis(bool rotation, const Eigen::Vector3d& direction, const std::string& coordinate,
                   opensim::Function function) {
  TransformAxis a;
  a.rotation = rotation;
  a.axis = direction;
  a.coordinate = coordinate;
  a.function = std::move(function);
  return a;
}

PathPoint path_point(const std::string& name, const std::string& bone, const Eigen::Vector3d& p) {
  PathPoint result;
  result.name = name;
  result.bone = bone;
  result.position = p;
  return result;
}

// pelvis (box, root) -hip_r (ball)-> femur_r (icosphere, two levels)
// -knee_r (custom, gait2392-like splines)-> tibia_r (box); one muscle with
// every kind of path point, attachment area and wrap obstacle.
Atlas synthetic_atlas(const fs::path& dir) {
  Atlas atlas;
  atlas.name = "synthetic_leg";
  atlas.description = "test atlas: yes, with 'quotes', \"double quotes\" and a # hash";
  atlas.frame_description = "x right, y anterior, z superior";
  atlas.provenance = {"built by atlas_io_test", "step 2: 0.1 + 0.2", "true", "42"};

  Bone pelvis;
  pelvis.name = "pelvis";
  pelvis.tags = {"bone", "pelvis"};
  pelvis.meshes = {
      write_level(dir, "pelvis", "full", mesh::make_box({-100, -60, -40}, {100, 60, 40}))};
  Bone femur;
  femur.name = "femur_r";
  femur.tags = {"bone", "right", "thigh"};
  femur.meshes = {
      write_level(dir, "femur_r", "full", mesh::make_icosphere(2, 25.0, {80, 0, -250})),
      write_level(dir, "femur_r", "lod1", mesh::make_icosphere(1, 25.0, {80, 0, -250}))};
  femur.frame = pose({80.1, 0.2, -50.3}, 0.1, {0, 0, 1});
  femur.parent_joint = "hip_r";
  Bone tibia;
  tibia.name = "tibia_r";
  tibia.tags = {"bone", "right", "shank"};
  tibia.meshes = {
      write_level(dir, "tibia_r", "full", mesh::make_box({60, -20, -850}, {100, 20, -460}))};
  tibia.frame = pose({80, 0, -450}, -1.0 / 3.0, {1, 2, 3});
  tibia.parent_joint = "knee_r";
  atlas.bones = {pelvis, femur, tibia};

  Joint hip;
  hip.name = "hip_r";
  hip.type = JointType::kBall;
  hip.parent = "pelvis";
  hip.child = "femur_r";
  hip.parent_frame = pose({80.1, 0.2, -50.3}, 0.0, {0, 0, 1});
  hip.child_frame = pose({80.1, 0.2, -50.3}, 0.1, {0, 0, 1});
  hip.coordinates = {coordinate("hip_flexion_r", {-0.5235987755982988, 2.0943951023931953}),
                     coordinate("hip_adduction_r", {-0.8726646259971648, 0.5235987755982988}),
                     coordinate("hip_rotation_r", {-0.6981317007977318, 0.6981317007977318})};
  Joint knee;
  knee.name = "knee_r";
  knee.type = JointType::kCustom;
  knee.parent = "femur_r";
  knee.child = "tibia_r";
  knee.parent_frame = pose({80, 0, -450}, 0.25, {0, 1, 0});
  knee.child_frame = pose({80, 0, -450}, 0.25, {0, 1, 0});
  knee.coordinates = {coordinate("knee_angle_r", {-2.0943951023931953, 0.17453292519943295}, -0.1)};
  const opensim::SimmSpline knee_x(
      {-2.0944, -1.74533, -1.39626, -1.0472, -0.698132, -0.349066, -0.174533, 0.197344, 0.337395,
       0.490178, 1.52146, 2.0944},
      {-3.2, 1.79, 4.11, 4.1, 2.12, -0.01, -1.05, -2.5, -3.16, -3.66, -3.2, -1.0});
  knee.axes = {axis(true, {0, 0, 1}, "knee_angle_r", opensim::LinearFunction{1.0, 0.0}),
               axis(true, {0, 1, 0}, "", opensim::Constant{0.0}),
               axis(true, {1, 0, 0}, "", opensim::Constant{-0.0}),
               axis(false, {1, 0, 0}, "knee_angle_r", knee_x),
               axis(false, {0, 1, 0}, "knee_angle_r",
                    opensim::MultiplierFunction(
                        opensim::SimmSpline({-2.0944, 0.0, 2.0944}, {-422.2, -395.0, -396.9}),
                        1.0471975511965976)),
               axis(false, {0, 0, 1}, "", opensim::Constant{std::numeric_limits<double>::min()})};
  atlas.joints = {hip, knee};

  Muscle vastus;
  vastus.name = "vastus_intermedius_r";
  vastus.tags = {"muscle", "right", "thigh", "quadriceps"};
  vastus.meshes = {write_level(dir, "vastus_intermedius_r", "full",
                               mesh::make_icosphere(1, 10.0, {80, 35, -250}))};
  vastus.architecture = FibreArchitecture::kPennate;
  vastus.max_isometric_force_n = 1365.0;
  vastus.optimal_fibre_length_mm = 87.0;
  vastus.tendon_slack_length_mm = 136.0;
  vastus.pennation_angle_rad = 0.052359877559829883;

  WrapObstacle sphere;
  sphere.name = "knee_sphere";
  sphere.shape = WrapShape::kSphere;
  sphere.bone = "femur_r";
  sphere.pose = pose({80, 10, -440}, 0.0, {1, 0, 0});
  sphere.radii = {25.0, 0.0, 0.0};
  WrapObstacle cylinder;
  cylinder.name = "knee_cylinder";
  cylinder.shape = WrapShape::kCylinder;
  cylinder.bone = "femur_r";
  cylinder.pose = pose({80, 0, -430}, std::numbers::pi / 2, {0, 1, 0});
  cylinder.radii = {24.0, 0.0, 80.0};
  cylinder.quadrant = "+y";
  WrapObstacle ellipsoid;
  ellipsoid.name = "thigh_ellipsoid";
  ellipsoid.shape = WrapShape::kEllipsoid;
  ellipsoid.bone = "tibia_r";
  ellipsoid.pose = pose({80, 5, -500}, 0.7, {1, 1, 0});
  ellipsoid.radii = {30.0, 20.0, 1e-3};
  ellipsoid.quadrant = "-x";
  vastus.wrap_obstacles = {sphere, cylinder, ellipsoid};

  ActionLine line;
  line.name = "vas_int_r";
  line.wrap_obstacles = {"knee_cylinder", "knee_sphere"};
  PathPoint via = path_point("vas_int_r-P3", "femur_r", {80.5, 35.25, -430.125});
  via.kind = PathPointKind::kConditional;
  via.coordinate = "knee_angle_r";
  via.range = {-2.6179938779914944, -1.4199999999999999};
  PathPoint moving = path_point("vas_int_r-P4", "tibia_r", {80.0, 30.0, -460.0});
  moving.kind = PathPointKind::kMoving;
  moving.moving_coordinates = {"knee_angle_r", "knee_angle_r", ""};
  moving.moving_functions = {
      opensim::SimmSpline({-2.0944, -1.0472, 0, 0.174533}, {9.0, 5.5, 3.3, 3.1}),
      opensim::PiecewiseLinearFunction({-2.0944, 0.0, 0.174533}, {-20.0, 0.1, 0.2}),
      opensim::PolynomialFunction{{1.5e-3, -2.0, 7.0}}};
  line.points = {path_point("vas_int_r-P1", "femur_r", {82.0, 29.0, -300.0}),
                 path_point("vas_int_r-P2", "femur_r", {std::sqrt(2.0), 1e-300, -1e20}), via,
                 moving};
  vastus.action_lines = {line};

  AttachmentArea origin;
  origin.bone = "femur_r";
  origin.faces = {0, 1, 2, 7, 319};
  origin.area_mm2 = 123.456;
  origin.centroid = {81.0, 28.5, -301.0};
  AttachmentArea insertion;
  insertion.bone = "tibia_r";
  insertion.faces = {3, 4};
  insertion.area_mm2 = 0.1 + 0.2;
  insertion.centroid = {80.0, 20.0, -461.0};
  vastus.origins = {origin};
  vastus.insertions = {insertion};
  atlas.muscles = {vastus};

  const auto landmark = [](const std::string& name, const std::string& bone,
                           const Eigen::Vector3d& p, std::vector<std::string> tags,
                           const std::string& description) {
    Landmark l;
    l.name = name;
    l.bone = bone;
    l.position = p;
    l.tags = std::move(tags);
    l.description = description;
    return l;
  };
  atlas.landmarks = {
      landmark("femoral_head_centre_r", "femur_r", {80.1, 0.2, -50.3}, {"right", "hip"},
               "centre of the sphere fitted to the femoral head"),
      landmark("patella_centre_r", "tibia_r", {80.0, 40.0, -440.0}, {"right", "knee"}, ""),
      landmark("ankle_centre_r", "tibia_r", {80.0, 0.0, -850.0}, {"right", "ankle"},
               "midpoint of the malleoli: lateral + medial / 2"),
      landmark("asis_r", "pelvis", {95.0, 55.0, 20.0}, {"pelvis", "right"}, "")};

  Marker asis;
  asis.name = "R.ASIS";
  asis.bone = "pelvis";
  asis.position = {95.0, 60.0, 20.0};
  Marker knee_marker;
  knee_marker.name = "R.Knee.Lat";
  knee_marker.bone = "femur_r";
  knee_marker.position = {110.0, 5e-324, -450.0};  // a subnormal survives too
  knee_marker.fixed = true;
  atlas.markers = {asis, knee_marker};

  Region pelvis_region;
  pelvis_region.name = "pelvis";
  pelvis_region.tags = {"trunk"};
  pelvis_region.bones = {"pelvis"};
  Region thigh;
  thigh.name = "right_thigh";
  thigh.tags = {"right", "thigh"};
  thigh.bones = {"femur_r"};
  thigh.muscles = {"vastus_intermedius_r"};
  thigh.structures = {"collateral_ligament_r"};
  atlas.regions = {pelvis_region, thigh};

  Structure ligament;
  ligament.name = "collateral_ligament_r";
  ligament.kind = StructureKind::kLigament;
  ligament.tags = {"ligament", "right"};
  ligament.bones = {"femur_r", "tibia_r"};
  ligament.meshes = {
      write_level(dir, ligament.name, "full", mesh::make_box({100, -2, -480}, {104, 2, -400}))};
  Structure cartilage;
  cartilage.name = "femur_distal_cartilage_r";
  cartilage.kind = StructureKind::kCartilage;
  cartilage.bones = {"femur_r"};
  atlas.structures = {ligament, cartilage};
  return atlas;
}

// ---- exact comparison ------------------------------------------------------

// Bitwise equality for doubles (so 0.0 and -0.0 differ and NaN equals NaN).
void expect_same(double a, double b, const std::string& where) {
  EXPECT_TRUE(std::signbit(a) == std::signbit(b) && (a == b || (std::isnan(a) && std::isnan(b))))
      << where << ": " << a << " vs " << b;
}

template <class Matrix>
void expect_same_matrix(const Matrix& a, const Matrix& b, const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    expect_same(a.data()[i], b.data()[i], where + "[" + std::to_string(i) + "]");
  }
}

void expect_same_function(const opensim::Function& a, const opensim::Function& b,
                          const std::string& where) {
  ASSERT_EQ(a.variant().index(), b.variant().index()) << where;
  const auto same_vectors = [&](const std::vector<double>& x, const std::vector<double>& y,
                                const std::string& what) {
    ASSERT_EQ(x.size(), y.size()) << where << what;
    for (std::size_t i = 0; i < x.size(); ++i) expect_same(x[i], y[i], where + what);
  };
  if (const auto* f = a.get_if<opensim::Constant>()) {
    expect_same(f->value, b.get_if<opensim::Constant>()->value, where + ".value");
  } else if (const auto* g = a.get_if<opensim::LinearFunction>()) {
    expect_same(g->slope, b.get_if<opensim::LinearFunction>()->slope, where + ".slope");
    expect_same(g->intercept, b.get_if<opensim::LinearFunction>()->intercept, where);
  } else if (const auto* p = a.get_if<opensim::PolynomialFunction>()) {
    same_vectors(p->coefficients, b.get_if<opensim::PolynomialFunction>()->coefficients, ".c");
  } else if (const auto* s = a.get_if<opensim::SimmSpline>()) {
    same_vectors(s->x(), b.get_if<opensim::SimmSpline>()->x(), ".x");
    same_vectors(s->y(), b.get_if<opensim::SimmSpline>()->y(), ".y");
  } else if (const auto* l = a.get_if<opensim::PiecewiseLinearFunction>()) {
    same_vectors(l->x(), b.get_if<opensim::PiecewiseLinearFunction>()->x(), ".x");
    same_vectors(l->y(), b.get_if<opensim::PiecewiseLinearFunction>()->y(), ".y");
  } else {
    const auto* m = a.get_if<opensim::MultiplierFunction>();
    const auto* n = b.get_if<opensim::MultiplierFunction>();
    expect_same(m->scale(), n->scale(), where + ".scale");
    expect_same_function(m->function(), n->function(), where + ".function");
  }
}

void expect_same_levels(const std::vector<MeshLevel>& a, const std::vector<MeshLevel>& b,
                        const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].level, b[i].level) << where;
    EXPECT_EQ(a[i].file, b[i].file) << where;
    EXPECT_EQ(a[i].faces, b[i].faces) << where;
  }
}

void expect_same_area(const AttachmentArea& a, const AttachmentArea& b, const std::string& where) {
  EXPECT_EQ(a.bone, b.bone) << where;
  EXPECT_EQ(a.faces, b.faces) << where;
  expect_same(a.area_mm2, b.area_mm2, where + ".area_mm2");
  expect_same_matrix(a.centroid, b.centroid, where + ".centroid");
}

void expect_same_atlas(const Atlas& a, const Atlas& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.frame_description, b.frame_description);
  EXPECT_EQ(a.provenance, b.provenance);
  ASSERT_EQ(a.regions.size(), b.regions.size());
  for (std::size_t i = 0; i < a.regions.size(); ++i) {
    EXPECT_EQ(a.regions[i].name, b.regions[i].name);
    EXPECT_EQ(a.regions[i].tags, b.regions[i].tags);
    EXPECT_EQ(a.regions[i].bones, b.regions[i].bones);
    EXPECT_EQ(a.regions[i].muscles, b.regions[i].muscles);
    EXPECT_EQ(a.regions[i].structures, b.regions[i].structures);
  }
  ASSERT_EQ(a.bones.size(), b.bones.size());
  for (std::size_t i = 0; i < a.bones.size(); ++i) {
    const std::string where = "bones[" + std::to_string(i) + "]";
    EXPECT_EQ(a.bones[i].name, b.bones[i].name);
    EXPECT_EQ(a.bones[i].tags, b.bones[i].tags);
    expect_same_levels(a.bones[i].meshes, b.bones[i].meshes, where);
    expect_same_matrix(a.bones[i].frame.matrix(), b.bones[i].frame.matrix(), where + ".frame");
    EXPECT_EQ(a.bones[i].parent_joint, b.bones[i].parent_joint);
  }
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (std::size_t i = 0; i < a.joints.size(); ++i) {
    const Joint& x = a.joints[i];
    const Joint& y = b.joints[i];
    const std::string where = "joints[" + std::to_string(i) + "]";
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.parent, y.parent);
    EXPECT_EQ(x.child, y.child);
    expect_same_matrix(x.parent_frame.matrix(), y.parent_frame.matrix(), where + ".parent_frame");
    expect_same_matrix(x.child_frame.matrix(), y.child_frame.matrix(), where + ".child_frame");
    ASSERT_EQ(x.coordinates.size(), y.coordinates.size());
    for (std::size_t c = 0; c < x.coordinates.size(); ++c) {
      EXPECT_EQ(x.coordinates[c].name, y.coordinates[c].name);
      EXPECT_EQ(x.coordinates[c].kind, y.coordinates[c].kind);
      expect_same(x.coordinates[c].range[0], y.coordinates[c].range[0], where + ".range");
      expect_same(x.coordinates[c].range[1], y.coordinates[c].range[1], where + ".range");
      expect_same(x.coordinates[c].rest_value, y.coordinates[c].rest_value, where + ".rest");
      expect_same(x.coordinates[c].default_value, y.coordinates[c].default_value, where);
    }
    ASSERT_EQ(x.axes.size(), y.axes.size());
    for (std::size_t k = 0; k < x.axes.size(); ++k) {
      const std::string at = where + ".axes[" + std::to_string(k) + "]";
      EXPECT_EQ(x.axes[k].rotation, y.axes[k].rotation) << at;
      expect_same_matrix(x.axes[k].axis, y.axes[k].axis, at + ".axis");
      EXPECT_EQ(x.axes[k].coordinate, y.axes[k].coordinate) << at;
      expect_same_function(x.axes[k].function, y.axes[k].function, at + ".function");
    }
  }
  ASSERT_EQ(a.muscles.size(), b.muscles.size());
  for (std::size_t i = 0; i < a.muscles.size(); ++i) {
    const Muscle& x = a.muscles[i];
    const Muscle& y = b.muscles[i];
    const std::string where = "muscles[" + std::to_string(i) + "]";
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.tags, y.tags);
    expect_same_levels(x.meshes, y.meshes, where);
    EXPECT_EQ(x.architecture, y.architecture);
    expect_same(x.max_isometric_force_n, y.max_isometric_force_n, where);
    expect_same(x.optimal_fibre_length_mm, y.optimal_fibre_length_mm, where);
    expect_same(x.tendon_slack_length_mm, y.tendon_slack_length_mm, where);
    expect_same(x.pennation_angle_rad, y.pennation_angle_rad, where);
    ASSERT_EQ(x.wrap_obstacles.size(), y.wrap_obstacles.size());
    for (std::size_t w = 0; w < x.wrap_obstacles.size(); ++w) {
      const WrapObstacle& p = x.wrap_obstacles[w];
      const WrapObstacle& q = y.wrap_obstacles[w];
      EXPECT_EQ(p.name, q.name);
      EXPECT_EQ(p.shape, q.shape);
      EXPECT_EQ(p.bone, q.bone);
      expect_same_matrix(p.pose.matrix(), q.pose.matrix(), where + ".wrap.pose");
      expect_same_matrix(p.radii, q.radii, where + ".wrap.radii");
      EXPECT_EQ(p.quadrant, q.quadrant);
    }
    ASSERT_EQ(x.action_lines.size(), y.action_lines.size());
    for (std::size_t l = 0; l < x.action_lines.size(); ++l) {
      const ActionLine& p = x.action_lines[l];
      const ActionLine& q = y.action_lines[l];
      EXPECT_EQ(p.name, q.name);
      EXPECT_EQ(p.wrap_obstacles, q.wrap_obstacles);
      ASSERT_EQ(p.points.size(), q.points.size());
      for (std::size_t k = 0; k < p.points.size(); ++k) {
        const PathPoint& s = p.points[k];
        const PathPoint& t = q.points[k];
        const std::string at = where + ".points[" + std::to_string(k) + "]";
        EXPECT_EQ(s.name, t.name) << at;
        EXPECT_EQ(s.bone, t.bone) << at;
        expect_same_matrix(s.position, t.position, at + ".position");
        EXPECT_EQ(s.kind, t.kind) << at;
        EXPECT_EQ(s.coordinate, t.coordinate) << at;
        expect_same(s.range[0], t.range[0], at + ".range");
        expect_same(s.range[1], t.range[1], at + ".range");
        EXPECT_EQ(s.moving_coordinates, t.moving_coordinates) << at;
        for (std::size_t f = 0; f < 3; ++f) {
          expect_same_function(s.moving_functions[f], t.moving_functions[f], at + ".moving");
        }
      }
    }
    ASSERT_EQ(x.origins.size(), y.origins.size());
    for (std::size_t k = 0; k < x.origins.size(); ++k) {
      expect_same_area(x.origins[k], y.origins[k], where + ".origins");
    }
    ASSERT_EQ(x.insertions.size(), y.insertions.size());
    for (std::size_t k = 0; k < x.insertions.size(); ++k) {
      expect_same_area(x.insertions[k], y.insertions[k], where + ".insertions");
    }
  }
  ASSERT_EQ(a.landmarks.size(), b.landmarks.size());
  for (std::size_t i = 0; i < a.landmarks.size(); ++i) {
    EXPECT_EQ(a.landmarks[i].name, b.landmarks[i].name);
    EXPECT_EQ(a.landmarks[i].bone, b.landmarks[i].bone);
    expect_same_matrix(a.landmarks[i].position, b.landmarks[i].position, "landmarks");
    EXPECT_EQ(a.landmarks[i].tags, b.landmarks[i].tags);
    EXPECT_EQ(a.landmarks[i].description, b.landmarks[i].description);
  }
  ASSERT_EQ(a.structures.size(), b.structures.size());
  for (std::size_t i = 0; i < a.structures.size(); ++i) {
    EXPECT_EQ(a.structures[i].name, b.structures[i].name);
    EXPECT_EQ(a.structures[i].kind, b.structures[i].kind);
    EXPECT_EQ(a.structures[i].tags, b.structures[i].tags);
    EXPECT_EQ(a.structures[i].bones, b.structures[i].bones);
    ASSERT_EQ(a.structures[i].meshes.size(), b.structures[i].meshes.size());
    for (std::size_t k = 0; k < a.structures[i].meshes.size(); ++k) {
      EXPECT_EQ(a.structures[i].meshes[k].file, b.structures[i].meshes[k].file);
      EXPECT_EQ(a.structures[i].meshes[k].faces, b.structures[i].meshes[k].faces);
    }
  }
  ASSERT_EQ(a.markers.size(), b.markers.size());
  for (std::size_t i = 0; i < a.markers.size(); ++i) {
    EXPECT_EQ(a.markers[i].name, b.markers[i].name);
    EXPECT_EQ(a.markers[i].bone, b.markers[i].bone);
    expect_same_matrix(a.markers[i].position, b.markers[i].position, "markers");
    EXPECT_EQ(a.markers[i].fixed, b.markers[i].fixed);
  }
}

// ---- round trip ------------------------------------------------------------

TEST(AtlasIoTest, WriteThenReadReproducesEveryValueExactly) {
  const test::ScratchDir dir("atlas_io_round_trip");
  const Atlas atlas = synthetic_atlas(dir.path());
  write_atlas_manifest(atlas, dir.path());
  ASSERT_TRUE(fs::exists(dir / "atlas.yaml"));
  EXPECT_FALSE(fs::exists(dir / "atlas.yaml.tmp"));
  const Atlas read = read_atlas(dir.path());
  expect_same_atlas(atlas, read);
}

TEST(AtlasIoTest, WritingWhatWasReadGivesTheSameText) {
  const test::ScratchDir dir("atlas_io_idempotent");
  write_atlas_manifest(synthetic_atlas(dir.path()), dir.path());
  const std::string first = test::read_text(dir / "atlas.yaml");
  write_atlas_manifest(read_atlas(dir.path()), dir.path());
  EXPECT_EQ(test::read_text(dir / "atlas.yaml"), first);
}

TEST(AtlasIoTest, ManifestIsReadableYamlInTheDocumentedLayout) {
  const test::ScratchDir dir("atlas_io_layout");
  write_atlas_manifest(synthetic_atlas(dir.path()), dir.path());
  const std::string text = test::read_text(dir / "atlas.yaml");
  EXPECT_THAT(text, HasSubstr("mmm_atlas: 1\n"));
  EXPECT_THAT(text, HasSubstr("- {level: full, file: meshes/femur_r/full.ply, faces: 320}"));
  EXPECT_THAT(text, HasSubstr("frame: {origin: [80.1, 0.2, -50.3], rotation: [["));
  EXPECT_THAT(text, HasSubstr("{kind: multiplier, scale: 1.0471975511965976, function: "
                              "{kind: simm_spline, x: [-2.0944, 0, 2.0944]"));
  EXPECT_THAT(text, HasSubstr("value: -0}"));  // the sign of -0.0 survives
  // Strings YAML would read as something else are quoted.
  EXPECT_THAT(text, HasSubstr("- \"true\"\n"));
  EXPECT_THAT(text, HasSubstr("- \"42\"\n"));
  EXPECT_THAT(text, HasSubstr("quadrant: +y"));
}

TEST(AtlasIoTest, FindByTagAndNameAfterReading) {
  const test::ScratchDir dir("atlas_io_tags");
  write_atlas_manifest(synthetic_atlas(dir.path()), dir.path());
  const Atlas atlas = read_atlas(dir.path());
  // Bones, then muscles, structures, landmarks, regions, each in manifest order.
  EXPECT_EQ(
      atlas.find_by_tag("right"),
      (std::vector<std::string>{"femur_r", "tibia_r", "vastus_intermedius_r",
                                "collateral_ligament_r", "femoral_head_centre_r",
                                "patella_centre_r", "ankle_centre_r", "asis_r", "right_thigh"}));
  EXPECT_EQ(atlas.find_by_tag("quadriceps"), std::vector<std::string>{"vastus_intermedius_r"});
  EXPECT_TRUE(atlas.find_by_tag("left").empty());
  for (const std::string_view name : kRequiredLandmarks) {
    EXPECT_NE(atlas.find_landmark(name), nullptr) << name;
  }
  ASSERT_NE(atlas.find_joint("knee_r"), nullptr);
  EXPECT_EQ(atlas.find_joint("knee_r")->axes.size(), 6U);
  ASSERT_NE(atlas.find_marker("R.Knee.Lat"), nullptr);
  EXPECT_TRUE(atlas.find_marker("R.Knee.Lat")->fixed);
  EXPECT_EQ(atlas.find_region("right_thigh")->muscles,
            std::vector<std::string>{"vastus_intermedius_r"});
  EXPECT_EQ(atlas.find_bone("femr_r"), nullptr);
  ASSERT_NE(atlas.find_structure("collateral_ligament_r"), nullptr);
  EXPECT_EQ(atlas.find_structure("collateral_ligament_r")->kind, StructureKind::kLigament);
  EXPECT_EQ(atlas.find_structure("femur_distal_cartilage_r")->bones,
            std::vector<std::string>{"femur_r"});
}

TEST(AtlasIoTest, ReadFunctionsEvaluateLikeTheOriginals) {
  const test::ScratchDir dir("atlas_io_functions");
  const Atlas atlas = synthetic_atlas(dir.path());
  write_atlas_manifest(atlas, dir.path());
  const Atlas read = read_atlas(dir.path());
  const Joint& a = *atlas.find_joint("knee_r");
  const Joint& b = *read.find_joint("knee_r");
  for (std::size_t k = 0; k < 6; ++k) {
    for (const double q : {-2.5, -1.0, -0.3, 0.0, 0.1, 2.5}) {
      // Same data, same code: the same bits.
      EXPECT_EQ(a.axes[k].function.evaluate(q), b.axes[k].function.evaluate(q)) << k << " " << q;
    }
  }
}

TEST(AtlasIoTest, LoadMeshReadsEachLevel) {
  const test::ScratchDir dir("atlas_io_load_mesh");
  write_atlas_manifest(synthetic_atlas(dir.path()), dir.path());
  const Atlas atlas = read_atlas(dir.path());
  const Bone& femur = *atlas.find_bone("femur_r");
  EXPECT_EQ(load_mesh(dir.path(), femur.meshes).num_faces(), 320);  // 20 * 4^2
  EXPECT_EQ(load_mesh(dir.path(), femur.meshes, "").num_faces(), 320);
  EXPECT_EQ(load_mesh(dir.path(), femur.meshes, "lod1").num_faces(), 80);
  EXPECT_EQ(load_mesh(dir.path(), atlas.find_muscle("vastus_intermedius_r")->meshes).num_faces(),
            80);
}

TEST(AtlasIoTest, LoadMeshNamesTheAvailableLevelsWhenOneIsMissing) {
  const test::ScratchDir dir("atlas_io_missing_level");
  const Atlas atlas = synthetic_atlas(dir.path());
  try {
    (void)load_mesh(dir.path(), atlas.find_bone("femur_r")->meshes, "lod3");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), dir / "atlas.yaml");
    EXPECT_THAT(e.what(), HasSubstr("no mesh level 'lod3' (levels: full, lod1)"));
  }
}

TEST(AtlasIoTest, LoadMeshRejectsAFaceCountThatDisagreesWithTheManifest) {
  const test::ScratchDir dir("atlas_io_face_count");
  std::vector<MeshLevel> levels = synthetic_atlas(dir.path()).find_bone("femur_r")->meshes;
  levels[0].faces = 321;
  EXPECT_THAT([&] { (void)load_mesh(dir.path(), levels); },
              ::testing::ThrowsMessage<IoError>(
                  HasSubstr("has 320 triangles, but the atlas manifest says 321 (level 'full')")));
  levels[0].file = "meshes/nowhere.ply";
  EXPECT_THROW((void)load_mesh(dir.path(), levels), IoError);
}

TEST(AtlasIoTest, AtlasCheckReadsTheWrittenAtlasAndEveryMeshLevel) {
  const test::ScratchDir dir("atlas_io_check");
  write_atlas_manifest(synthetic_atlas(dir.path()), dir.path());
  const AtlasCheckReport report = check_atlas(dir.path());
  // pelvis 1 level, femur_r 2, tibia_r 1, the muscle 1, the ligament 1 (the
  // cartilage has none: a problem of its own, not a mesh).
  ASSERT_EQ(report.meshes.size(), 6U);
  for (const MeshHealth& health : report.meshes) {
    EXPECT_TRUE(health.closed && health.manifold && health.oriented)
        << health.element << " " << health.level;
  }
  for (const std::string& problem : report.problems) {
    EXPECT_THAT(problem, Not(HasSubstr("atlas.yaml"))) << "the manifest must read";
    EXPECT_THAT(problem, Not(HasSubstr("no mesh level")));
  }
}

TEST(AtlasIoTest, MissingManifestIsAnIoErrorNamingTheFile) {
  const test::ScratchDir dir("atlas_io_no_manifest");
  try {
    (void)read_atlas(dir.path());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), dir / "atlas.yaml");
    EXPECT_THAT(e.what(), HasSubstr("atlas.yaml: no such file"));
  }
  EXPECT_THAT([&] { (void)read_atlas(dir / "not_there"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("the atlas folder does not exist")));
}

TEST(AtlasIoTest, WriterRefusesAnInvalidAtlasAndLeavesNoFile) {
  const test::ScratchDir dir("atlas_io_refuse");
  Atlas atlas = synthetic_atlas(dir.path());
  atlas.landmarks[0].bone = "femr_r";
  atlas.bones[1].frame.translation().x() = std::numeric_limits<double>::quiet_NaN();
  try {
    write_atlas_manifest(atlas, dir.path());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not written, the atlas is invalid: 2 problems:"));
    EXPECT_THAT(e.what(), HasSubstr("bones[1].frame.origin[0]: expected a finite number, got "
                                    "'.nan'"));
    EXPECT_THAT(e.what(), HasSubstr("landmarks[0].bone: unknown bone 'femr_r'; did you mean "
                                    "'femur_r'?"));
  }
  EXPECT_FALSE(fs::exists(dir / "atlas.yaml"));
  EXPECT_FALSE(fs::exists(dir / "atlas.yaml.tmp"));
  EXPECT_THROW(write_atlas_manifest(synthetic_atlas(dir.path()), dir / "missing"), IoError);
}

// ---- malformed manifests ---------------------------------------------------

// A small valid manifest; each case below breaks one thing in it.
constexpr const char* kTiny = R"(mmm_atlas: 1
name: tiny
bones:
  - name: pelvis
    tags: [bone]
    meshes: [{level: full, file: meshes/pelvis.ply, faces: 12}]
  - name: femur_r
    parent_joint: hip_r
    frame: {origin: [1, 2, 3], rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}
joints:
  - name: hip_r
    type: ball
    parent: pelvis
    child: femur_r
    coordinates:
      - {name: hip_flexion_r, range: [-1, 2]}
      - {name: hip_adduction_r, range: [-1, 1]}
      - {name: hip_rotation_r, range: [-1, 1]}
muscles:
  - name: psoas_r
    wrap_obstacles:
      - {name: brim, shape: cylinder, bone: pelvis, radii: [10, 0, 50]}
    action_lines:
      - name: psoas_r
        wrap_obstacles: [brim]
        points:
          - {bone: pelvis, position: [0, 0, 0]}
          - {bone: femur_r, position: [0, 0, -10], kind: conditional, coordinate: hip_flexion_r, range: [0, 1]}
          - {bone: femur_r, position: [0, 0, -20]}
    origins:
      - {bone: pelvis, faces: [0, 11]}
landmarks:
  - {name: femoral_head_centre_r, bone: femur_r, position: [0, 0, 0]}
  - {name: asis_r, bone: pelvis, position: [10, 0, 0]}
markers:
  - {name: R.ASIS, bone: pelvis, position: [10, 5, 0], fixed: true}
structures:
  - {name: hip_ligament_r, kind: ligament, bones: [pelvis, femur_r]}
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the manifest";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// what() of read_atlas on `manifest` ("" when it reads).
std::string read_error(const std::string& manifest) {
  const test::ScratchDir dir("atlas_io_malformed");
  test::write_file(dir / "atlas.yaml", manifest);
  try {
    (void)read_atlas(dir.path());
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), dir / "atlas.yaml");
    const std::string what = e.what();
    // Strip the folder, which differs per run.
    return what.substr(what.find("atlas.yaml: ") + std::string("atlas.yaml: ").size());
  }
  return "";
}

TEST(AtlasIoTest, TheTinyManifestReads) {
  EXPECT_EQ(read_error(kTiny), "");
  const test::ScratchDir dir("atlas_io_tiny");
  test::write_file(dir / "atlas.yaml", kTiny);
  const Atlas atlas = read_atlas(dir.path());
  EXPECT_EQ(atlas.bones.size(), 2U);
  EXPECT_EQ(atlas.bones[1].frame.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(atlas.muscles[0].action_lines[0].points[1].kind, PathPointKind::kConditional);
  EXPECT_EQ(atlas.muscles[0].wrap_obstacles[0].quadrant, "all");  // the default
  EXPECT_EQ(atlas.joints[0].coordinates[0].kind, CoordinateKind::kRotational);
}

struct Malformed {
  const char* label;
  const char* from;
  const char* to;
  const char* message;  // the whole message after "atlas.yaml: "
};

class AtlasIoMalformedTest : public ::testing::TestWithParam<Malformed> {};

TEST_P(AtlasIoMalformedTest, IsRejectedWithItsMessage) {
  const Malformed& c = GetParam();
  EXPECT_EQ(read_error(replaced(kTiny, c.from, c.to)), c.message);
}

INSTANTIATE_TEST_SUITE_P(
    AtlasIoTest, AtlasIoMalformedTest,
    ::testing::Values(
        Malformed{"UnknownBoneWithSuggestion", "{bone: femur_r, position: [0, 0, -20]}",
                  "{bone: femr_r, position: [0, 0, -20]}",
                  "line 29, column 20: muscles[0].action_lines[0].points[2].bone: unknown bone "
                  "'femr_r'; did you mean 'femur_r'?"},
        Malformed{"UnknownBoneListsTheBones", "bone: pelvis, position: [10, 5, 0]",
                  "bone: skull, position: [10, 5, 0]",
                  "line 36, column 26: markers[0].bone: unknown bone 'skull' (bones: pelvis, "
                  "femur_r)"},
        Malformed{"DuplicateName", "name: asis_r", "name: femoral_head_centre_r",
                  "line 34, column 12: landmarks[1].name: duplicate landmark name "
                  "'femoral_head_centre_r' (first defined at landmarks[0].name, line 33)"},
        Malformed{"DuplicateCoordinateAcrossTheJoint", "name: hip_rotation_r",
                  "name: hip_flexion_r",
                  "line 18, column 16: joints[0].coordinates[2].name: duplicate coordinate name "
                  "'hip_flexion_r' (first defined at joints[0].coordinates[0].name, line 16)"},
        Malformed{"NotANumber", "position: [10, 0, 0]", "position: [10, .nan, 0]",
                  "line 34, column 49: landmarks[1].position[1]: expected a finite number, got "
                  "'.nan'"},
        Malformed{"Infinity", "faces: 12}", "faces: .inf}",
                  "line 6, column 60: bones[0].meshes[0].faces: expected an integer, got '.inf'"},
        Malformed{"QuotedNumber", "position: [10, 0, 0]", "position: [10, '0', 0]",
                  "line 34, column 49: landmarks[1].position[1]: expected a number, got '0'"},
        Malformed{"BadRotation", "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
                  "[[1, 0, 0], [0, 1, 0], [0, 0.5, 1]]",
                  "line 9, column 42: bones[1].frame.rotation: not a rotation: its rows are not "
                  "orthonormal (R^T R differs from the identity by 0.5, at most 1e-06 allowed)"},
        Malformed{"Reflection", "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
                  "[[1, 0, 0], [0, 1, 0], [0, 0, -1]]",
                  "line 9, column 42: bones[1].frame.rotation: not a rotation: it is a reflection "
                  "(determinant -1)"},
        Malformed{"WrongFormatVersion", "mmm_atlas: 1", "mmm_atlas: 2",
                  "line 1, column 12: mmm_atlas: atlas format version 2 is not supported (this "
                  "program reads version 1)"},
        Malformed{"NoFormatVersion", "mmm_atlas: 1\n", "",
                  "line 1, column 1: top level: missing required key 'mmm_atlas' (the atlas "
                  "format version; this program reads version 1)"},
        Malformed{"MissingRequiredField", "    parent: pelvis\n", "",
                  "line 11, column 5: joints[0]: missing required key 'parent'"},
        Malformed{"UnknownJointType", "type: ball", "type: balll",
                  "line 12, column 11: joints[0].type: unknown joint type 'balll'; did you mean "
                  "'ball'? (expected one of: weld, pin, ball, custom)"},
        Malformed{"CoordinateCountOfTheJointType", "type: ball", "type: pin",
                  "line 16, column 7: joints[0].coordinates: a pin joint has 1 coordinate(s), "
                  "got 3"},
        Malformed{"AxesOnlyForCustomJoints", "    child: femur_r\n",
                  "    child: femur_r\n    axes: []\n",
                  "line 15, column 5: joints[0].axes: only custom joints have axes (this joint "
                  "is ball)"},
        Malformed{"UnknownKeyWithSuggestion", "    tags: [bone]", "    tagz: [bone]",
                  "line 5, column 5: bones[0]: unknown key 'tagz'; did you mean 'tags'? "
                  "(allowed: name, tags, meshes, frame, parent_joint)"},
        Malformed{"UnknownCoordinate", "coordinate: hip_flexion_r", "coordinate: hip_flex_r",
                  "line 28, column 83: muscles[0].action_lines[0].points[1].coordinate: unknown "
                  "coordinate 'hip_flex_r' (coordinates: hip_flexion_r, hip_adduction_r, "
                  "hip_rotation_r)"},
        Malformed{"RangeOnAFixedPoint", "position: [0, 0, -20]}",
                  "position: [0, 0, -20], range: [0, 1]}",
                  "line 29, column 52: muscles[0].action_lines[0].points[2].range: only "
                  "conditional points have a range"},
        Malformed{"EmptyRange", "range: [0, 1]", "range: [1, 0]",
                  "line 28, column 105: muscles[0].action_lines[0].points[1].range: range [1, 0] "
                  "is empty: the minimum comes first"},
        Malformed{"UnknownWrapObstacle", "wrap_obstacles: [brim]", "wrap_obstacles: [brin]",
                  "line 25, column 26: muscles[0].action_lines[0].wrap_obstacles[0]: unknown "
                  "wrap obstacle 'brin'; did you mean 'brim'?"},
        Malformed{"NegativeFaceIndex", "faces: [0, 11]", "faces: [0, -11]",
                  "line 31, column 35: muscles[0].origins[0].faces[1]: face index -11 is "
                  "negative or too large"},
        Malformed{"FaceIndexOutsideTheFullMesh", "faces: [0, 11]", "faces: [0, 12]",
                  "line 31, column 31: muscles[0].origins[0].faces: face index 12 is out of "
                  "range: bone 'pelvis' has 12 faces in its full mesh"},
        Malformed{"UnknownWrapShape", "shape: cylinder", "shape: cone",
                  "line 22, column 29: muscles[0].wrap_obstacles[0].shape: unknown wrap "
                  "obstacle shape 'cone' (expected one of: sphere, cylinder, ellipsoid)"},
        Malformed{"ParentJointOfAnotherBone", "    parent_joint: hip_r\n", "",
                  "line 13, column 12: joints[0].child: bone 'femur_r' has no parent_joint, but "
                  "this joint moves it (set its parent_joint to 'hip_r')"},
        Malformed{"IllTypedField", "fixed: true", "fixed: yes",
                  "line 36, column 63: markers[0].fixed: expected true or false, got 'yes'"},
        Malformed{"AbsoluteMeshPath", "file: meshes/pelvis.ply", "file: /etc/pelvis.ply",
                  "line 6, column 34: bones[0].meshes[0].file: '/etc/pelvis.ply' must be a "
                  "relative path inside the atlas folder (no leading / and no ..)"},
        Malformed{"LigamentWithOneBone", "bones: [pelvis, femur_r]", "bones: [femur_r]",
                  "line 38, column 51: structures[0].bones: a ligament names the two bones it "
                  "joins, [from, to]"},
        Malformed{"StructureNamedLikeABone", "name: hip_ligament_r", "name: femur_r",
                  "line 38, column 12: structures[0].name: 'femur_r' is already the name of a "
                  "bone or muscle"},
        Malformed{"UnknownStructureKind", "kind: ligament", "kind: tendon",
                  "line 38, column 34: structures[0].kind: unknown structure kind 'tendon' "
                  "(expected one of: cartilage, ligament)"},
        Malformed{"StructureOnAnUnknownBone", "bones: [pelvis, femur_r]", "bones: [pelvis, femr_r]",
                  "line 38, column 60: structures[0].bones[1]: unknown bone 'femr_r'; did you "
                  "mean 'femur_r'?"},
        Malformed{"MalformedYaml", "    tags: [bone]\n", "    tags: [bone\n",
                  "line 6, column 11: top level: malformed YAML: end of sequence flow not found"},
        Malformed{"TwoDocuments", "fixed: true}\n", "fixed: true}\n---\nname: other\n",
                  "line 38, column 1: top level: holds 2 YAML documents; an atlas manifest is "
                  "one"}),
    [](const ::testing::TestParamInfo<Malformed>& test_case) {
      return std::string(test_case.param.label);
    });

TEST(AtlasIoTest, EveryProblemIsReportedNotOnlyTheFirst) {
  std::string manifest = replaced(kTiny, "type: ball", "type: hinge");
  manifest = replaced(manifest, "{bone: femur_r, position: [0, 0, -20]}",
                      "{bone: femr_r, position: [0, 0, -20]}");
  manifest = replaced(manifest, "position: [10, 0, 0]", "position: [10, 0, .inf]");
  const std::string error = read_error(manifest);
  EXPECT_THAT(error, ::testing::StartsWith("3 problems:\n  line 12, column 11: joints[0].type: "));
  EXPECT_THAT(error, HasSubstr("\n  line 29, column 20: muscles[0].action_lines[0].points[2].bone: "
                               "unknown bone 'femr_r'"));
  EXPECT_THAT(error, HasSubstr("\n  line 34, column 52: landmarks[1].position[2]: expected a "
                               "finite number, got '.inf'"));
}

TEST(AtlasIoTest, AnEmptyManifestOrOneThatIsNotAMappingIsRejected) {
  EXPECT_THAT(read_error(""), ::testing::StartsWith("top level: the manifest is empty"));
  EXPECT_THAT(read_error("# only a comment\n"),
              ::testing::StartsWith("top level: the manifest is empty"));
  EXPECT_EQ(read_error("- a\n- b\n"),
            "line 1, column 1: top level: expected a mapping, got a list");
}

TEST(AtlasIoTest, ReadAtlasErrorsStandAloneOnOneLine) {
  // atlas_check turns a read_atlas failure into a problem string: the message
  // must stand alone (file, line, element path).
  const std::string error = read_error(replaced(kTiny, "mmm_atlas: 1", "mmm_atlas: 0"));
  EXPECT_THAT(error, HasSubstr("line 1, column 12: mmm_atlas:"));
  EXPECT_THAT(error, Not(HasSubstr("\n")));
}

}  // namespace
}  // namespace mmm::atlas
