// The default atlas end to end, on the real data: `mmm atlas build` with the
// committed recipe, `mmm atlas check`, `mmm atlas show`, and a synthetic
// patient whose radiographs must show its anatomy where the calibration says.
// The atlas is built once (about 20 s of CPU) and every check runs on it in
// one test: ctest runs each TEST in its own process, so separate tests would
// build it again each time.
//
// MMM_TEST_DEFAULT_ATLAS names an atlas already built from the same recipe by
// another build of the same tree (.ci/run: the Release build's test fixture,
// for the sanitizer build, where the build alone takes ten minutes); then
// every check runs on that atlas, which is only read.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>

#include "core/atlas/atlas_io.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_views.h"
#include "core/image/png.h"
#include "core/image/projection.h"
#include "tests/support/test_data.h"

namespace mmm::app {
namespace {

using mmm::test::CommandResult;
using mmm::test::run_mmm;

class AtlasCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = std::make_unique<mmm::test::ScratchDir>("atlas-cli");
    atlas_ = scratch_->path() / "atlas";
    const std::filesystem::path recipe =
        mmm::test::source_dir() / "schemas" / "recipes" / "vhf_right_leg.yaml";
    if (const char* prebuilt = std::getenv("MMM_TEST_DEFAULT_ATLAS"); prebuilt != nullptr) {
      prebuilt_ = prebuilt;
      return;
    }
    build_ = run_mmm("atlas build " + recipe.string() + " -o " + atlas_.string() + " --data " +
                     mmm::test::data_dir().string());
  }
  static void TearDownTestSuite() { scratch_.reset(); }

  static nlohmann::json build_report() {
    return nlohmann::json::parse(mmm::test::read_text(atlas_ / "build_report.json"));
  }

  static void check_passes();
  static void anchors_land();
  static void show_writes_a_picture();
  static void patient_radiographs_show_the_anatomy();

  static std::unique_ptr<mmm::test::ScratchDir> scratch_;
  static std::filesystem::path atlas_;
  static std::filesystem::path prebuilt_;  // MMM_TEST_DEFAULT_ATLAS, else empty
  static CommandResult build_;
};

std::unique_ptr<mmm::test::ScratchDir> AtlasCliTest::scratch_;
std::filesystem::path AtlasCliTest::atlas_;
std::filesystem::path AtlasCliTest::prebuilt_;
CommandResult AtlasCliTest::build_;

void AtlasCliTest::check_passes() {
  const CommandResult check = run_mmm("atlas check " + atlas_.string() + " --json");
  ASSERT_EQ(check.exit_code, 0) << check.out << check.err;
  const nlohmann::json report = nlohmann::json::parse(check.out);
  EXPECT_TRUE(report["passed"].get<bool>());
  EXPECT_EQ(report["muscles"].size(), 38U);  // 37 right muscles + the mirrored left one
  for (const auto& muscle : report["muscles"]) {
    // The builder cleans muscles down to 0.5 mm inside bone; the check allows 1.
    EXPECT_LE(muscle["max_penetration_mm"].get<double>(), 1.0) << muscle["name"];
    // The gemelli and plantaris are the smallest (2.3-3.8 cm^3).
    EXPECT_GT(muscle["volume_mm3"].get<double>(), 2e3) << muscle["name"];
  }
  // One subject's bones fit together: every joint closed, no bone in another.
  const nlohmann::json& anatomy = report["anatomy"];
  ASSERT_GE(anatomy["articulations"].size(), 6U);
  for (const auto& articulation : anatomy["articulations"]) {
    EXPECT_LE(articulation["gap_mm"].get<double>(), 3.0) << articulation["name"];
    EXPECT_LE(articulation["overlap_mm"].get<double>(), 1.0) << articulation["name"];
  }
  for (const auto& [bone, gap] : anatomy["nearest_neighbour_gap_mm"].items()) {
    EXPECT_LE(gap.get<double>(), 5.0) << bone;
  }
  EXPECT_LT(anatomy["hip_centre_offset_mm"].get<double>(), 3.0);
  const atlas::Atlas atlas = atlas::read_atlas(atlas_);
  for (const char* name : {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r", "asis_r",
                           "lateral_epicondyle_r", "medial_malleolus_r"}) {
    EXPECT_NE(atlas.find_landmark(name), nullptr) << name;
  }
  // Each ASIS on its own hip bone (the pelvis is four welded bones): a left
  // ASIS looked for on the right hip bone alone lands on the pubis, 216 mm
  // from its marker, and tips a pelvis scaled onto a subject's ASIS.
  const atlas::Landmark* asis_r = atlas.find_landmark("asis_r");
  const atlas::Landmark* asis_l = atlas.find_landmark("asis_l");
  ASSERT_NE(asis_r, nullptr);
  ASSERT_NE(asis_l, nullptr);
  const Eigen::Vector3d across = asis_r->position - asis_l->position;
  EXPECT_GT(across.norm(), 160.0);
  EXPECT_LT(across.norm(), 340.0);
  EXPECT_GT(across.x(), 0.95 * across.norm());  // x toward the subject's right
  // The femoral-head centre is the sphere fitted to the VHF head cartilage,
  // which the data's README puts at about (636.9, 448.9, 883.0) mm.
  const Eigen::Vector3d head = atlas.find_landmark("femoral_head_centre_r")->position;
  EXPECT_LT((head - Eigen::Vector3d(636.9, 448.9, 883.0)).norm(), 1.5);
  EXPECT_EQ(atlas.find_by_tag("quadriceps").size(), 4U);
}

void AtlasCliTest::anchors_land() {
  const nlohmann::json report = build_report();
  int anchored = 0;
  for (const auto& registration : report["registrations"]) {
    for (const auto& [name, residual] : registration["anchor_residuals_mm"].items()) {
      // Anchors (hip centres, femoral head, joint centres) weigh as much as
      // the whole surface fit: they land within a millimetre.
      EXPECT_LT(residual.get<double>(), 1.0) << registration["body"] << " " << name;
      ++anchored;
    }
    if (registration["surface_pairs"].get<int>() > 0) {
      // Generic OpenSim bones onto one subject's: a few mm of shape
      // difference remain (the gait2392 pelvis is 242 triangles).
      EXPECT_LT(registration["surface_rms_mm"].get<double>(), 10.0) << registration["body"];
    }
  }
  // Both hip centres, the femoral head and the knee (the talus is placed
  // through the ankle joint instead).
  EXPECT_GE(anchored, 4);
  // The knee and hip frames mapped through two independent registrations
  // agree: hip centres coincide, the knee to within a few mm and degrees.
  for (const auto& joint : report["joints"]) {
    if (joint["joint"] == "hip_r") {
      EXPECT_LT(joint["frame_mismatch_mm"].get<double>(), 3.0);
    }
    if (joint["joint"] == "knee_r") {
      EXPECT_LT(joint["frame_mismatch_mm"].get<double>(), 5.0);
    }
    if (joint["joint"] == "ankle_r") {
      // Placed through the joint's own motion: agrees up to rounding.
      EXPECT_LT(joint["frame_mismatch_mm"].get<double>(), 1e-6);
      EXPECT_LT(joint["frame_mismatch_deg"].get<double>(), 1e-6);
    }
  }
}

void AtlasCliTest::show_writes_a_picture() {
  const std::filesystem::path picture = scratch_->path() / "atlas.png";
  const CommandResult shown =
      run_mmm("atlas show " + atlas_.string() + " --png " + picture.string() + " --width 200");
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const image::PngContent png = image::read_png(picture);
  ASSERT_TRUE(std::holds_alternative<image::RgbImage8>(png.image));
  // Four panels side by side (each at most 200 px wide; the side views are
  // narrower), taller than wide: a standing leg.
  const auto& rgb = std::get<image::RgbImage8>(png.image);
  EXPECT_GT(rgb.width, 2 * 200);
  EXPECT_LE(rgb.width, 4 * 200 + 3 * 10);
  EXPECT_GT(rgb.height, 200);
  // The landmarks with their anatomical definitions (the manifest's).
  EXPECT_NE(shown.out.find("lateral_epicondyle_r on femur_r [landmark, right, bony, local]: "
                           "Lateral femoral epicondyle: the most prominent point"),
            std::string::npos)
      << shown.out;
  const CommandResult labels = run_mmm("atlas labels");
  ASSERT_EQ(labels.exit_code, 0) << labels.err;
  EXPECT_NE(labels.out.find("asis_r (R ASIS"), std::string::npos) << labels.out;
}

void AtlasCliTest::patient_radiographs_show_the_anatomy() {
  const std::filesystem::path patient = scratch_->path() / "patient";
  // A coarse detector (1.5 mm pitch) keeps the test quick.
  const CommandResult made = run_mmm("patient synth --atlas " + atlas_.string() +
                                     " --seed 7 --pixel-pitch 1.5 --dicom -o " + patient.string());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const nlohmann::json truth =
      nlohmann::json::parse(mmm::test::read_text(patient / "ground_truth.json"));
  const auto views = image::read_view_sidecar(patient / "radiographs" / "views.json");
  ASSERT_EQ(views.size(), 2U);
  std::vector<image::DicomRadiograph> dicoms;
  dicoms.reserve(views.size());
  for (const image::RadiographFile& file : views) {
    SCOPED_TRACE(file.view.name);
    const image::GrayImage16 radiograph =
        image::read_png_gray16(patient / "radiographs" / file.image);
    ASSERT_EQ(radiograph.width, file.view.width);
    // The DICOM copy: the same samples, and its attributes make the same
    // slot-scanning view about the isocentre (the world origin for a view
    // calibrated from DICOM, the bones' centre for the synthetic patient).
    dicoms.push_back(
        image::read_dicom_radiograph(patient / "radiographs" / (file.view.name + ".dcm")));
    EXPECT_EQ(dicoms.back().image.pixels, radiograph.pixels);
    std::vector<std::uint16_t> sorted = radiograph.pixels;
    std::ranges::sort(sorted);
    const double median = sorted[sorted.size() / 2];
    for (const char* name : {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"}) {
      const auto& landmark = truth["landmarks"][name];
      const Eigen::Vector3d position(landmark["position_mm"][0].get<double>(),
                                     landmark["position_mm"][1].get<double>(),
                                     landmark["position_mm"][2].get<double>());
      // The sidecar's matrix projects the ground-truth point where the
      // ground truth says (same numbers, written and read back).
      const Eigen::Vector2d pixel = image::project(file.view, position);
      EXPECT_NEAR(pixel.x(), landmark["pixels"][file.view.name][0].get<double>(), 1e-6);
      // ... onto bone: brighter (more attenuation) than most of the image,
      // most of which is air around the leg.
      const int u = std::clamp(static_cast<int>(pixel.x()), 0, radiograph.width - 1);
      const int v = std::clamp(static_cast<int>(pixel.y()), 0, radiograph.height - 1);
      EXPECT_GT(radiograph.at(u, v), median + 2000) << name;
    }
  }
  const image::DicomPairGeometry from_dicom =
      image::views_from_dicom({dicoms.data(), "frontal.dcm"}, {dicoms.data() + 1, "lateral.dcm"},
                              image::ProjectionModel::kSlotScanning);
  // The isocentre: the point both true views project to their image centres.
  const std::array<image::RadiographView, 2> truth_views = {views[0].view, views[1].view};
  const std::array<Eigen::Vector2d, 2> centres = {
      Eigen::Vector2d(0.5 * views[0].view.width, 0.5 * views[0].view.height),
      Eigen::Vector2d(0.5 * views[1].view.width, 0.5 * views[1].view.height)};
  const Eigen::Vector3d isocentre = image::triangulate_linear(truth_views, centres);
  for (std::size_t k = 0; k < 2; ++k) {
    const Eigen::Vector3d X = isocentre + Eigen::Vector3d(30, -20, 150);
    EXPECT_LT(
        (image::project(from_dicom.views[k], X - isocentre) - image::project(truth_views[k], X))
            .norm(),
        1e-6);
  }
  // Back-projecting the femoral head from both views recovers it (3D -> 2D -> 3D).
  const auto& head = truth["landmarks"]["femoral_head_centre_r"];
  const std::array<image::RadiographView, 2> pair = {views[0].view, views[1].view};
  const std::array<Eigen::Vector2d, 2> pixels = {
      Eigen::Vector2d(head["pixels"][views[0].view.name][0], head["pixels"][views[0].view.name][1]),
      Eigen::Vector2d(head["pixels"][views[1].view.name][0],
                      head["pixels"][views[1].view.name][1])};
  const Eigen::Vector3d recovered = image::triangulate_linear(pair, pixels);
  const Eigen::Vector3d expected(head["position_mm"][0], head["position_mm"][1],
                                 head["position_mm"][2]);
  // Exact pixels: only rounding separates them.
  EXPECT_LT((recovered - expected).norm(), 1e-6);
}

TEST_F(AtlasCliTest, DefaultRecipeBuildsACheckedAtlasAndSyntheticPatients) {
  if (prebuilt_.empty()) {
    ASSERT_EQ(build_.exit_code, 0) << build_.err;
  } else {
    // Built by another build of this tree: it must postdate the recipe.
    const std::filesystem::path recipe =
        mmm::test::source_dir() / "schemas" / "recipes" / "vhf_right_leg.yaml";
    ASSERT_TRUE(std::filesystem::is_regular_file(prebuilt_ / "atlas.yaml"))
        << "MMM_TEST_DEFAULT_ATLAS=" << prebuilt_ << " holds no atlas.yaml";
    ASSERT_GE(std::filesystem::last_write_time(prebuilt_ / "atlas.yaml"),
              std::filesystem::last_write_time(recipe))
        << "MMM_TEST_DEFAULT_ATLAS=" << prebuilt_ << " is older than " << recipe;
    atlas_ = prebuilt_;
  }
  {
    SCOPED_TRACE("mmm atlas check passes, landmarks and tags are there");
    check_passes();
  }
  {
    SCOPED_TRACE("the registrations land their anchors; the chain's frames agree");
    anchors_land();
  }
  {
    SCOPED_TRACE("mmm atlas show writes a picture");
    show_writes_a_picture();
  }
  {
    SCOPED_TRACE("a synthetic patient's radiographs show its anatomy where the sidecar says");
    patient_radiographs_show_the_anatomy();
  }
}

}  // namespace
}  // namespace mmm::app
