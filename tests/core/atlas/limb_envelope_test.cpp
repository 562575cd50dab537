// The limb envelope against analytic cases: around a cylinder it is the
// cylinder widened by the fat thickness (volume), closed and outward; it
// contains every point of what it wraps; separate bodies along z give separate
// components; bad options are errors.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/atlas/limb_envelope.h"
#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/primitives.h"
#include "core/mesh/signed_distance.h"

namespace mmm::atlas {
namespace {

TEST(LimbEnvelopeTest, AroundACylinderItIsTheCylinderWidenedByTheFat) {
  constexpr double kRadius = 20.0;
  constexpr double kHeight = 100.0;
  constexpr double kFat = 5.0;
  const mesh::IndexedMesh cylinder = mesh::make_cylinder(kRadius, kHeight, 96);
  LimbEnvelopeOptions options;
  options.fat_mm = kFat;
  const mesh::IndexedMesh envelope = limb_envelope({&cylinder}, options);
  const mesh::MeshCheckReport check = mesh::check_mesh(envelope);
  EXPECT_TRUE(check.closed());
  const double expected = std::numbers::pi * (kRadius + kFat) * (kRadius + kFat) * kHeight;
  EXPECT_NEAR(mesh::signed_volume(envelope), expected, 0.02 * expected);
  const mesh::SignedDistance inside(envelope);
  for (Eigen::Index i = 0; i < cylinder.V.rows(); ++i) {
    const Eigen::Vector3d p = cylinder.V.row(i).transpose();
    // The side lies kFat inside; the caps lie on the envelope's caps.
    EXPECT_LT(inside.at(p), 1e-6) << "vertex " << i;
  }
}

TEST(LimbEnvelopeTest, BodiesApartAlongTheAxisGiveSeparateComponents) {
  const mesh::IndexedMesh low = mesh::make_box({-10, -10, 0}, {10, 10, 30});
  const mesh::IndexedMesh high = mesh::make_box({-10, -10, 60}, {10, 10, 90});
  const mesh::IndexedMesh envelope = limb_envelope({&low, &high});
  const mesh::SignedDistance inside(envelope);
  EXPECT_LT(inside.at(Eigen::Vector3d(0, 0, 15)), 0.0);
  EXPECT_LT(inside.at(Eigen::Vector3d(0, 0, 75)), 0.0);
  EXPECT_GT(inside.at(Eigen::Vector3d(0, 0, 45)), 0.0);  // the gap stays air
  EXPECT_GT(mesh::signed_volume(envelope), 0.0);
}

TEST(LimbEnvelopeTest, BadOptionsAndNoSurfaceAreErrors) {
  const mesh::IndexedMesh box = mesh::make_box({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW((void)limb_envelope({}), InvalidInputError);
  LimbEnvelopeOptions options;
  options.slice_mm = 0;
  EXPECT_THROW((void)limb_envelope({&box}, options), InvalidInputError);
  options = {};
  options.sectors = 4;
  EXPECT_THROW((void)limb_envelope({&box}, options), InvalidInputError);
  options = {};
  options.fat_mm = -1;
  EXPECT_THROW((void)limb_envelope({&box}, options), InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas
