// Crash safety of studies, end to end: a child `mmm run` is killed with
// SIGKILL at many different points of a deterministic workflow (inside
// artifact writes, inside nodes, around database commits, between nodes,
// while exporting); after each, a plain `mmm run` must finish the study, and
// every result and exported file must be bit-identical to those of a run that
// was never interrupted. The kill points come from the engine's fault
// injection (workflow/fault_injection.h): MMM_FAULT_TRACE lists the points an
// uninterrupted run passes, MMM_KILL_AT=K kills the process at the K-th.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/hash/sha256.h"
#include "tests/app/study/study_cli_fixture.h"
#include "tests/support/test_data.h"

namespace mmm::app {
namespace {

using mmm::test::CommandResult;
using mmm::test::run_mmm;
using mmm::test::ScratchDir;

std::vector<std::string> read_lines(const std::filesystem::path& file) {
  std::istringstream in(mmm::test::read_text(file));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Exported file name -> SHA-256 of its bytes.
std::map<std::string, std::string> exported_files(const std::filesystem::path& study) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(study / "outputs")) {
    files[entry.path().filename().string()] = hash::sha256_file_hex(entry.path());
  }
  return files;
}

// Files of a study that only a writer in the middle of its work may leave.
std::vector<std::string> leftover_temporaries(const std::filesystem::path& study) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(study)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".tmp-") || name.ends_with(".tmp")) found.push_back(name);
  }
  return found;
}

bool killed(const CommandResult& result) {
  // SIGKILL: not a normal exit, or the shell's 128 + 9 when it did not exec.
  return result.exit_code == -1 || result.exit_code == 128 + 9;
}

// The kill points to test: the first occurrence of every distinct point, then
// evenly spaced others, up to `budget` in all (sorted, 1-based).
std::vector<int> choose_points(const std::vector<std::string>& trace, std::size_t budget) {
  std::set<int> chosen;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    if (seen.insert(trace[i]).second) chosen.insert(static_cast<int>(i) + 1);
  }
  const std::size_t spare = budget > chosen.size() ? budget - chosen.size() : 0;
  for (std::size_t j = 0; j < spare; ++j) {
    chosen.insert(static_cast<int>(1 + (j * trace.size()) / std::max<std::size_t>(spare, 1)));
  }
  return {chosen.begin(), chosen.end()};
}

class StudyCrashTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::tie(workflow_, surface_) = app::test::write_mesh_workflow(scratch_.path());
    pristine_ = scratch_ / "pristine";
    const CommandResult created =
        run_mmm(app::test::create_command(pristine_, workflow_, surface_));
    ASSERT_EQ(created.exit_code, 0) << created.err;
  }

  // A copy of the freshly created (never run) study.
  std::filesystem::path fresh_copy(const std::string& name) {
    std::filesystem::path copy = scratch_ / name;
    std::filesystem::copy(pristine_, copy, std::filesystem::copy_options::recursive);
    return copy;
  }

  ScratchDir scratch_{"crash"};
  std::filesystem::path workflow_;
  std::filesystem::path surface_;
  std::filesystem::path pristine_;
};

TEST_F(StudyCrashTest, EveryKillPointResumesToTheUninterruptedResult) {
  // The reference: one uninterrupted run, tracing its fault points.
  const std::filesystem::path reference = fresh_copy("reference");
  const std::filesystem::path trace_file = scratch_ / "trace.txt";
  const CommandResult first =
      run_mmm("run " + reference.string() + " -j 1 -q", "MMM_FAULT_TRACE=" + trace_file.string());
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::vector<std::string> trace = read_lines(trace_file);
  const std::set<std::string> distinct(trace.begin(), trace.end());
  // Every kind of place must be covered: artifact writes, node bodies,
  // commits, scheduling, exports.
  for (const char* expected :
       {"artifact.mid_write", "artifact.before_rename", "artifact.after_rename", "node.progress",
        "node.before_run", "node.after_run", "run.before_commit", "run.after_commit",
        "run.schedule", "export.before_rename", "run.finished"}) {
    EXPECT_TRUE(distinct.contains(expected)) << expected << " never reached";
  }
  const nlohmann::json reference_status = app::test::status_json(reference);
  ASSERT_EQ(reference_status["state"], "done");
  const auto reference_outputs = app::test::result_outputs(reference_status);
  ASSERT_EQ(reference_outputs.size(), 6U);
  const auto reference_files = exported_files(reference);
  ASSERT_EQ(reference_files.size(), 4U);

  // 40 points: every distinct one plus evenly spaced others.
  const std::vector<int> points = choose_points(trace, 40);
  ASSERT_GE(points.size(), 20U) << "the workflow passes too few fault points: " << trace.size();
  for (const int point : points) {
    SCOPED_TRACE("killed at point " + std::to_string(point) + " (" + trace[point - 1] + ")");
    const std::filesystem::path study = fresh_copy("kill-" + std::to_string(point));
    const CommandResult crashed =
        run_mmm("run " + study.string() + " -j 1 -q", "MMM_KILL_AT=" + std::to_string(point));
    // Group commits depend on the clock, so the points after the first
    // commit may shift by one or two between runs: the last ones may then
    // lie beyond the end of the run.
    const bool near_the_end = point + 3 > static_cast<int>(trace.size());
    if (!near_the_end || crashed.exit_code != 0) {
      ASSERT_TRUE(killed(crashed)) << "exit " << crashed.exit_code << ": " << crashed.err;
    }

    const CommandResult resumed = run_mmm("run " + study.string() + " -q");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    const nlohmann::json status = app::test::status_json(study);
    EXPECT_EQ(status["state"], "done");
    EXPECT_EQ(app::test::result_outputs(status), reference_outputs);
    EXPECT_EQ(exported_files(study), reference_files);
    EXPECT_THAT(leftover_temporaries(study), ::testing::IsEmpty());
    // The interrupted execution, if one was recorded, is marked so.
    for (const auto& node : status["nodes"]) {
      EXPECT_NE(node["last_execution"]["status"], "running") << node["id"];
    }
    std::filesystem::remove_all(study);
  }
}

TEST_F(StudyCrashTest, KillsWithParallelWorkersResumeToTheSameResult) {
  // The reference, traced: with two workers and clock-driven group commits
  // the number of points a run passes varies from run to run (fewer commits
  // when the machine is slow, e.g. under a sanitizer), so the kill points are
  // spread over the first 75% of this run's trace rather than fixed.
  const std::filesystem::path reference = fresh_copy("reference");
  const std::filesystem::path trace_file = scratch_ / "parallel_trace.txt";
  ASSERT_EQ(
      run_mmm("run " + reference.string() + " -j 2 -q", "MMM_FAULT_TRACE=" + trace_file.string())
          .exit_code,
      0);
  const auto reference_outputs = app::test::result_outputs(app::test::status_json(reference));
  const auto trace_length = static_cast<int>(read_lines(trace_file).size());
  ASSERT_GE(trace_length, 20) << "the workflow passes too few fault points";
  for (const double fraction : {0.05, 0.25, 0.45, 0.6, 0.75}) {
    const int point = std::max(1, static_cast<int>(fraction * trace_length));
    SCOPED_TRACE("killed at point " + std::to_string(point) + " of ~" +
                 std::to_string(trace_length));
    const std::filesystem::path study = fresh_copy("parallel-" + std::to_string(point));
    const CommandResult crashed =
        run_mmm("run " + study.string() + " -j 2 -q", "MMM_KILL_AT=" + std::to_string(point));
    EXPECT_TRUE(killed(crashed)) << "exit " << crashed.exit_code << ": " << crashed.err;
    ASSERT_EQ(run_mmm("run " + study.string() + " -j 2 -q").exit_code, 0);
    EXPECT_EQ(app::test::result_outputs(app::test::status_json(study)), reference_outputs);
    EXPECT_EQ(exported_files(study), exported_files(reference));
    EXPECT_THAT(leftover_temporaries(study), ::testing::IsEmpty());
  }
}

}  // namespace
}  // namespace mmm::app
