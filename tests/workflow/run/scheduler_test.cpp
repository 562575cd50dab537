// The scheduler in process (workflow/run/run_study.h), with small node types
// that compute on numbers: what runs, in which order, what is reused, what a
// failure or a manual node does to the rest, and that parallel workers give
// the same results. Also run under ThreadSanitizer in CI.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "core/errors.h"
#include "tests/support/manual_task_stub.h"
#include "tests/support/test_data.h"
#include "workflow/run/run_study.h"
#include "workflow/run/study_plan.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/study.h"

namespace mmm::workflow {
namespace {

using ::testing::ElementsAre;
using ::testing::UnorderedElementsAre;

// How many `slow` nodes run at this moment, and the most ever seen.
std::atomic<int> g_running{0};
std::atomic<int> g_most_running{0};

double number_input(NodeContext& context, std::string_view port) {
  return nlohmann::json::parse(context.input_bytes(port)).get<double>();
}

NodeRegistry make_registry() {
  NodeRegistry registry;
  registry.add(NodeSpec{"emit", 1, "A number from its parameter"}
                   .param<double>("value", 0.0, "The number")
                   .output<port::Number>("out", "The number"),
               [](NodeContext& context) {
                 context.set_output("out", nlohmann::json(context.number("value")).dump());
               });
  registry.add(NodeSpec{"add", 1, "Sum of two numbers plus an offset"}
                   .input<port::Number>("a", "First")
                   .input<port::Number>("b", "Second")
                   .param<double>("offset", 0.0, "Added to the sum")
                   .param<bool>("fail", false, "Throw instead of computing")
                   .output<port::Number>("out", "a + b + offset"),
               [](NodeContext& context) {
                 if (context.flag("fail")) throw InvalidInputError("asked to fail");
                 const double sum = number_input(context, "a") + number_input(context, "b") +
                                    context.number("offset");
                 context.info("sum " + std::to_string(sum));
                 context.set_output("out", nlohmann::json(sum).dump());
               });
  registry.add(NodeSpec{"slow", 1, "Copies its input after a few progress steps"}
                   .input<port::Number>("in", "A number")
                   .output<port::Number>("out", "The same number"),
               [](NodeContext& context) {
                 const int now = ++g_running;
                 int most = g_most_running.load();
                 while (now > most && !g_most_running.compare_exchange_weak(most, now)) {
                 }
                 for (int step = 0; step < 5; ++step) {
                   context.progress(step, 5, "step");
                   std::this_thread::sleep_for(std::chrono::milliseconds(20));
                 }
                 --g_running;
                 context.set_output("out", context.input_bytes("in"));
               });
  registry.add(NodeSpec{"read_number", 1, "The number a text file holds"}
                   .input<port::File>("file", "A text file")
                   .output<port::Number>("out", "Its number"),
               [](NodeContext& context) {
                 const std::string text = context.input_bytes("file");
                 if (text.find_first_not_of("0123456789.-") != std::string::npos) {
                   throw IoError(context.input("file").path, "holds no number");
                 }
                 context.set_output("out", text);
               });
  registry.add(
      NodeSpec{"approve", 1, "A person confirms a number"}
          .input<port::Number>("in", "The number to confirm")
          .output<port::Number>("out", "The confirmed number")
          .manual(),
      [](NodeContext&) {}, mmm::test::stub_task_behaviour());
  return registry;
}

constexpr const char* kDiamond = R"yaml(mmm_workflow: 1
name: diamond
nodes:
  - {id: a, type: emit, params: {value: 1}}
  - {id: b, type: emit, params: {value: 2}}
  - {id: c, type: add, inputs: {a: a.out, b: b.out}}
  - {id: d, type: add, params: {offset: 10}, inputs: {a: a.out, b: c.out}}
  - {id: e, type: emit, params: {value: 5}}
outputs: {total: d.out}
)yaml";

class SchedulerTest : public ::testing::Test {
 protected:
  Study create(const std::string& yaml) {
    const auto workflow = test::write_file(scratch_ / "wf.yaml", yaml);
    return Study::create(scratch_ / "study", {workflow, {}, {"test", "test"}}, registry_);
  }

  RunSummary run(Study& study, int jobs = 1) {
    const StudyLock lock = StudyLock::acquire(study.dir(), std::chrono::milliseconds(0));
    RunOptions options;
    options.jobs = jobs;
    options.provenance = {"test", "test"};
    return run_study(study, lock, options);
  }

  double output_value(Study& study, const std::string& node) {
    const std::optional<ExecutionRecord> done = last_done_execution(study.database(), node);
    if (!done) throw std::runtime_error("no result for " + node);
    return nlohmann::json::parse(study.artifacts().get(done->outputs.at("out").hash)).get<double>();
  }

  NodeRegistry registry_ = make_registry();
  test::ScratchDir scratch_{"scheduler"};
};

TEST_F(SchedulerTest, RunsADiamondInDependencyOrderThenReusesEverything) {
  Study study = create(kDiamond);
  const RunSummary first = run(study);
  EXPECT_EQ(first.outcome, RunOutcome::kDone);
  ASSERT_EQ(first.executed.size(), 5U);
  const auto position = [&](const std::string& node) {
    return std::ranges::find(first.executed, node) - first.executed.begin();
  };
  EXPECT_LT(position("a"), position("c"));
  EXPECT_LT(position("b"), position("c"));
  EXPECT_LT(position("c"), position("d"));
  EXPECT_EQ(output_value(study, "c"), 3.0);
  EXPECT_EQ(output_value(study, "d"), 14.0);  // 1 + 3 + 10
  EXPECT_EQ(test::read_text(study.outputs_dir() / "total.json"), "14.0");
  const RunSummary second = run(study);
  EXPECT_TRUE(second.executed.empty());
  EXPECT_EQ(second.cached.size(), 5U);
  EXPECT_EQ(second.outcome, RunOutcome::kDone);
}

TEST_F(SchedulerTest, AParameterChangeRerunsExactlyItsDownstreamAndChangingBackReuses) {
  Study study = create(kDiamond);
  run(study);
  study.set_param("b", "value", "4");
  const StudyPlan plan = plan_study(study, false);
  EXPECT_EQ(plan.find("b")->state, NodeState::kPending);
  EXPECT_THAT(plan.find("b")->reason,
              ::testing::HasSubstr("parameter 'value' changed from 2 to 4"));
  EXPECT_EQ(plan.find("c")->state, NodeState::kBlocked);
  EXPECT_EQ(plan.find("a")->state, NodeState::kCached);
  const RunSummary changed = run(study);
  EXPECT_THAT(changed.executed, ElementsAre("b", "c", "d"));
  EXPECT_EQ(output_value(study, "d"), 16.0);  // 1 + 5 + 10
  study.set_param("b", "value", "2");
  const RunSummary back = run(study);
  EXPECT_TRUE(back.executed.empty()) << "the results for value 2 are still in the study";
  EXPECT_EQ(test::read_text(study.outputs_dir() / "total.json"), "14.0");
}

TEST_F(SchedulerTest, AFailureBlocksItsDownstreamWhileOtherBranchesFinish) {
  Study study = create(kDiamond);
  study.set_param("c", "fail", "true");
  const RunSummary failed = run(study);
  EXPECT_EQ(failed.outcome, RunOutcome::kFailed);
  EXPECT_THAT(failed.failed, ElementsAre("c"));
  EXPECT_THAT(failed.blocked, ElementsAre("d"));
  EXPECT_THAT(failed.executed, UnorderedElementsAre("a", "b", "e"));
  const std::optional<ExecutionRecord> record = last_execution(study.database(), "c");
  ASSERT_TRUE(record.has_value());
  EXPECT_EQ(record->status, ExecutionStatus::kFailed);
  EXPECT_THAT(record->error, ::testing::HasSubstr("asked to fail"));
  EXPECT_FALSE(std::filesystem::exists(study.outputs_dir() / "total.json"));
  study.set_param("c", "fail", "false");
  const RunSummary fixed = run(study);
  EXPECT_THAT(fixed.executed, ElementsAre("c", "d"));
  EXPECT_EQ(fixed.outcome, RunOutcome::kDone);
}

// An artifact edited in place used to flow into the next computation.
TEST_F(SchedulerTest, AnInputChangedInPlaceFailsTheNodeThatWouldReadIt) {
  Study study = create(kDiamond);
  run(study);
  const std::string hash = last_done_execution(study.database(), "c")->outputs.at("out").hash;
  const std::filesystem::path blob = study.artifacts().path_of(hash);
  std::filesystem::permissions(blob, std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::add);
  test::write_file(blob, "1000.0");  // c's result was 3
  study.set_param("d", "offset", "20");
  const RunSummary rerun = run(study);
  EXPECT_EQ(rerun.outcome, RunOutcome::kFailed);
  EXPECT_THAT(rerun.failed, ElementsAre("d"));
  const std::optional<ExecutionRecord> record = last_execution(study.database(), "d");
  ASSERT_TRUE(record.has_value());
  EXPECT_THAT(record->error, ::testing::HasSubstr("input 'b' of node 'd' is missing or was "
                                                  "changed after it was stored"));
}

// Errors of nodes name the files they read by their place in the store; the
// recorded error names the file the user gave, and the input.
TEST_F(SchedulerTest, ANodeErrorNamesTheFileTheUserGaveNotItsStoredCopy) {
  const auto workflow = test::write_file(scratch_ / "wf.yaml", R"yaml(mmm_workflow: 1
name: read
inputs: {numbers: {type: File}}
nodes:
  - {id: read, type: read_number, inputs: {file: study.numbers}}
outputs: {value: read.out}
)yaml");
  const auto given = test::write_file(scratch_ / "my numbers.txt", "not a number");
  Study study = Study::create(
      scratch_ / "study", {workflow, {{"numbers", given.string()}}, {"test", "test"}}, registry_);
  const RunSummary failed = run(study);
  EXPECT_THAT(failed.failed, ElementsAre("read"));
  const std::optional<ExecutionRecord> record = last_execution(study.database(), "read");
  ASSERT_TRUE(record.has_value());
  EXPECT_THAT(record->error, ::testing::HasSubstr("'" + std::filesystem::absolute(given).string() +
                                                  "' (study input 'numbers'): holds no number"));
  EXPECT_THAT(record->error, ::testing::Not(::testing::HasSubstr("artifacts/")));
  const std::vector<LogLine> logs = execution_logs(study.database(), record->id);
  ASSERT_FALSE(logs.empty());
  EXPECT_EQ(logs.back().message, record->error);
}

TEST_F(SchedulerTest, AManualNodeMakesTheStudyWaitAndBlocksOnlyItsDownstream) {
  Study study = create(R"yaml(mmm_workflow: 1
name: manual
nodes:
  - {id: a, type: emit, params: {value: 1}}
  - {id: check, type: approve, inputs: {in: a.out}}
  - {id: after, type: add, inputs: {a: check.out, b: a.out}}
  - {id: side, type: add, inputs: {a: a.out, b: a.out}}
)yaml");
  const RunSummary summary = run(study);
  EXPECT_EQ(summary.outcome, RunOutcome::kWaiting);
  EXPECT_THAT(summary.waiting, ElementsAre("check"));
  EXPECT_THAT(summary.blocked, ElementsAre("after"));
  EXPECT_THAT(summary.executed, UnorderedElementsAre("a", "side"));
  EXPECT_EQ(plan_study(study, false).find("check")->state, NodeState::kWaiting);
}

TEST_F(SchedulerTest, ParallelWorkersOverlapAndGiveTheSameResults) {
  std::string yaml =
      "mmm_workflow: 1\nname: wide\nnodes:\n  - {id: seed, type: emit, params: {value: 7}}\n";
  for (int i = 0; i < 6; ++i) {
    yaml += "  - {id: s" + std::to_string(i) + ", type: slow, inputs: {in: seed.out}}\n";
  }
  Study serial = create(yaml);
  run(serial, 1);
  test::ScratchDir other("scheduler-parallel");
  const auto workflow = test::write_file(other / "wf.yaml", yaml);
  Study parallel = Study::create(other / "study", {workflow, {}, {"test", "test"}}, registry_);
  g_most_running = 0;
  const RunSummary summary = run(parallel, 4);
  EXPECT_EQ(summary.executed.size(), 7U);
  // The six slow nodes are independent: with four workers at least two ran
  // at the same time.
  EXPECT_GE(g_most_running.load(), 2);
  for (int i = 0; i < 6; ++i) {
    const std::string node = "s" + std::to_string(i);
    EXPECT_EQ(last_done_execution(serial.database(), node)->outputs,
              last_done_execution(parallel.database(), node)->outputs);
  }
}

TEST_F(SchedulerTest, AnExecutionLeftRunningByADeadRunnerIsMarkedInterrupted) {
  Study study = create(kDiamond);
  ExecutionRecord dead;
  dead.node = "c";
  dead.node_type = "add";
  dead.version = 1;
  dead.cache_key = "0000";
  dead.started_at = "2026-01-01T00:00:00.000Z";
  dead.host = "elsewhere";
  dead.key_parts.node_type = "add";
  const std::int64_t id = insert_execution(study.database(), dead);
  run(study);
  const std::vector<ExecutionRecord> history = executions_of(study.database(), "c");
  ASSERT_EQ(history.size(), 2U);
  EXPECT_EQ(history.front().id, id);
  EXPECT_EQ(history.front().status, ExecutionStatus::kInterrupted);
  EXPECT_EQ(history.back().status, ExecutionStatus::kDone);
}

TEST_F(SchedulerTest, NodeLogsAreStoredWithTheExecution) {
  Study study = create(kDiamond);
  run(study);
  const std::optional<ExecutionRecord> c = last_done_execution(study.database(), "c");
  ASSERT_TRUE(c.has_value());
  const std::vector<LogLine> logs = execution_logs(study.database(), c->id);
  ASSERT_EQ(logs.size(), 1U);
  EXPECT_EQ(logs.front().message, "sum 3.000000");
  EXPECT_EQ(logs.front().level, LogLevel::kInfo);
}

}  // namespace
}  // namespace mmm::workflow
