// Radiographs of a filled limb: a bone inside soft tissue replaces it, so its
// contrast is (mu_bone - mu_soft) times the chord, not mu_bone times it as
// with the soft tissue standing in air.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "core/atlas/patient_radiographs.h"
#include "core/image/png.h"
#include "core/image/projection.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::atlas {
namespace {

mesh::IndexedMesh sphere_at(const Eigen::Vector3d& centre, double radius) {
  return mesh::make_icosphere(5, radius, centre);
}

// The frontal radiograph's value through the world origin.
double value_at_origin(const std::map<std::string, mesh::IndexedMesh>& bones,
                       const std::map<std::string, mesh::IndexedMesh>& soft,
                       const std::filesystem::path& dir, bool filled) {
  PatientRadiographOptions options;
  options.soft_tissue_envelope = filled;
  options.radiograph.quantum_noise = false;
  const auto views = write_patient_radiographs(bones, soft, dir, options);
  const image::GrayImage16 frontal = image::read_png_gray16(dir / "frontal.png");
  const Eigen::Vector2d pixel = image::project(views[0], Eigen::Vector3d::Zero());
  return frontal.at(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()));
}

TEST(FilledLimbRadiographTest, ABoneInSoftTissueShowsItsAttenuationAboveTheTissues) {
  const test::ScratchDir scratch("filled_limb");
  const std::filesystem::path& dir = scratch.path();
  // Two small bones far apart fix the field of view with and without the
  // tested bone; the muscle encloses the tested bone.
  std::map<std::string, mesh::IndexedMesh> bones = {{"low", sphere_at({-50, -50, -120}, 5)},
                                                    {"high", sphere_at({50, 50, 120}, 5)}};
  const std::map<std::string, mesh::IndexedMesh> soft = {{"muscle", sphere_at({0, 0, 0}, 40)}};
  const double tissue_filled = value_at_origin(bones, soft, dir / "a", true);
  const double tissue_in_air = value_at_origin(bones, soft, dir / "b", false);
  bones["bone"] = sphere_at({0, 0, 0}, 10);
  const double bone_filled = value_at_origin(bones, soft, dir / "c", true);
  const double bone_in_air = value_at_origin(bones, soft, dir / "d", false);
  // Counts per unit of attenuation 6000; the chord through the centre 20 mm
  // (the icosphere's, a little less).
  const double per_mm = 6000.0 * 20.0;
  EXPECT_NEAR(bone_filled - tissue_filled,
              (image::kBoneMuPerMm - image::kSoftTissueMuPerMm) * per_mm,
              0.01 * per_mm * image::kBoneMuPerMm);
  EXPECT_NEAR(bone_in_air - tissue_in_air, image::kBoneMuPerMm * per_mm,
              0.01 * per_mm * image::kBoneMuPerMm);
}

}  // namespace
}  // namespace mmm::atlas
