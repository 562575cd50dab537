// Landmarks from a 3D Slicer point list, from the command line: a study of
// schemas/examples/import_markups.yaml imports the file, checks it and
// scales the atlas onto it; the study report says where the landmarks came
// from. A mirrored file (LPS points declared RAS) fails with the hint.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/atlas/atlas_io.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::CommandResult;
using test::run_mmm;

// The toy atlas's landmarks 5 % larger about the hip, with common labels;
// `negate` flips x and y while the file still says RAS.
std::string toy_point_list(const atlas::Atlas& generic, bool negate) {
  const Eigen::Vector3d hip(80, 0, -50);
  const std::vector<std::pair<std::string, std::string>> labels = {
      {"Femoral Head Centre R", "femoral_head_centre_r"},
      {"Patella", "patella_centre_r"},
      {"AJC", "ankle_centre_r"},
      {"R ASIS", "asis_r"},
      {"LASIS", "asis_l"}};
  Json points = Json::array();
  for (const auto& [label, name] : labels) {
    const Eigen::Vector3d X = hip + 1.05 * (generic.find_landmark(name)->position - hip);
    const double s = negate ? -1.0 : 1.0;
    points.push_back({{"label", label}, {"position", {s * X.x(), s * X.y(), X.z()}}});
  }
  return Json{{"markups", Json::array({{{"type", "Fiducial"},
                                        {"coordinateSystem", "RAS"},
                                        {"controlPoints", points}}})}}
      .dump(2);
}

CommandResult create_and_run(const fs::path& study, const fs::path& atlas,
                             const fs::path& markups) {
  const CommandResult created =
      run_mmm("study create " + study.string() + " -w " +
              (test::source_dir() / "schemas/examples/import_markups.yaml").string() +
              " --input atlas=" + atlas.string() + " --input markups=" + markups.string());
  EXPECT_EQ(created.exit_code, 0) << created.err;
  return run_mmm("run " + study.string() + " -q");
}

TEST(ImportMarkupsCliTest, ASlicerFileScalesTheAtlasAndTheReportNamesIt) {
  test::ScratchDir dir("import-markups-cli");
  test::write_toy_leg(dir / "toy");
  const atlas::Atlas generic = atlas::read_atlas(dir / "toy");
  const fs::path file =
      test::write_file(dir / "ct_landmarks.mrk.json", toy_point_list(generic, false));
  const fs::path study = dir / "ct1";
  const CommandResult ran = create_and_run(study, dir / "toy", file);
  ASSERT_EQ(ran.exit_code, 0) << ran.out << ran.err;
  const Json report = Json::parse(test::read_text(study / "outputs" / "scaling_report.json"));
  EXPECT_EQ(report["landmark_residual_mm"].size(), 5U);
  EXPECT_NEAR(report["length_factor"]["femur_r"].get<double>(), 1.05, 0.01);
  EXPECT_TRUE(report["warnings"].empty());
  const CommandResult written = run_mmm("report " + study.string());
  ASSERT_EQ(written.exit_code, 0) << written.err;
  const std::string html = test::read_text(study / "report" / "index.html");
  EXPECT_NE(html.find("Imported from " + file.string()), std::string::npos);
  EXPECT_NE(html.find("no radiograph"), std::string::npos);
  EXPECT_NE(html.find("stretch vs first stage"), std::string::npos);
  EXPECT_NE(html.find("No implausible stretch"), std::string::npos);

  // The same points with x and y negated, still declared RAS.
  const fs::path mirrored =
      test::write_file(dir / "mirrored.mrk.json", toy_point_list(generic, true));
  const fs::path bad = dir / "ct2";
  const CommandResult failed = create_and_run(bad, dir / "toy", mirrored);
  EXPECT_NE(failed.exit_code, 0);
  const CommandResult status = run_mmm("status " + bad.string() + " --json");
  const std::string all = failed.out + failed.err + status.out;
  EXPECT_NE(all.find("look like LPS coordinates read as RAS"), std::string::npos) << all;
  EXPECT_FALSE(fs::exists(bad / "outputs" / "patient_atlas.atlas"));
}

}  // namespace
}  // namespace mmm
