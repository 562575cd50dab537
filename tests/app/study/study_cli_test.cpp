// End-to-end checks of studies from the command line: mmm study create|set,
// mmm run, mmm status, mmm explain, with the real node types, the way an
// operator or a script uses them (exit codes, messages, what re-runs).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <string>
#include <thread>

#include "tests/app/study/study_cli_fixture.h"
#include "tests/support/test_data.h"
#include "workflow/store/study_lock.h"

namespace mmm::app {
namespace {

using mmm::test::CommandResult;
using mmm::test::run_mmm;
using mmm::test::ScratchDir;
using ::testing::HasSubstr;

// node id -> id of its latest execution (0 when it never ran).
std::map<std::string, std::int64_t> last_execution_ids(const std::filesystem::path& study) {
  std::map<std::string, std::int64_t> ids;
  const nlohmann::json status = app::test::status_json(study);
  for (const auto& node : status["nodes"]) {
    ids[node["id"]] =
        node.contains("last_execution") ? node["last_execution"]["id"].get<std::int64_t>() : 0;
  }
  return ids;
}

// The nodes whose latest execution changed between two snapshots.
std::set<std::string> reran(const std::map<std::string, std::int64_t>& before,
                            const std::map<std::string, std::int64_t>& after) {
  std::set<std::string> nodes;
  for (const auto& [node, id] : after) {
    if (before.at(node) != id) nodes.insert(node);
  }
  return nodes;
}

class StudyCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::tie(workflow_, surface_) = app::test::write_mesh_workflow(scratch_.path());
    study_ = scratch_ / "study";
    const CommandResult created = run_mmm(app::test::create_command(study_, workflow_, surface_));
    ASSERT_EQ(created.exit_code, 0) << created.err;
    ASSERT_THAT(created.out, HasSubstr("created study"));
  }

  CommandResult run(const std::string& extra = "") {
    return run_mmm("run " + study_.string() + " -q" + extra);
  }

  ScratchDir scratch_{"study-cli"};
  std::filesystem::path workflow_;
  std::filesystem::path surface_;
  std::filesystem::path study_;
};

TEST_F(StudyCliTest, FirstRunComputesEverythingAndTheSecondDoesNothing) {
  const CommandResult first = run();
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_THAT(first.out, HasSubstr("6 node(s) ran, 0 cached"));
  EXPECT_THAT(first.out, HasSubstr("study done"));
  for (const char* file : {"coarser.ply", "side.ply", "coarser_report.json", "full_report.json"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(study_ / "outputs" / file)) << file;
  }
  const CommandResult second = run();
  EXPECT_EQ(second.exit_code, 0) << second.err;
  EXPECT_THAT(second.out, HasSubstr("nothing to do: 6 node(s) up to date (cached)"));
  EXPECT_EQ(app::test::status_json(study_)["state"], "done");
}

// outputs/ behind the results (a run killed while exporting, a file edited
// by hand): status says so and is not "done"; the next run re-exports.
TEST_F(StudyCliTest, StatusSaysWhenOutputsDoNotMatchTheResultsAndARunReexports) {
  ASSERT_EQ(run().exit_code, 0);
  mmm::test::write_file(study_ / "outputs" / "full_report.json", "{}");
  std::filesystem::remove(study_ / "outputs" / "side.ply");
  const nlohmann::json stale = app::test::status_json(study_);
  EXPECT_EQ(stale["state"], "outputs_stale");
  EXPECT_FALSE(stale["outputs_match"].get<bool>());
  const std::string reasons = stale["stale_outputs"].dump();
  EXPECT_THAT(reasons, HasSubstr("outputs/full_report.json was changed after it was exported"));
  EXPECT_THAT(reasons, HasSubstr("outputs/side.ply is missing"));
  const CommandResult text = run_mmm("status " + study_.string());
  EXPECT_THAT(text.out, HasSubstr("outputs   'side': outputs/side.ply is missing"));
  const CommandResult rerun = run();
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_THAT(rerun.out, HasSubstr("exported to"));
  const nlohmann::json fixed = app::test::status_json(study_);
  EXPECT_EQ(fixed["state"], "done");
  EXPECT_TRUE(fixed["outputs_match"].get<bool>());
}

TEST_F(StudyCliTest, ChangingAParameterRerunsExactlyItsDownstream) {
  ASSERT_EQ(run().exit_code, 0);
  const auto before = last_execution_ids(study_);
  const CommandResult set = run_mmm("study set " + study_.string() + " coarse.target_faces=1000");
  ASSERT_EQ(set.exit_code, 0) << set.err;
  const nlohmann::json status = app::test::status_json(study_);
  for (const auto& node : status["nodes"]) {
    if (node["id"] == "coarse") {
      EXPECT_EQ(node["state"], "pending");
      EXPECT_THAT(node["reason"].get<std::string>(),
                  HasSubstr("parameter 'target_faces' changed from 1200 to 1000"));
    }
  }
  ASSERT_EQ(run().exit_code, 0);
  EXPECT_EQ(reran(before, last_execution_ids(study_)),
            (std::set<std::string>{"coarse", "coarser", "measure_coarser"}));
}

TEST_F(StudyCliTest, ChangingTheInputFileRerunsEverythingThatReadsIt) {
  ASSERT_EQ(run().exit_code, 0);
  const auto before = last_execution_ids(study_);
  // Same content written again: nothing changes.
  const std::string bytes = mmm::test::read_text(surface_);
  mmm::test::write_file(surface_, bytes);
  std::filesystem::last_write_time(
      surface_, std::filesystem::file_time_type::clock::now() + std::chrono::seconds(5));
  CommandResult again = run();
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.out, HasSubstr("nothing to do"));
  // New content: a finer sphere.
  app::test::write_mesh_workflow(scratch_.path(), 3);
  std::filesystem::last_write_time(
      surface_, std::filesystem::file_time_type::clock::now() + std::chrono::seconds(10));
  const CommandResult changed = run();
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_EQ(reran(before, last_execution_ids(study_)),
            (std::set<std::string>{"load", "coarse", "coarser", "side", "measure_coarser",
                                   "measure_full"}));
}

TEST_F(StudyCliTest, AMovedStudyLosesNothing) {
  ASSERT_EQ(run().exit_code, 0);
  const std::filesystem::path moved = scratch_ / "elsewhere" / "moved-study";
  std::filesystem::create_directories(moved.parent_path());
  std::filesystem::rename(study_, moved);
  const CommandResult result = run_mmm("run " + moved.string() + " -q");
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("nothing to do: 6 node(s)"));
}

TEST_F(StudyCliTest, AFailingNodeFailsTheStudyButIndependentBranchesFinish) {
  // Reading the PLY surface as STL fails in the first node: everything waits
  // behind it.
  ASSERT_EQ(run_mmm("study set " + study_.string() + " coarser.target_faces=2000000").exit_code, 0);
  ASSERT_EQ(run_mmm("study set " + study_.string() + " load.format=stl").exit_code, 0);
  const CommandResult failed = run();
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_THAT(failed.err, HasSubstr("study failed: load"));
  EXPECT_THAT(failed.err, HasSubstr("mmm explain"));
  const CommandResult explain = run_mmm("explain " + study_.string() + " load");
  EXPECT_EQ(explain.exit_code, 0) << explain.err;
  EXPECT_THAT(explain.out, HasSubstr("failed"));
  EXPECT_THAT(explain.out, HasSubstr("error: "));
  // Back to PLY: load and everything after it run; the study completes.
  ASSERT_EQ(run_mmm("study set " + study_.string() + " load.format=ply").exit_code, 0);
  const CommandResult fixed = run();
  EXPECT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_THAT(fixed.out, HasSubstr("6 node(s) ran"));
}

TEST_F(StudyCliTest, BadSettingsAreRejectedWithTheKnownNames) {
  CommandResult result = run_mmm("study set " + study_.string() + " coarse.target_face=10");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err,
              HasSubstr("has no parameter 'target_face'; did you mean 'target_faces'?"));
  result = run_mmm("study set " + study_.string() + " coarse.target_faces=-3");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("outside the range"));
  result = run_mmm("study set " + study_.string() + " corse.target_faces=10");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("no node 'corse' in the workflow; did you mean 'coarse'?"));
  result = run_mmm("study set " + study_.string() + " study.surfce=/tmp/x.ply");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("unknown study input 'surfce'; did you mean 'surface'?"));
  result = run_mmm("run");
  EXPECT_EQ(result.exit_code, 2);
  result = run_mmm("run " + (scratch_ / "nowhere").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("not a study folder"));
}

TEST_F(StudyCliTest, CreateRefusesBadInputsAndLeavesNothingBehind) {
  const std::filesystem::path other = scratch_ / "other";
  CommandResult result = run_mmm("study create " + other.string() + " --workflow " +
                                 workflow_.string() + " --input surfac=" + surface_.string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("unknown study input 'surfac'; did you mean 'surface'?"));
  EXPECT_THAT(result.err, HasSubstr("study input 'surface' (File) has no default"));
  EXPECT_FALSE(std::filesystem::exists(other));
  result = run_mmm("study create " + other.string() + " --workflow " + workflow_.string() +
                   " --input surface=" + (scratch_ / "missing.ply").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("no such file"));
  EXPECT_FALSE(std::filesystem::exists(other));
  result = run_mmm(app::test::create_command(study_, workflow_, surface_));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("exists and is not empty"));
  // Nothing but the two studies' folders and the fixture files: no staging
  // folder left.
  for (const auto& entry : std::filesystem::directory_iterator(scratch_.path())) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr("creating")));
  }
}

TEST_F(StudyCliTest, ASecondRunnerExitsOrWaitsAndNothingRunsTwice) {
  // A big sphere keeps the first runner busy long enough (about a second).
  app::test::write_mesh_workflow(scratch_.path(), 6);
  ASSERT_EQ(
      run_mmm("study set " + study_.string() + " study.surface=" + surface_.string()).exit_code, 0);
  auto first = std::async(std::launch::async, [this] { return run(); });
  // Wait until the first runner has recorded itself in the lock file.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!workflow::StudyLock::read_holder(study_) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(workflow::StudyLock::read_holder(study_).has_value());
  const CommandResult second = run(" --wait 0");
  auto third = std::async(std::launch::async, [this] { return run(" --wait 600"); });
  const CommandResult first_result = first.get();
  const CommandResult third_result = third.get();
  EXPECT_EQ(first_result.exit_code, 0) << first_result.err;
  if (second.exit_code == 4) {
    EXPECT_THAT(second.err, HasSubstr("pid"));
    EXPECT_THAT(second.err, HasSubstr("--wait"));
  } else {
    // The first runner finished before the second started (a very fast
    // machine): then the second found nothing to do.
    EXPECT_EQ(second.exit_code, 0) << second.err;
    EXPECT_THAT(second.out, HasSubstr("nothing to do"));
  }
  EXPECT_EQ(third_result.exit_code, 0) << third_result.err;
  EXPECT_THAT(third_result.out, HasSubstr("nothing to do"));
  // Every node ran exactly once.
  for (const char* node :
       {"load", "coarse", "coarser", "side", "measure_coarser", "measure_full"}) {
    const CommandResult explain = run_mmm("explain " + study_.string() + " " + node + " --json");
    ASSERT_EQ(explain.exit_code, 0) << explain.err;
    EXPECT_EQ(nlohmann::json::parse(explain.out)["history"].size(), 1U) << node;
  }
}

}  // namespace
}  // namespace mmm::app
