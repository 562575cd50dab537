// The landmark station from the command line: a study of
// schemas/examples/landmark_station.yaml pauses (exit 3) with a task on the
// worklist; an operator claims and submits pixels; a rejected submission
// lists its reasons (exit 1); an accepted one resumes the study (exit 0);
// `mmm audit verify` passes, then catches an edited entry.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <nlohmann/json.hpp>

#include "core/image/png.h"
#include "core/image/projection.h"
#include "tests/app/operator_token.h"
#include "tests/support/test_data.h"

namespace mmm {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using test::CommandResult;
using test::run_mmm;

class StationCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image::BiplanarOptions options;
    options.isocentre_mm = {0, 0, 500};
    options.detector_pixel_pitch_mm = 4.0;
    std::vector<image::RadiographFile> files;
    for (const image::RadiographView& view : image::make_biplanar_views(options)) {
      image::write_png(image::GrayImage16(view.width, view.height), dir_ / (view.name + ".png"));
      files.push_back({view, view.name + ".png"});
      views_.push_back(view);
    }
    image::write_view_sidecar(dir_ / "views.json", files);
    fs::create_directories(root_);
    const CommandResult created =
        run_mmm("study create " + study_.string() + " -w " +
                (test::source_dir() / "schemas/examples/landmark_station.yaml").string() +
                " --input calibration=" + (dir_ / "views.json").string() +
                " --input frontal=" + (dir_ / "frontal.png").string() +
                " --input lateral=" + (dir_ / "lateral.png").string() + " --input patient=P042");
    ASSERT_EQ(created.exit_code, 0) << created.err;
    ana_ = mmm::test::operator_token_option(root_, "ana", dir_.path());
    ben_ = mmm::test::operator_token_option(root_, "ben", dir_.path());
  }

  std::string point(const std::string& name, const Eigen::Vector3d& X) const {
    std::string text;
    for (const image::RadiographView& view : views_) {
      const Eigen::Vector2d uv = image::project(view, X);
      text += " --point " + name + ":" + view.name + "=" + std::to_string(uv.x()) + "," +
              std::to_string(uv.y());
    }
    return text;
  }

  std::string task_id() const {
    const CommandResult listed = run_mmm("worklist --root " + root_.string() + " --json");
    EXPECT_EQ(listed.exit_code, 0) << listed.err;
    const Json tasks = Json::parse(listed.out);
    EXPECT_EQ(tasks.size(), 1U) << listed.out;
    return tasks.empty() ? std::string() : tasks[0]["task"].get<std::string>();
  }

  test::ScratchDir dir_{"station-cli"};
  fs::path root_ = dir_ / "studies";
  fs::path study_ = root_ / "p42";
  std::vector<image::RadiographView> views_;
  std::string ana_;  // " --token-file FILE" of operator ana
  std::string ben_;
};

TEST_F(StationCliTest, PauseSubmitRejectedThenAcceptedResumesAndTheAuditVerifies) {
  const CommandResult paused = run_mmm("run " + study_.string() + " -q");
  EXPECT_EQ(paused.exit_code, 3) << paused.out << paused.err;
  const std::string id = task_id();
  ASSERT_EQ(id.size(), 10U);
  const CommandResult table = run_mmm("worklist --root " + root_.string());
  EXPECT_NE(table.out.find("P042"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("open"), std::string::npos) << table.out;

  const std::string task = " --root " + root_.string();
  const CommandResult claimed = run_mmm("task claim " + id.substr(0, 5) + task + ana_);
  EXPECT_EQ(claimed.exit_code, 0) << claimed.err;
  EXPECT_EQ(run_mmm("task claim " + id + task + ben_).exit_code, 1);

  const Eigen::Vector3d head(90, 0, 900);
  const Eigen::Vector3d patella(80, 30, 480);
  // The patella placed above the femoral head: rejected, with the reason.
  const CommandResult rejected =
      run_mmm("task submit " + id + task + ana_ + point("femoral_head_centre_r", patella) +
              point("patella_centre_r", head));
  EXPECT_EQ(rejected.exit_code, 1);
  EXPECT_NE(rejected.err.find("rejected"), std::string::npos) << rejected.err;
  EXPECT_NE(rejected.err.find("above"), std::string::npos) << rejected.err;

  ASSERT_EQ(run_mmm("task claim " + id + task + ana_).exit_code, 0);
  const CommandResult accepted =
      run_mmm("task submit " + id + task + ana_ + point("femoral_head_centre_r", head) +
              point("patella_centre_r", patella));
  EXPECT_EQ(accepted.exit_code, 0) << accepted.out << accepted.err;
  EXPECT_NE(accepted.out.find("study resumed"), std::string::npos) << accepted.out;
  const Json report = Json::parse(test::read_text(study_ / "outputs/landmark_report.json"));
  EXPECT_NEAR(report["distances_mm"]["femoral_head_centre_r-patella_centre_r"].get<double>(),
              (head - patella).norm(), 1e-3);

  const CommandResult verified = run_mmm("audit verify " + study_.string());
  EXPECT_EQ(verified.exit_code, 0) << verified.err;
  const CommandResult csv = run_mmm("audit show " + study_.string() + " --csv");
  EXPECT_NE(csv.out.find("ana"), std::string::npos);

  // Someone edits the operator of an entry behind mmm's back.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((study_ / "study.db").c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "DROP TRIGGER IF EXISTS audit_no_update", nullptr, nullptr, nullptr);
  sqlite3_exec(db, "DROP TRIGGER IF EXISTS audit_no_delete", nullptr, nullptr, nullptr);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE audit SET operator_name = 'ben' WHERE seq = 2", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const CommandResult tampered = run_mmm("audit verify " + study_.string());
  EXPECT_EQ(tampered.exit_code, 1);
  EXPECT_NE(tampered.err.find("entry 2"), std::string::npos) << tampered.err;
}

// A submission file nested 100,000 levels deep (it used to crash mmm) or
// larger than a submission can be is refused with the reason; the task stays
// claimed and a proper submission then goes through.
TEST_F(StationCliTest, DeepOrHugeSubmissionFilesAreRefusedAndTheTaskStaysOpen) {
  ASSERT_EQ(run_mmm("run " + study_.string() + " -q").exit_code, 3);
  const std::string id = task_id();
  const std::string task = " --root " + root_.string() + ana_;
  ASSERT_EQ(run_mmm("task claim " + id + task).exit_code, 0);

  const fs::path deep =
      test::write_file(dir_ / "deep.json", std::string(100000, '[') + std::string(100000, ']'));
  const CommandResult refused = run_mmm("task submit " + id + task + " --file " + deep.string());
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_NE(refused.err.find("nested more than 64 levels"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("deep.json"), std::string::npos) << refused.err;

  const fs::path huge = test::write_file(dir_ / "huge.json", std::string(2 << 20, ' ') + "{}");
  const CommandResult too_big = run_mmm("task submit " + id + task + " --file " + huge.string());
  EXPECT_EQ(too_big.exit_code, 1);
  EXPECT_NE(too_big.err.find("a submission is at most 1048576"), std::string::npos) << too_big.err;

  const CommandResult accepted =
      run_mmm("task submit " + id + task + point("femoral_head_centre_r", {90, 0, 900}) +
              point("patella_centre_r", {80, 30, 480}));
  EXPECT_EQ(accepted.exit_code, 0) << accepted.out << accepted.err;
}

// On the command line an operator acts under their own token (a file or the
// environment, never an argument); an administrative override is named,
// needs a reason and is recorded in the audit trail.
TEST_F(StationCliTest, CommandLineActionsNeedTheOperatorsTokenOrAnAuditedOverride) {
  ASSERT_EQ(run_mmm("run " + study_.string() + " -q").exit_code, 3);
  const std::string id = task_id();
  const std::string task = " --root " + root_.string();

  const CommandResult bare = run_mmm("task claim " + id + task + " --operator ana");
  EXPECT_EQ(bare.exit_code, 1);
  EXPECT_NE(bare.err.find("no operator token"), std::string::npos) << bare.err;
  const CommandResult other = run_mmm("task claim " + id + task + ben_ + " --operator ana");
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("the token is operator 'ben''s, not 'ana''s"), std::string::npos)
      << other.err;
  const CommandResult forged = run_mmm("task claim " + id + task, "MMM_OPERATOR_TOKEN=forged");
  EXPECT_EQ(forged.exit_code, 1);
  EXPECT_NE(forged.err.find("unknown operator token"), std::string::npos) << forged.err;
  const CommandResult blank =
      run_mmm("task claim " + id + task + " --operator ana --admin-override '  '");
  EXPECT_EQ(blank.exit_code, 1);
  EXPECT_NE(blank.err.find("needs a reason"), std::string::npos) << blank.err;

  // The token from the environment.
  const std::string ana_token = test::read_text(dir_ / "ana.token");
  const CommandResult claimed = run_mmm(
      "task claim " + id + task, "MMM_OPERATOR_TOKEN=" + ana_token.substr(0, ana_token.find('\n')));
  EXPECT_EQ(claimed.exit_code, 0) << claimed.err;
  EXPECT_NE(claimed.out.find("claimed by ana"), std::string::npos) << claimed.out;

  // A script of the root's administrator releases it for ana, by override.
  const CommandResult released =
      run_mmm("task release " + id + task + " --operator ana --admin-override 'nightly cleanup'");
  EXPECT_EQ(released.exit_code, 0) << released.err;
  const Json trail = Json::parse(run_mmm("audit show " + study_.string() + " --json").out);
  ASSERT_GE(trail.size(), 2U);
  const Json& override_entry = trail[trail.size() - 2];
  EXPECT_EQ(override_entry["action"], "override");
  EXPECT_EQ(override_entry["operator"], "ana");
  EXPECT_NE(override_entry["reason"].get<std::string>().find(
                "administrative override for 'release': nightly cleanup"),
            std::string::npos)
      << override_entry;
  EXPECT_EQ(trail.back()["action"], "release");
  EXPECT_EQ(run_mmm("audit verify " + study_.string()).exit_code, 0);
}

// mmm report on a study that has only its landmarks: the audit section names
// who submitted which landmarks, the later sections say they are not computed
// yet, and the page is offline (no scripts, no links out).
TEST_F(StationCliTest, ReportShowsTheAuditAndWhatIsNotComputedYet) {
  EXPECT_EQ(run_mmm("run " + study_.string() + " -q").exit_code, 3);
  const std::string id = task_id();
  const std::string task = " --root " + root_.string();
  ASSERT_EQ(run_mmm("task claim " + id + task + ana_).exit_code, 0);
  const CommandResult accepted =
      run_mmm("task submit " + id + task + ana_ + point("femoral_head_centre_r", {90, 0, 900}) +
              point("patella_centre_r", {80, 30, 480}));
  ASSERT_EQ(accepted.exit_code, 0) << accepted.err;

  const CommandResult reported = run_mmm("report " + study_.string());
  ASSERT_EQ(reported.exit_code, 0) << reported.err;
  EXPECT_NE(reported.out.find("not computed yet: overlay scaling motion wrapping fibres"),
            std::string::npos)
      << reported.out;
  const std::string html = test::read_text(study_ / "report/index.html");
  EXPECT_NE(html.find("<td>ana</td><td>submit</td>"), std::string::npos);
  EXPECT_NE(html.find("femoral_head_centre_r, patella_centre_r"), std::string::npos);
  EXPECT_NE(html.find("id=\"provenance\""), std::string::npos);
  EXPECT_NE(html.find("<td>landmark_station</td>"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos);
  EXPECT_EQ(run_mmm("report " + (dir_ / "nothing").string()).exit_code, 1);

  // A synthetic patient's truth: the placed landmarks' distances from it
  // (1 mm and 4 mm off by construction); the surfaces wait for the scaling.
  const fs::path truth = dir_ / "truth";
  test::write_file(truth / "ground_truth.json",
                   R"({"landmarks": {"femoral_head_centre_r": {"position_mm": [91, 0, 900]},
                                     "patella_centre_r": {"position_mm": [80, 30, 484]}}})");
  const CommandResult compared =
      run_mmm("report " + study_.string() + " --truth " + truth.string());
  ASSERT_EQ(compared.exit_code, 0) << compared.err;
  const std::string with_truth = test::read_text(study_ / "report/index.html");
  EXPECT_NE(with_truth.find("<td>femoral_head_centre_r</td><td>1.00</td>"), std::string::npos);
  EXPECT_NE(with_truth.find("<td>patella_centre_r</td><td>4.00</td>"), std::string::npos);
  EXPECT_EQ(with_truth.find("Surface distance of every"), std::string::npos);
  const CommandResult not_a_patient =
      run_mmm("report " + study_.string() + " --truth " + root_.string());
  EXPECT_EQ(not_a_patient.exit_code, 1);
  EXPECT_NE(not_a_patient.err.find("ground_truth.json: missing"), std::string::npos)
      << not_a_patient.err;
}

}  // namespace
}  // namespace mmm
