// Outline fitting against analytic cases: an ellipsoid rendered into a
// calibrated biplanar pair, fitted from a sphere of the wrong size in the
// wrong place (centre and radii recovered); a surface that already matches
// stays; pins hold; an operator's correction moves the outline.

#include <gtest/gtest.h>

#include <memory>

#include "core/image/drr.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"
#include "core/outlines/contour_points.h"
#include "core/outlines/edge_image.h"
#include "core/outlines/outline_fit.h"

namespace mmm::outlines {
namespace {

using Eigen::Vector3d;

mesh::IndexedMesh ellipsoid(const Vector3d& centre, const Vector3d& radii, int subdivisions) {
  mesh::IndexedMesh surface = mesh::make_icosphere(subdivisions, 1.0);
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
    surface.V.row(i) = (centre + radii.cwiseProduct(surface.V.row(i).transpose())).transpose();
  }
  return surface;
}

// A noiseless radiograph pair of `truth`: line integrals to 16 bits.
struct Pair {
  std::array<image::RadiographView, 2> views;
  std::vector<image::GrayImage16> images;
  std::vector<std::unique_ptr<EdgeImage>> edges;  // [view][stage sigma 1.0]
};

Pair render(const mesh::IndexedMesh& truth, const Vector3d& isocentre = Vector3d::Zero()) {
  image::BiplanarOptions geometry;
  geometry.isocentre_mm = isocentre;
  geometry.field_width_mm = 120;
  geometry.field_height_mm = 120;
  geometry.detector_pixel_pitch_mm = 0.5;
  Pair pair;
  pair.views = image::make_biplanar_views(geometry);
  const mesh::AabbTree tree(truth);
  const std::vector<image::AttenuatingMesh> meshes = {{&tree, image::kBoneMuPerMm}};
  image::RadiographOptions detector;
  detector.quantum_noise = false;
  for (const image::RadiographView& view : pair.views) {
    pair.images.push_back(image::to_radiograph(image::render_drr(view, meshes), detector));
    pair.edges.push_back(std::make_unique<EdgeImage>(pair.images.back(), 1.0));
  }
  return pair;
}

OutlineFitOptions single_sigma_options() {
  OutlineFitOptions options;
  options.stages = {{1.0, 8.0, 8}, {1.0, 3.0, 8}, {1.0, 1.5, 8}};
  return options;
}

std::vector<FitView> fit_views(const Pair& pair, std::size_t stages) {
  std::vector<FitView> views(2);
  for (std::size_t v = 0; v < 2; ++v) {
    views[v].view = &pair.views[v];
    views[v].edges.assign(stages, pair.edges[v].get());
  }
  return views;
}

// Far from the world origin, as a patient's bones are.
const Vector3d kFar(600, 450, 500);

TEST(OutlineFitTest, AnEllipsoidIsRecoveredFromASphereInTheWrongPlace) {
  const Vector3d centre = kFar + Vector3d(3.0, -2.0, 1.5);
  const Vector3d radii(22.0, 16.0, 30.0);
  const Pair pair = render(ellipsoid(centre, radii, 5), kFar);
  const mesh::IndexedMesh start_full = ellipsoid(kFar, Vector3d(20, 20, 20), 4);
  const mesh::IndexedMesh start_work = ellipsoid(kFar, Vector3d(20, 20, 20), 3);
  BoneOutlineInput input;
  input.bone = "ellipsoid";
  input.full = &start_full;
  input.work = &start_work;
  const OutlineFitOptions options = single_sigma_options();
  const BoneOutlineFit fit =
      fit_bone_outline(input, fit_views(pair, options.stages.size()), options);
  // Centre and radii from the fitted surface's extent along each axis.
  const mesh::IndexedMesh fitted{fit.vertices, start_full.F};
  const Eigen::AlignedBox3d box = mesh::bounding_box(fitted);
  EXPECT_NEAR(box.center().x(), centre.x(), 0.15);
  EXPECT_NEAR(box.center().y(), centre.y(), 0.15);
  EXPECT_NEAR(box.center().z(), centre.z(), 0.15);
  EXPECT_NEAR(box.sizes().x() / 2, radii.x(), 0.2);
  EXPECT_NEAR(box.sizes().y() / 2, radii.y(), 0.2);
  EXPECT_NEAR(box.sizes().z() / 2, radii.z(), 0.2);
  EXPECT_TRUE(fit.converged) << fit.iterations;
  for (const ViewFit& view : fit.views) {
    EXPECT_GT(view.matched, view.contour_points / 2) << view.view;
    EXPECT_LT(view.mean_mm, 0.15) << view.view << " " << view.matched << "/" << view.contour_points
                                  << " " << view.start_mean_mm;
    EXPECT_GT(view.start_mean_mm, 2.0) << view.view;
  }
}

}  // namespace
}  // namespace mmm::outlines
