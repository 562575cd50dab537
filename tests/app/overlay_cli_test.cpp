// `mmm overlay`: the bones of an atlas outlined over a radiograph pair. The
// drawing itself is tested in tests/core/image/outline_overlay_test.cpp; here
// the command line: its usage errors, and one run on the fixture patient
// (built under <build>/fixtures by the web test, or by `make demo` under
// build/fixtures; skipped when neither exists).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <variant>

#include "core/image/png.h"
#include "core/image/projection.h"
#include "tests/support/test_data.h"

namespace mmm::app {
namespace {

using mmm::test::CommandResult;
using mmm::test::run_mmm;
using ::testing::HasSubstr;

TEST(OverlayCliTest, MissingOptionsAreAUsageError) {
  const CommandResult result = run_mmm("overlay --atlas somewhere -o out.png");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("--radiographs"));
}

TEST(OverlayCliTest, MissingAtlasFailsNamingIt) {
  const mmm::test::ScratchDir dir("overlay-cli");
  const CommandResult result =
      run_mmm("overlay --atlas " + (dir / "no_atlas").string() + " --radiographs " +
              (dir / "views.json").string() + " -o " + (dir / "out.png").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("no_atlas"));
}

TEST(OverlayCliTest, FixturePatientsBonesOverItsRadiographs) {
  std::filesystem::path patient = mmm::test::binary_dir() / "fixtures" / "patient_1";
  if (!std::filesystem::exists(patient / "radiographs" / "views.json")) {
    patient = mmm::test::source_dir() / "build" / "fixtures" / "patient_1";
  }
  if (!std::filesystem::exists(patient / "radiographs" / "views.json")) {
    GTEST_SKIP() << "no fixture patient";
  }
  const mmm::test::ScratchDir dir("overlay-cli");
  const std::filesystem::path out = dir / "overlay.png";
  const CommandResult result =
      run_mmm("overlay --atlas " + (patient / "atlas").string() + " --radiographs " +
              (patient / "radiographs" / "views.json").string() + " -o " + out.string() +
              " --max-width 1000");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  // The legend names each bone with its colour.
  EXPECT_THAT(result.out, HasSubstr("femur_r"));
  EXPECT_THAT(result.out, HasSubstr("pelvis"));
  const image::PngContent png = image::read_png(out);
  const auto& rgb = std::get<image::RgbImage8>(png.image);
  EXPECT_LE(rgb.width, 1000);
  EXPECT_GT(rgb.width, 900);  // the pair (2098 px for seed 1's) scaled down to fit
  // Both views keep their proportions: as tall as one view scaled alike.
  const auto views = image::read_view_sidecar(patient / "radiographs" / "views.json");
  const double scale = (1000.0 - 10.0) / (views[0].view.width + views[1].view.width);
  EXPECT_NEAR(rgb.height, views[0].view.height * scale, 1.0);
}

}  // namespace
}  // namespace mmm::app
