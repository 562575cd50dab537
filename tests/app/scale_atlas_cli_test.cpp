// Atlas scaling inside a workflow, from the command line: a study of
// schemas/examples/scale_atlas.yaml packs the atlas folder given as its
// input, pauses at the landmark station, and once an operator's landmarks
// are accepted scales the atlas onto them and exports the patient's atlas
// (bundle and folder), the report and the overlay picture.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/atlas/atlas_io.h"
#include "core/image/png.h"
#include "core/image/projection.h"
#include "tests/app/operator_token.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::CommandResult;
using test::run_mmm;

TEST(ScaleAtlasCliTest, TheStationsLandmarksScaleTheAtlasAndItIsExported) {
  test::ScratchDir dir("scale-atlas-cli");
  test::write_toy_leg(dir / "toy");
  const atlas::Atlas generic = atlas::read_atlas(dir / "toy");
  image::BiplanarOptions options;
  options.isocentre_mm = {60, 0, -400};
  options.field_width_mm = 300;
  options.field_height_mm = 1000;
  options.detector_pixel_pitch_mm = 2.0;
  std::vector<image::RadiographFile> files;
  std::vector<image::RadiographView> views;
  for (const image::RadiographView& view : image::make_biplanar_views(options)) {
    image::write_png(image::GrayImage16(view.width, view.height), dir / (view.name + ".png"));
    files.push_back({view, view.name + ".png"});
    views.push_back(view);
  }
  image::write_view_sidecar(dir / "views.json", files);
  const fs::path root = dir / "studies";
  const fs::path study = root / "p7";
  fs::create_directories(root);
  const CommandResult created =
      run_mmm("study create " + study.string() + " -w " +
              (test::source_dir() / "schemas/examples/scale_atlas.yaml").string() +
              " --input atlas=" + (dir / "toy").string() + " --input calibration=" +
              (dir / "views.json").string() + " --input frontal=" + (dir / "frontal.png").string() +
              " --input lateral=" + (dir / "lateral.png").string() + " --input patient=P007");
  ASSERT_EQ(created.exit_code, 0) << created.err;
  const CommandResult paused = run_mmm("run " + study.string() + " -q");
  ASSERT_EQ(paused.exit_code, 3) << paused.out << paused.err;

  const CommandResult listed = run_mmm("worklist --root " + root.string() + " --json");
  const Json tasks = Json::parse(listed.out);
  ASSERT_EQ(tasks.size(), 1U) << listed.out;
  const std::string id = tasks[0]["task"].get<std::string>();
  const std::string where = " --root " + root.string();
  const std::string ana = mmm::test::operator_token_option(root, "ana", dir.path());
  ASSERT_EQ(run_mmm("task claim " + id + where + ana).exit_code, 0);
  // The patient: the atlas 5 % larger about the hip.
  const Eigen::Vector3d hip(80, 0, -50);
  std::string points;
  for (const char* name :
       {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r", "asis_r", "asis_l"}) {
    const Eigen::Vector3d X = hip + 1.05 * (generic.find_landmark(name)->position - hip);
    for (const image::RadiographView& view : views) {
      const Eigen::Vector2d uv = image::project(view, X);
      points += " --point " + std::string(name) + ":" + view.name + "=" + std::to_string(uv.x()) +
                "," + std::to_string(uv.y());
    }
  }
  const CommandResult accepted = run_mmm("task submit " + id + where + ana + points);
  ASSERT_EQ(accepted.exit_code, 0) << accepted.out << accepted.err;

  const fs::path outputs = study / "outputs";
  const Json report = Json::parse(test::read_text(outputs / "scaling_report.json"));
  for (const auto& [name, residual] : report["landmark_residual_mm"].items()) {
    EXPECT_LT(residual.get<double>(), 0.5) << name;
  }
  EXPECT_EQ(report["landmark_residual_mm"].size(), 5U);
  EXPECT_NEAR(report["bones"][1]["length_factor"].get<double>(), 1.05, 0.01);
  // The ASIS measure the pelvis: its affine part is fitted to them.
  EXPECT_EQ(report["bones"][0]["solve"], "affine fit");
  EXPECT_TRUE(fs::is_regular_file(outputs / "patient_atlas.atlas"));
  const atlas::Atlas patient = atlas::read_atlas(outputs / "patient_atlas");
  EXPECT_NEAR((patient.markers[0].position - hip).norm(),
              1.05 * (generic.markers[0].position - hip).norm(), 0.5);
  EXPECT_TRUE(fs::is_regular_file(outputs / "overlay.png"));
  EXPECT_EQ(run_mmm("audit verify " + study.string()).exit_code, 0);
}

}  // namespace
}  // namespace mmm
