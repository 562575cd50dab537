// The slot-scanning (EOS-type) projection model beside the pinhole: its
// geometry, back-projection, Jacobian, triangulation and sidecar, and how far
// a pinhole fitted to it is over a full-leg scan.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/image/projection.h"
#include "core/image/view_fit.h"
#include "core/landmarks/triangulation.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

// A full-leg scan: 450 x 1700 mm at the isocentre, as an EOS scan of the
// lower limbs.
std::array<RadiographView, 2> slot_views(const Eigen::Vector3d& isocentre = {10, -20, 900}) {
  BiplanarOptions options;
  options.model = ProjectionModel::kSlotScanning;
  options.isocentre_mm = isocentre;
  options.field_height_mm = 1700.0;
  options.detector_pixel_pitch_mm = 0.5;
  return make_biplanar_views(options);
}

Eigen::Vector3d random_point(std::mt19937& rng, const Eigen::Vector3d& centre,
                             const Eigen::Vector3d& half) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  return centre + Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(half);
}

TEST(SlotScanningTest, RowsAreHeightsAndColumnsAPinholesWithinEachRow) {
  const Eigen::Vector3d iso(10, -20, 900);
  const auto views = slot_views(iso);
  for (const RadiographView& view : views) {
    EXPECT_NO_THROW(validate_view(view));
    EXPECT_EQ(view.model, ProjectionModel::kSlotScanning);
    // The isocentre at the image centre.
    EXPECT_LT((project(view, iso) - Eigen::Vector2d(0.5 * view.width, 0.5 * view.height)).norm(),
              1e-9);
    // Parallel along the scan: the row is the height over the spacing, at
    // any depth and any position across.
    const Eigen::Vector3d near_source = iso + Eigen::Vector3d(150, 120, 600);
    const Eigen::Vector3d far_side = iso + Eigen::Vector3d(-150, -120, 600);
    EXPECT_NEAR(project(view, near_source).y(), project(view, far_side).y(), 1e-9);
    EXPECT_NEAR(project(view, near_source).y(), 0.5 * view.height - 600 / view.pixel_spacing_mm,
                1e-9);
    // Conic across: a point off the isocentre plane is magnified by the
    // ratio of distances from the focal spot at its own height.
    const Eigen::Vector3d source_here = source_for(view, near_source);
    EXPECT_NEAR(source_here.z(), near_source.z(), 1e-9);
    const Eigen::Vector3d beam = (iso - source_for(view, iso)).normalized();
    const double depth = (near_source - source_here).dot(beam);
    EXPECT_NEAR(depth, depth_mm(view, near_source), 1e-9);
    const Eigen::Vector3d across = near_source - source_here - depth * beam;
    const double expected_offset = across.norm() * 1300.0 / depth / view.pixel_spacing_mm;
    EXPECT_NEAR(std::abs(project(view, near_source).x() - 0.5 * view.width), expected_offset, 1e-6);
  }
}

TEST(SlotScanningTest, BackProjectedRayPassesThroughThePointFromItsOwnFocalSpot) {
  const auto views = slot_views();
  std::mt19937 rng(7);
  for (const RadiographView& view : views) {
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d X = random_point(rng, {10, -20, 900}, {200, 200, 800});
      const Ray ray = backproject(view, project(view, X));
      const Eigen::Vector3d offset = X - ray.origin;
      EXPECT_LT((offset - offset.dot(ray.direction) * ray.direction).norm(), 1e-7);
      EXPECT_GT(offset.dot(ray.direction), 0);
      EXPECT_LT((ray.origin - source_for(view, X)).norm(), 1e-7);
    }
  }
}

TEST(SlotScanningTest, JacobianMatchesFiniteDifferences) {
  const auto views = slot_views();
  std::mt19937 rng(11);
  for (const RadiographView& view : views) {
    const Eigen::Vector3d X = random_point(rng, {10, -20, 900}, {150, 150, 700});
    const Eigen::Matrix<double, 2, 3> J = projection_jacobian(view, X);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d h = 1e-4 * Eigen::Vector3d::Unit(k);
      const Eigen::Vector2d numeric = (project(view, X + h) - project(view, X - h)) / 2e-4;
      EXPECT_LT((J.col(k) - numeric).norm(), 1e-6) << view.name << " column " << k;
    }
  }
}

TEST(SlotScanningTest, TriangulationIsExactOnSlotViews) {
  const auto views = slot_views();
  std::mt19937 rng(3);
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d X = random_point(rng, {10, -20, 900}, {200, 200, 800});
    const std::array<Eigen::Vector2d, 2> pixels = {project(views[0], X), project(views[1], X)};
    EXPECT_LT((triangulate_linear(views, pixels) - X).norm(), 1e-7);
    const landmarks::Triangulation refined = landmarks::triangulate(views, pixels);
    EXPECT_LT((refined.point_mm - X).norm(), 1e-7);
    for (const double error : refined.reprojection_error_mm) EXPECT_LT(error, 1e-8);
  }
}

TEST(SlotScanningTest, MixedPairsTriangulateToo) {
  const auto slot = slot_views();
  BiplanarOptions options;
  options.isocentre_mm = {10, -20, 900};
  options.field_height_mm = 1700.0;
  const auto pinhole = make_biplanar_views(options);
  const std::array<RadiographView, 2> mixed = {slot[0], pinhole[1]};
  const Eigen::Vector3d X(60, 40, 1300);
  const std::array<Eigen::Vector2d, 2> pixels = {project(mixed[0], X), project(mixed[1], X)};
  EXPECT_LT((triangulate_linear(mixed, pixels) - X).norm(), 1e-7);
}

TEST(SlotScanningTest, SidecarKeepsTheModel) {
  const auto views = slot_views();
  const std::vector<RadiographFile> files = {{views[0], "frontal.png"}, {views[1], "lateral.png"}};
  const std::string text = view_sidecar_text(files);
  EXPECT_THAT(text, HasSubstr("\"model\": \"slot-scanning\""));
  const std::vector<RadiographFile> back = parse_view_sidecar(text, "views.json");
  ASSERT_EQ(back.size(), 2U);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back[k].view.model, ProjectionModel::kSlotScanning);
    EXPECT_EQ(back[k].view.P, views[k].P);
    EXPECT_EQ(back[k].view.source_mm, views[k].source_mm);
  }
  // A pinhole sidecar does not mention the model (files written before it
  // existed read alike).
  const auto pinhole = make_biplanar_views();
  const std::vector<RadiographFile> plain = {{pinhole[0], "frontal.png"}};
  EXPECT_THAT(view_sidecar_text(plain), ::testing::Not(HasSubstr("model")));
  std::string wrong = text;
  wrong.replace(wrong.find("slot-scanning"), 13, "fan-beam");
  try {
    parse_view_sidecar(wrong, "views.json");
    FAIL() << "an unknown model was accepted";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("views.json"));
    EXPECT_THAT(error.what(), HasSubstr("field 'model'"));
    EXPECT_THAT(error.what(), HasSubstr("slot-scanning"));
  }
}

TEST(SlotScanningTest, PinholeFitRecoversAPinholeExactly) {
  BiplanarOptions options;
  options.isocentre_mm = {10, -20, 900};
  const auto views = make_biplanar_views(options);
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (int i = 0; i < 30; ++i) {
    points.push_back(random_point(rng, options.isocentre_mm, {200, 200, 500}));
    pixels.push_back(project(views[0], points.back()));
  }
  const RadiographView fitted = fit_pinhole_view(points, pixels, "fitted", views[0].width,
                                                 views[0].height, views[0].pixel_spacing_mm);
  EXPECT_LT((fitted.source_mm - views[0].source_mm).norm(), 1e-6);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d X = random_point(rng, options.isocentre_mm, {200, 200, 500});
    EXPECT_LT((project(fitted, X) - project(views[0], X)).norm(), 1e-6);
  }
  const std::vector<Eigen::Vector3d> flat(6, Eigen::Vector3d::Zero());
  EXPECT_THROW(fit_pinhole_view(flat, std::vector<Eigen::Vector2d>(6, Eigen::Vector2d::Zero()),
                                "flat", 10, 10, 1.0),
               InvalidInputError);
}

// The error of the usual approximation: a pinhole fitted (DLT) to an EOS-type
// scan of the whole leg, over the volume the leg fills (200 mm deep and
// across, 1600 mm tall). Its vertical magnification depends on depth, the
// scan's does not, and one centre of projection cannot be conic across and
// parallel along: millimetres off over the whole scan, most at the ends.
// bench/image_bench.cpp prints the same figures.
TEST(SlotScanningTest, APinholeFittedToAFullLegScanIsMillimetresOff) {
  const Eigen::Vector3d iso(0, 0, 900);
  const auto views = slot_views(iso);
  std::vector<Eigen::Vector3d> points;
  for (int i = -4; i <= 4; ++i) {
    for (int j = -4; j <= 4; ++j) {
      for (int k = -8; k <= 8; ++k)
        points.emplace_back(iso + Eigen::Vector3d(25 * i, 25 * j, 100 * k));
    }
  }
  for (const RadiographView& view : views) {
    std::vector<Eigen::Vector2d> pixels;
    pixels.reserve(points.size());
    for (const Eigen::Vector3d& X : points) pixels.push_back(project(view, X));
    const RadiographView pinhole =
        fit_pinhole_view(points, pixels, view.name, view.width, view.height, view.pixel_spacing_mm);
    double worst_end = 0;
    double worst_isocentre_plane = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double error = (project(pinhole, points[i]) - pixels[i]).norm() * view.pixel_spacing_mm;
      if (std::abs(points[i].z() - iso.z()) >= 700) worst_end = std::max(worst_end, error);
      if ((points[i] - iso).head<2>().norm() < 1e-9) {
        worst_isocentre_plane = std::max(worst_isocentre_plane, error);
      }
    }
    EXPECT_GT(worst_end, 2.0) << view.name;
    // On the scan's axis the depth is the isocentre's, and the fit is close.
    EXPECT_LT(worst_isocentre_plane, 1.0) << view.name;
  }
}

}  // namespace
}  // namespace mmm::image
