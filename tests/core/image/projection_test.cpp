#include "core/image/projection.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using Json = nlohmann::json;

constexpr double kSid = 1300.0;
constexpr double kSdd = 1700.0;
constexpr double kPitch = 0.3;
constexpr double kSpacing = kPitch * kSid / kSdd;  // at the isocentre

Eigen::Vector3d uniform_in_box(std::mt19937& rng, const Eigen::Vector3d& half_size,
                               const Eigen::Vector3d& centre) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  return centre + Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(half_size);
}

// A view of the same system turned by `angle` about the vertical axis through
// the isocentre: it sees X as the original view sees R (X - iso) + iso.
RadiographView turned_view(const RadiographView& view, const Eigen::Vector3d& iso, double angle,
                           const std::string& name) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = iso - R * iso;
  RadiographView turned = view;
  turned.name = name;
  turned.P = view.P * T;
  turned.source_mm = R.transpose() * (view.source_mm - iso) + iso;
  return turned;
}

TEST(ProjectionTest, BiplanarViewsHaveTheDocumentedGeometry) {
  const auto views = make_biplanar_views();
  const RadiographView& frontal = views[0];
  const RadiographView& lateral = views[1];
  EXPECT_EQ(frontal.name, "frontal");
  EXPECT_EQ(lateral.name, "lateral");
  for (const RadiographView& view : views) {
    EXPECT_NO_THROW(validate_view(view));
    // Exact formula, evaluated the same way up to one rounding.
    EXPECT_NEAR(view.pixel_spacing_mm, kSpacing, 1e-15);
    EXPECT_EQ(view.width, static_cast<int>(std::round(450.0 / kSpacing)));
    EXPECT_EQ(view.height, static_cast<int>(std::round(1100.0 / kSpacing)));
    // The isocentre lands on the image centre: coordinates of a few thousand
    // pixels are exact to ~1e-12.
    const Eigen::Vector2d centre = project(view, Eigen::Vector3d::Zero());
    EXPECT_NEAR(centre.x(), 0.5 * view.width, 1e-9);
    EXPECT_NEAR(centre.y(), 0.5 * view.height, 1e-9);
  }
  // AP frontal: the source is anterior; the lateral source is on the right.
  EXPECT_TRUE(frontal.source_mm.isApprox(Eigen::Vector3d(0, kSid, 0)));
  EXPECT_TRUE(lateral.source_mm.isApprox(Eigen::Vector3d(kSid, 0, 0)));
}

TEST(ProjectionTest, FrontalViewShowsTheSubjectsRightOnTheImageLeft) {
  const auto views = make_biplanar_views();
  const RadiographView& frontal = views[0];
  const RadiographView& lateral = views[1];
  const double cu = 0.5 * frontal.width;
  const double cv = 0.5 * frontal.height;
  // u grows toward the subject's left (-x); v grows downward (-z).
  EXPECT_LT(project(frontal, {100, 0, 0}).x(), cu);
  EXPECT_GT(project(frontal, {-100, 0, 0}).x(), cu);
  EXPECT_LT(project(frontal, {0, 0, 100}).y(), cv);
  // Lateral: anterior (+y) on the image right, superior up.
  EXPECT_GT(project(lateral, {0, 100, 0}).x(), cu);
  EXPECT_LT(project(lateral, {0, 0, 100}).y(), cv);
  // In the isocentre plane a displacement of d mm moves the image by
  // d / spacing pixels (exact in a pinhole model; 1e-9 px is rounding).
  EXPECT_NEAR(project(frontal, {-45, 0, 0}).x() - cu, 45 / kSpacing, 1e-9);
  EXPECT_NEAR(project(lateral, {0, 45, -10}).x() - cu, 45 / kSpacing, 1e-9);
  EXPECT_NEAR(project(lateral, {0, 45, -10}).y() - cv, 10 / kSpacing, 1e-9);
  // Nearer the source the image is magnified: the frontal source is anterior.
  EXPECT_GT(cu - project(frontal, {45, 200, 0}).x(), cu - project(frontal, {45, -200, 0}).x());
}

TEST(ProjectionTest, ImageCentreBackProjectsOntoTheIsocentreRay) {
  BiplanarOptions options;
  options.isocentre_mm = {12, -30, 950};  // a field centred on the knees
  for (const RadiographView& view : make_biplanar_views(options)) {
    const Ray ray = backproject(view, {0.5 * view.width, 0.5 * view.height});
    EXPECT_TRUE(ray.origin.isApprox(view.source_mm));
    // Unit direction toward the detector, passing through the isocentre
    // (distance from the line: rounding of 1000 mm coordinates, ~1e-12 mm).
    EXPECT_NEAR(ray.direction.norm(), 1.0, 1e-15);
    const Eigen::Vector3d to_iso = options.isocentre_mm - ray.origin;
    EXPECT_LT(to_iso.cross(ray.direction).norm(), 1e-9);
    EXPECT_NEAR(to_iso.dot(ray.direction), kSid, 1e-9);
    // Any point of any back-projected ray projects back onto its pixel.
    const Eigen::Vector2d pixel(123.5, 4000.25);
    const Ray other = backproject(view, pixel);
    const Eigen::Vector2d back = project(view, other.origin + 1500 * other.direction);
    EXPECT_LT((back - pixel).norm(), 1e-9);  // pixels: rounding only
  }
}

TEST(ProjectionTest, TriangulationRecoversKnownPoints) {
  BiplanarOptions options;
  options.isocentre_mm = {5, 20, 800};
  const auto views = make_biplanar_views(options);
  std::mt19937 rng(11);
  for (int i = 0; i < 200; ++i) {
    // Anywhere in the imaged volume: 450 x 450 x 1100 mm around the isocentre.
    const Eigen::Vector3d X = uniform_in_box(rng, {200, 200, 520}, options.isocentre_mm);
    const std::vector<Eigen::Vector2d> pixels = {project(views[0], X), project(views[1], X)};
    const Eigen::Vector3d back = triangulate_linear(views, pixels);
    // Noise-free data: the error is rounding in a least-squares solve with
    // coordinates of ~1000 mm and condition ~1e3, far below 1e-6 mm.
    EXPECT_LT((back - X).norm(), 1e-6) << "point " << i;
    EXPECT_LT(reprojection_error_mm(views[0], back, pixels[0]), 1e-6);
  }
}

TEST(ProjectionTest, TriangulationUsesMoreThanTwoViews) {
  const auto pair = make_biplanar_views();
  const std::vector<RadiographView> views = {
      pair[0], pair[1], turned_view(pair[0], Eigen::Vector3d::Zero(), 0.6, "oblique")};
  const Eigen::Vector3d X(-80, 35, 410);
  std::vector<Eigen::Vector2d> pixels(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) pixels[i] = project(views[i], X);
  // Same rounding-level bound as with two views.
  EXPECT_LT((triangulate_linear(views, pixels) - X).norm(), 1e-6);
  // Any two of the three views suffice.
  const std::vector<RadiographView> two = {views[0], views[2]};
  const std::vector<Eigen::Vector2d> two_pixels = {pixels[0], pixels[2]};
  EXPECT_LT((triangulate_linear(two, two_pixels) - X).norm(), 1e-6);
}

// Pixel noise of sigma pixels in u and v of both views. At the isocentre the
// frontal view measures x and z, the lateral one y and z, each with an error
// of sigma * spacing mm; z is measured twice. Expected RMS errors: x and y
// sigma * s, z sigma * s / sqrt(2), 3-D sigma * s * sqrt(2.5).
TEST(ProjectionTest, PixelNoiseGivesTheExpectedPointError) {
  const auto views = make_biplanar_views();
  const Eigen::Vector3d X = Eigen::Vector3d::Zero();
  const std::vector<Eigen::Vector2d> exact = {project(views[0], X), project(views[1], X)};
  constexpr double kSigma = 2.0;  // pixels
  constexpr int kTrials = 4000;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, kSigma);
  Eigen::Vector3d sum_squared = Eigen::Vector3d::Zero();
  for (int i = 0; i < kTrials; ++i) {
    std::vector<Eigen::Vector2d> noisy = exact;
    for (Eigen::Vector2d& pixel : noisy) pixel += Eigen::Vector2d(noise(rng), noise(rng));
    sum_squared += (triangulate_linear(views, noisy) - X).cwiseAbs2();
  }
  const Eigen::Vector3d rms = (sum_squared / kTrials).cwiseSqrt();
  const double s = views[0].pixel_spacing_mm;
  // An RMS over N = 4000 samples has a relative standard error of about
  // 1 / sqrt(2 N) = 1.1 %; 5 % is more than four standard errors. (The
  // linearisation of the projection is exact to ~1e-3 for 0.5 mm errors at
  // 1300 mm.)
  EXPECT_NEAR(rms.x() / (kSigma * s), 1.0, 0.05);
  EXPECT_NEAR(rms.y() / (kSigma * s), 1.0, 0.05);
  EXPECT_NEAR(rms.z() / (kSigma * s / std::sqrt(2.0)), 1.0, 0.05);
  EXPECT_NEAR(rms.norm() / (kSigma * s * std::sqrt(2.5)), 1.0, 0.05);
}

TEST(ProjectionTest, ReprojectionErrorIsPixelDistanceTimesSpacing) {
  const auto views = make_biplanar_views();
  const Eigen::Vector3d X(10, -20, 30);
  const Eigen::Vector2d pixel = project(views[0], X) + Eigen::Vector2d(3, 4);
  // 5 pixels exactly, times the spacing; rounding only.
  EXPECT_NEAR(reprojection_error_mm(views[0], X, pixel), 5 * kSpacing, 1e-9);
}

TEST(ProjectionTest, BadInputIsRejected) {
  const auto views = make_biplanar_views();
  const Eigen::Vector3d X(1, 2, 3);
  const Eigen::Vector2d p0 = project(views[0], X);
  const Eigen::Vector2d p1 = project(views[1], X);
  const std::vector<RadiographView> one = {views[0]};
  const std::vector<Eigen::Vector2d> one_pixel = {p0};
  EXPECT_THAT([&] { (void)triangulate_linear(one, one_pixel); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("at least 2 views")));
  const std::vector<Eigen::Vector2d> three = {p0, p1, p1};
  EXPECT_THAT([&] { (void)triangulate_linear(views, three); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("2 views but 3 pixels")));
  const std::vector<Eigen::Vector2d> nan = {p0, {p1.x(), std::nan("")}};
  EXPECT_THAT([&] { (void)triangulate_linear(views, nan); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("not finite")));
  const std::vector<RadiographView> same = {views[0], views[0]};
  const std::vector<Eigen::Vector2d> same_pixels = {p0, p0};
  EXPECT_THAT([&] { (void)triangulate_linear(same, same_pixels); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("degenerate")));
  // The same source looking at two different pixels: the rays cross only at
  // the focal spot.
  const std::vector<Eigen::Vector2d> two_pixels_one_source = {p0, p0 + Eigen::Vector2d(500, 0)};
  EXPECT_THAT([&] { (void)triangulate_linear(same, two_pixels_one_source); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("share one source")));
  // A second view shifted sideways: parallel central rays, no intersection.
  RadiographView shifted = views[0];
  shifted.name = "shifted";
  shifted.source_mm += Eigen::Vector3d(0, 0, 50);
  shifted.P.col(3) -= shifted.P.leftCols<3>() * Eigen::Vector3d(0, 0, 50);
  const std::vector<RadiographView> parallel = {views[0], shifted};
  const std::vector<Eigen::Vector2d> centres = {{0.5 * views[0].width, 0.5 * views[0].height},
                                                {0.5 * views[0].width, 0.5 * views[0].height}};
  EXPECT_THAT([&] { (void)triangulate_linear(parallel, centres); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("parallel")));

  RadiographView broken = views[1];
  broken.P(1, 2) = std::nan("");
  const std::vector<RadiographView> with_broken = {views[0], broken};
  const std::vector<Eigen::Vector2d> pixels = {p0, p1};
  EXPECT_THAT([&] { (void)triangulate_linear(with_broken, pixels); },
              ::testing::ThrowsMessage<InvalidInputError>(
                  AllOf(HasSubstr("'lateral'"), HasSubstr("non-finite"))));
  RadiographView wrong_source = views[1];
  wrong_source.source_mm.x() += 5;
  EXPECT_THAT([&] { validate_view(wrong_source); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("centre of projection")));
  RadiographView flat = views[1];
  flat.P.row(2).head<3>() = flat.P.row(0).head<3>();  // rank-2 left block
  EXPECT_THAT([&] { validate_view(flat); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("singular")));

  EXPECT_THAT(
      [&] {
        (void)project(views[0], {0, kSid + 10, 0});
      },  // behind the AP source
      ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("behind the source")));
  EXPECT_THROW((void)project(views[0], {0, std::nan(""), 0}), InvalidInputError);
  EXPECT_THROW((void)backproject(views[0], {std::nan(""), 0}), InvalidInputError);
}

TEST(ProjectionTest, OptionsAreValidatedByName) {
  BiplanarOptions pitch;
  pitch.detector_pixel_pitch_mm = -0.3;
  EXPECT_THAT([&] { (void)make_biplanar_views(pitch); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("detector_pixel_pitch_mm")));
  BiplanarOptions near;
  near.source_to_detector_mm = 1000;
  EXPECT_THAT([&] { (void)make_biplanar_views(near); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("must exceed")));
  BiplanarOptions iso;
  iso.isocentre_mm.z() = std::numeric_limits<double>::infinity();
  EXPECT_THAT([&] { (void)make_biplanar_views(iso); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("isocentre_mm")));
  BiplanarOptions huge;
  huge.field_height_mm = 1e6;
  EXPECT_THAT([&] { (void)make_biplanar_views(huge); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("limit")));
}

// --- sidecars ---

std::vector<RadiographFile> example_files() {
  BiplanarOptions options;
  options.isocentre_mm = {1.25, -3.5, 812.0625};
  const auto views = make_biplanar_views(options);
  return {{views[0], "frontal.png"}, {views[1], "lateral.png"}};
}

TEST(ProjectionTest, SidecarRoundTripIsExact) {
  const test::ScratchDir dir("sidecar");
  const std::vector<RadiographFile> files = example_files();
  write_view_sidecar(dir / "views.json", files);
  const std::vector<RadiographFile> back = read_view_sidecar(dir / "views.json");
  ASSERT_EQ(back.size(), 2U);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].image, files[i].image);
    EXPECT_EQ(back[i].view.name, files[i].view.name);
    EXPECT_EQ(back[i].view.width, files[i].view.width);
    EXPECT_EQ(back[i].view.height, files[i].view.height);
    // Shortest round-trip decimal text: bit-identical doubles.
    EXPECT_EQ(back[i].view.pixel_spacing_mm, files[i].view.pixel_spacing_mm);
    EXPECT_EQ(back[i].view.source_mm, files[i].view.source_mm);
    EXPECT_EQ(back[i].view.P, files[i].view.P);
  }
  const Json json = Json::parse(test::read_text(dir / "views.json"));
  EXPECT_EQ(json["format"], "mmm-radiograph-views");
  EXPECT_EQ(json["views"][1]["P"].size(), 3U);
  EXPECT_EQ(json["views"][1]["P"][0].size(), 4U);
}

TEST(ProjectionTest, SidecarWriterRejectsBadViews) {
  const test::ScratchDir dir("sidecar");
  std::vector<RadiographFile> files = example_files();
  files[1].view.name = "frontal";
  EXPECT_THAT([&] { write_view_sidecar(dir / "v.json", files); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("used twice")));
  files = example_files();
  files[0].image.clear();
  EXPECT_THROW(write_view_sidecar(dir / "v.json", files), InvalidInputError);
  files = example_files();
  files[0].view.pixel_spacing_mm = std::nan("");
  EXPECT_THROW(write_view_sidecar(dir / "v.json", files), InvalidInputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "v.json"));
}

struct Malformation {
  std::string label;
  // Edits the JSON text of a valid sidecar.
  std::function<std::string(Json)> edit;
  std::vector<std::string> expected;  // substrings of the error message
};

std::string dumped(const Json& json) { return json.dump(2); }

std::vector<Malformation> malformations() {
  return {
      {"missing spacing",
       [](Json j) {
         j["views"][1].erase("pixel_spacing_mm");
         return dumped(j);
       },
       {"views[1] ('lateral')", "'pixel_spacing_mm' is missing"}},
      {"P with 3 columns",
       [](Json j) {
         for (auto& row : j["views"][0]["P"]) row.erase(3);
         return dumped(j);
       },
       {"views[0] ('frontal')", "'P' must be 3 rows of 4 finite numbers", "row 0 has 3 entries"}},
      {"P with 2 rows",
       [](Json j) {
         j["views"][0]["P"].erase(2);
         return dumped(j);
       },
       {"'P' must be 3 rows", "got 2 rows"}},
      {"P not an array",
       [](Json j) {
         j["views"][0]["P"] = "identity";
         return dumped(j);
       },
       {"'P'", "string"}},
      {"NaN written as null",
       [](Json j) {
         j["views"][1]["P"][1][2] = nullptr;
         return dumped(j);
       },
       {"views[1] ('lateral')", "'P[1][2]' must be a finite number", "null"}},
      {"literal NaN",
       [](Json j) {
         j["views"][1]["P"][1][2] = 123456.789;
         std::string text = dumped(j);
         text.replace(text.find("123456.789"), 10, "NaN");
         return text;
       },
       {"field 'P'", "NaN or Infinity"}},
      {"literal Infinity in spacing",
       [](Json j) {
         j["views"][0]["pixel_spacing_mm"] = 0.123456789;
         std::string text = dumped(j);
         text.replace(text.find("0.123456789"), 11, "Infinity");
         return text;
       },
       {"field 'pixel_spacing_mm'", "NaN or Infinity"}},
      {"short source",
       [](Json j) {
         j["views"][0]["source_mm"].erase(2);
         return dumped(j);
       },
       {"'source_mm' must be an array of 3 finite numbers", "got 2 entries"}},
      {"source off the centre of projection",
       [](Json j) {
         j["views"][0]["source_mm"][0] = 40.0;
         return dumped(j);
       },
       {"views[0] ('frontal')", "centre of projection"}},
      {"fractional width",
       [](Json j) {
         j["views"][0]["width"] = 12.5;
         return dumped(j);
       },
       {"'width' must be a whole number >= 1"}},
      {"zero height",
       [](Json j) {
         j["views"][1]["height"] = 0;
         return dumped(j);
       },
       {"'height' must be a whole number >= 1"}},
      {"width as text",
       [](Json j) {
         j["views"][1]["width"] = "1962";
         return dumped(j);
       },
       {"'width'", "string"}},
      {"negative spacing",
       [](Json j) {
         j["views"][1]["pixel_spacing_mm"] = -0.2;
         return dumped(j);
       },
       {"'pixel_spacing_mm' must be > 0"}},
      {"no image name",
       [](Json j) {
         j["views"][0]["image"] = "";
         return dumped(j);
       },
       {"'image' must be a non-empty string"}},
      {"repeated name",
       [](Json j) {
         j["views"][1]["name"] = "frontal";
         return dumped(j);
       },
       {"views[1]", "used twice"}},
      {"future version",
       [](Json j) {
         j["version"] = 2;
         return dumped(j);
       },
       {"'version' must be 1"}},
      {"other format",
       [](Json j) {
         j["format"] = "something-else";
         return dumped(j);
       },
       {"'format'"}},
      {"no views",
       [](Json j) {
         j["views"] = Json::array();
         return dumped(j);
       },
       {"'views' must be a non-empty array"}},
      {"not JSON", [](const Json&) { return std::string("{\"views\": [}"); }, {"not valid JSON"}},
      {"not an object", [](const Json&) { return std::string("[1, 2]"); }, {"JSON object"}},
  };
}

TEST(ProjectionTest, MalformedSidecarsAreRejectedNamingTheField) {
  const test::ScratchDir dir("sidecar");
  write_view_sidecar(dir / "good.json", example_files());
  const Json good = Json::parse(test::read_text(dir / "good.json"));
  for (const Malformation& bad : malformations()) {
    SCOPED_TRACE(bad.label);
    const auto path = test::write_file(dir / "bad.json", bad.edit(good));
    try {
      (void)read_view_sidecar(path);
      ADD_FAILURE() << "accepted";
    } catch (const IoError& error) {
      const std::string message = error.what();
      EXPECT_THAT(message, HasSubstr("bad.json"));
      for (const std::string& part : bad.expected) EXPECT_THAT(message, HasSubstr(part));
    }
  }
  EXPECT_THAT([&] { (void)read_view_sidecar(dir / "missing.json"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("no such file")));
}

}  // namespace
}  // namespace mmm::image
