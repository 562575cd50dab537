// A patient made from a bone set: a bone given as a broken surface (holes, as
// in OpenSim's gait2392 pelvis) is rebuilt as the boundary of the solid it
// encloses, so that its radiographs show the bone its truth describes.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/atlas/bone_set_patient.h"
#include "core/image/drr.h"
#include "core/image/png.h"
#include "core/image/projection.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::atlas {
namespace {

using Eigen::Vector3d;

// `surface` without the face each ray enters through: a small hole through
// which the ray sees only the far wall.
mesh::IndexedMesh with_entry_holes(const mesh::IndexedMesh& surface,
                                   const std::vector<image::Ray>& rays) {
  const mesh::AabbTree tree(surface);
  std::vector<int> removed;
  for (const image::Ray& ray : rays) {
    const auto hits = tree.all_hits(ray.origin, ray.direction);
    const auto first = std::ranges::min_element(hits, {}, &mesh::AabbTree::RayHit::t);
    if (first != hits.end()) removed.push_back(first->face);
  }
  mesh::IndexedMesh out{surface.V, Eigen::MatrixX3i(surface.F.rows(), 3)};
  Eigen::Index kept = 0;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    if (std::ranges::find(removed, static_cast<int>(f)) == removed.end()) {
      out.F.row(kept++) = surface.F.row(f);
    }
  }
  out.F.conservativeResize(kept, 3);
  return out;
}

// The frontal radiograph's value where `point` projects, above its value in
// the air of the field's corner.
double frontal_excess_at(const std::filesystem::path& patient, const Vector3d& point) {
  const auto views = image::read_view_sidecar(patient / "radiographs" / "views.json");
  const image::GrayImage16 frontal =
      image::read_png_gray16(patient / "radiographs" / "frontal.png");
  const Eigen::Vector2d pixel = image::project(views.at(0).view, point);
  return static_cast<double>(frontal.at(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()))) -
         frontal.at(1, 1);
}

TEST(BoneSetPatientTest, ABrokenBoneIsRenderedAndMeasuredAsTheSolidItEncloses) {
  const test::ScratchDir dir("bone_set_patient");
  test::write_toy_leg(dir / "toy");
  const test::ToyLeg leg = test::toy_leg();
  const mesh::IndexedMesh& tibia = leg.meshes.at("tibia_r").at("full");
  const Vector3d centre = tibia.V.colwise().mean().transpose();
  // Holes where rays through the shaft's centre along x and y enter it:
  // whichever way a view looks, its ray through the shaft meets one.
  // (Off the axis by a little: the icosphere has vertices on its axes.)
  const Vector3d point = centre + Vector3d(0.7, 1.1, 3.3);
  const std::vector<image::Ray> rays = {{point - Vector3d(100, 0, 0), Vector3d(1, 0, 0)},
                                        {point - Vector3d(0, 100, 0), Vector3d(0, 1, 0)}};
  const mesh::IndexedMesh broken = with_entry_holes(tibia, rays);
  ASSERT_LT(broken.F.rows(), tibia.F.rows());
  ASSERT_FALSE(mesh::check_mesh(broken).watertight());

  PatientRadiographOptions options;
  options.detector_pixel_pitch_mm = 1.0;
  options.soft_tissue_envelope = false;
  options.radiograph.quantum_noise = false;
  BoneSet intact;
  intact.source = "toy leg";
  intact.bones = {{"femur_r", leg.meshes.at("femur_r").at("full")}, {"tibia_r", tibia}};
  BoneSet holed = intact;
  holed.bones["tibia_r"] = broken;

  const BoneSetPatientReport whole = make_bone_set_patient(intact, dir / "toy", dir / "a", options);
  const BoneSetPatientReport repaired =
      make_bone_set_patient(holed, dir / "toy", dir / "b", options);
  EXPECT_TRUE(whole.solidified.empty());
  ASSERT_EQ(repaired.solidified, std::vector<std::string>{"tibia_r"});
  const nlohmann::json truth =
      nlohmann::json::parse(test::read_text(dir / "b" / "ground_truth.json"));
  EXPECT_EQ(truth["solidified"], nlohmann::json::array({"tibia_r"}));

  // The truth written is closed and encloses the intact bone's volume (1 mm
  // grid: within 3 %); the closed femur is written as given.
  const mesh::IndexedMesh written = mesh::read_mesh(dir / "b" / "bones" / "tibia_r.ply");
  EXPECT_TRUE(mesh::check_mesh(written).watertight());
  const double volume = mesh::mass_properties(tibia).volume;
  EXPECT_NEAR(mesh::mass_properties(written).volume, volume, 0.03 * volume);
  EXPECT_EQ(mesh::read_mesh(dir / "b" / "bones" / "femur_r.ply").V.rows(),
            leg.meshes.at("femur_r").at("full").V.rows());

  // Rendered as it is, the broken bone would lose the shaft where the ray
  // meets a hole; the repaired patient's radiograph shows the whole shaft.
  const mesh::AabbTree broken_tree(broken);
  const mesh::AabbTree whole_tree(tibia);
  const std::vector<image::AttenuatingMesh> broken_only = {{&broken_tree, 1.0}};
  const std::vector<image::AttenuatingMesh> whole_only = {{&whole_tree, 1.0}};
  for (const image::Ray& ray : rays) {
    EXPECT_NEAR(image::line_integral(ray, whole_only), 32.0, 1.5);
    EXPECT_LT(image::line_integral(ray, broken_only), 1.0) << ray.direction.transpose();
  }
  const double expected = frontal_excess_at(dir / "a", point);
  EXPECT_GT(expected, 1000.0) << "the shaft shows";
  EXPECT_NEAR(frontal_excess_at(dir / "b", point), expected, 0.05 * expected);
}

}  // namespace
}  // namespace mmm::atlas
