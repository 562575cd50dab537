// The cohort report (app/report/cohort_report_page.h) on a root of five
// studies made by hand: databases with their runs, outputs with known
// figures. The distribution is the figures', the one study far from the
// others is the outlier, the operators' errors are pooled per operator, and
// a study without outputs counts as having no figure.

#include "app/report/cohort_report_page.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "tests/support/test_data.h"
#include "workflow/store/sqlite.h"
#include "workflow/study/study_database.h"
#include "worklists/task_store.h"

namespace mmm::app::report {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

void make_study(const fs::path& dir, double femur_factor, const std::string& finished,
                const std::string& operator_name) {
  fs::create_directories(dir / "outputs");
  workflow::Database database(dir / "study.db");
  workflow::prepare_study_database(database);
  database.exec(
      "INSERT INTO runs(started_at, finished_at, status, host, pid, mmm_version, git_revision, "
      "workflow_hash, jobs) VALUES ('2026-11-29T10:00:00.000Z', '" +
      finished + "', 'done', 'h', 1, 'v', 'r', 'w', 1)");
  worklists::prepare_task_tables(database);
  worklists::Task task;
  task.id = worklists::new_task_id();
  task.node = "landmarks";
  task.node_type = "landmark_station";
  task.cache_key = std::string(64, 'a');
  task.state = worklists::TaskState::kAccepted;
  task.created_at = task.updated_at = "2026-11-29T10:00:01.000Z";
  task.submitted_by = operator_name;
  worklists::insert_task(database, task);
  test::write_file(dir / "outputs" / "scaling_report.json",
                   R"({"length_factor": {"femur_r": )" + std::to_string(femur_factor) +
                       R"(, "tibia_r": 1.0}, "warnings": []})");
  test::write_file(
      dir / "outputs" / "landmarks.json",
      R"({"landmarks": [{"name": "a", "reprojection_error_mm": {"frontal": 0.5, "lateral": 1.5}}]})");
}

TEST(CohortReportTest, DistributionsOutliersOperatorsAndThroughput) {
  const test::ScratchDir scratch("cohort-report");
  const fs::path root = scratch / "root";
  make_study(root / "p1", 0.90, "2026-11-29T10:01:00.000Z", "ana");
  make_study(root / "p2", 0.91, "2026-11-29T10:02:00.000Z", "ana");
  make_study(root / "p3", 0.92, "2026-11-29T10:03:00.000Z", "lea");
  make_study(root / "p4", 0.91, "2026-11-29T10:04:00.000Z", "lea");
  make_study(root / "p5", 1.30, "2026-11-29T10:05:00.000Z", "lea");
  // A study created, never run: no figures.
  fs::create_directories(root / "p6");
  {
    workflow::Database database(root / "p6" / "study.db");
    workflow::prepare_study_database(database);
  }
  const std::vector<CohortStudyFigures> studies = gather_cohort_figures(root);
  ASSERT_EQ(studies.size(), 6U);
  EXPECT_DOUBLE_EQ(studies[0].figures.at("femur_length_factor"), 0.90);
  EXPECT_DOUBLE_EQ(studies[0].figures.at("landmark_error_mm"), 1.5);  // the worse view
  EXPECT_DOUBLE_EQ(studies[0].figures.at("compute_seconds"), 60.0);
  EXPECT_EQ(studies[0].landmark_operator, "ana");
  EXPECT_EQ(studies[5].state, "created");
  EXPECT_TRUE(studies[5].figures.empty());

  const CohortReportResult result = write_cohort_report(root, scratch / "report");
  EXPECT_EQ(result.studies, 6U);
  const std::string page = test::read_text(result.index);
  // femur: median 0.91 of (0.90, 0.91, 0.91, 0.92, 1.30); MAD 0.01 -> p5 is 3 x 1.48 x 0.01
  // off: the one outlier. Compute times 60..300 s have no outlier.
  EXPECT_EQ(result.outliers, 1U);
  EXPECT_THAT(page, HasSubstr("femur length factor: p5 (<code>mmm report"));
  EXPECT_THAT(page, HasSubstr("<td>5</td><td>0.910</td>"));
  EXPECT_THAT(page, HasSubstr("5 of 6 studies done"));
  // Operators: ana 2 sets, lea 3, each landmark's worst view 1.5 mm.
  EXPECT_THAT(page, HasSubstr("<td>ana</td><td>2</td><td>2</td><td>1.50</td>"));
  EXPECT_THAT(page, HasSubstr("<td>lea</td><td>3</td><td>3</td><td>1.50</td>"));
  EXPECT_THAT(page, Not(HasSubstr("<script")));
}

}  // namespace
}  // namespace mmm::app::report
