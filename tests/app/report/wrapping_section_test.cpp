// The study report's wrapping section: muscle-muscle depth is shown when the
// wrapping measured it, and the page says so when it did not.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/report/study_report_page.h"
#include "tests/support/test_data.h"

namespace mmm::app::report {
namespace {

using Json = nlohmann::json;

std::string report_html(const Json& wrapping) {
  const test::ScratchDir dir("report-wrapping");
  std::filesystem::create_directories(dir / "outputs");
  test::write_file(dir / "outputs" / "wrapping_report.json", wrapping.dump());
  const ReportInput input{.status = {{"state", "done"}, {"nodes", Json::array()}},
                          .audit = Json::array(),
                          .outputs = dir / "outputs",
                          .truth = std::nullopt,
                          .threads = 2};
  const ReportResult result = write_study_report(input, dir / "report");
  return test::read_text(result.index);
}

Json wrapping_report(bool measured) {
  return {{"frames", 121},
          {"muscle_penetration_measured", measured},
          {"max_depth_in_other_muscles_mm", 7.25},
          {"muscles",
           {{{"muscle", "vastus_lateralis_r"},
             {"max_abs_volume_error_percent", 1e-7},
             {"max_depth_mm", 0.1},
             {"max_depth_in_other_muscles_mm", 7.25},
             {"median_ms_per_frame", 13.0}}}}};
}

TEST(WrappingSectionTest, MuscleMuscleDepthIsShownWhenMeasured) {
  const std::string html = report_html(wrapping_report(true));
  EXPECT_NE(html.find("depth in other muscles (mm)"), std::string::npos);
  EXPECT_NE(html.find("7.25"), std::string::npos);
  EXPECT_EQ(html.find("was not measured"), std::string::npos);
}

TEST(WrappingSectionTest, TheReportSaysWhenMuscleMuscleDepthWasNotMeasured) {
  const std::string html = report_html(wrapping_report(false));
  EXPECT_EQ(html.find("depth in other muscles (mm)"), std::string::npos);
  EXPECT_NE(html.find("Muscle-muscle penetration was not measured"), std::string::npos);
}

}  // namespace
}  // namespace mmm::app::report
