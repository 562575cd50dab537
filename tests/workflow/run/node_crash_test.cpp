// A node that crashes the process (abort, segmentation fault, stack
// overflow): the run happens in a forked child, which dies; the next run in
// this process finds the crash marker, records the crash, reports the node as
// failed with the signal, and does not run it again with the same inputs and
// parameters unless asked to (workflow/run/crash_marker.h,
// workflow/study/crash_records.h).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/run/crash_marker.h"
#include "workflow/run/run_study.h"
#include "workflow/run/study_plan.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/crash_records.h"
#include "workflow/study/study.h"

namespace mmm::workflow {
namespace {

// Only the forked child really crashes; in the test process the node throws
// instead (so a node that runs when it should not fails the test, not the
// test program).
bool g_crash_allowed = false;

int overflow_the_stack(int depth) {
  std::array<volatile char, 1024> frame{};
  frame[0] = static_cast<char>(depth);
  if (depth > 1'000'000'000) return frame[0];
  return overflow_the_stack(depth + 1) + frame[0];
}

void crash(const std::string& how) {
  if (how == "none") return;
  if (!g_crash_allowed) throw InvalidInputError("would crash here (" + how + ")");
  if (how == "abort") std::abort();
  if (how == "segv") {
    volatile int* nowhere = nullptr;
    *nowhere = 1;
  }
  if (how == "stack") overflow_the_stack(static_cast<int>(how.size()));
}

NodeRegistry crash_registry() {
  NodeRegistry registry;
  registry.add(NodeSpec{"number", 1, "A number from its parameter"}
                   .param<double>("value", 0.0, "The number")
                   .output<port::Number>("out", "The number"),
               [](NodeContext& context) {
                 context.set_output("out", nlohmann::json(context.number("value")).dump());
               });
  registry.add(NodeSpec{"fragile", 1, "A number from its parameter, or a crash as told"}
                   .param<double>("value", 0.0, "The number")
                   .param<std::string>("how", "none", "abort, segv, stack or none")
                   .output<port::Number>("out", "The number"),
               [](NodeContext& context) {
                 crash(context.text("how"));
                 context.set_output("out", nlohmann::json(context.number("value")).dump());
               });
  registry.add(NodeSpec{"add", 1, "The sum of two numbers"}
                   .input<port::Number>("a", "First")
                   .input<port::Number>("b", "Second")
                   .output<port::Number>("out", "a + b"),
               [](NodeContext& context) {
                 const double sum = nlohmann::json::parse(context.input_bytes("a")).get<double>() +
                                    nlohmann::json::parse(context.input_bytes("b")).get<double>();
                 context.set_output("out", nlohmann::json(sum).dump());
               });
  return registry;
}

std::string workflow_with(const std::string& how) {
  return "mmm_workflow: 1\nname: crashing\nnodes:\n"
         "  - {id: a, type: number, params: {value: 4}}\n"
         "  - {id: c, type: fragile, params: {value: 2, how: " +
         how +
         "}}\n"
         "  - {id: d, type: add, inputs: {a: a.out, b: c.out}}\n"
         "outputs: {sum: d.out}\n";
}

class NodeCrashTest : public ::testing::Test {
 protected:
  void create(const std::string& how) {
    const auto workflow = test::write_file(scratch_ / "wf.yaml", workflow_with(how));
    Study::create(dir(), {workflow, {}, {"test", "test"}}, registry_);
  }

  [[nodiscard]] std::filesystem::path dir() const { return scratch_ / "study"; }

  RunSummary run(Study& study, bool retry_crashed = false) {
    const StudyLock lock = StudyLock::acquire(study.dir(), std::chrono::milliseconds(0));
    RunOptions options;
    options.provenance = {"test", "test"};
    options.retry_crashed = retry_crashed;
    return run_study(study, lock, options);
  }

  // Runs the study in a forked child (its own database connection); returns
  // the child's wait status.
  int run_in_child() {
    const pid_t child = ::fork();
    if (child == 0) {
      g_crash_allowed = true;
      try {
        Study study = Study::open(dir(), registry_);
        run(study);
      } catch (...) {
        ::_exit(3);
      }
      ::_exit(0);
    }
    // A child that hangs instead of dying (a sanitizer's own handler can
    // deadlock on a second fault) is killed after a minute: what is checked
    // is the marker it left.
    int status = 0;
    for (int waited_ms = 0; waited_ms < 60'000; waited_ms += 10) {
      if (::waitpid(child, &status, WNOHANG) == child) return status;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(child, SIGKILL);
    ::waitpid(child, &status, 0);
    return status;
  }

  NodeRegistry registry_ = crash_registry();
  test::ScratchDir scratch_{"node-crash"};
};

// The child died abnormally: killed by the signal, or (under a sanitizer,
// which reports the fault and exits) with a failure status.
bool died(int status) {
  return WIFSIGNALED(status) ||
         (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 3);
}

TEST_F(NodeCrashTest, ANodeThatAbortsIsReportedAsFailedAndNotRunAgain) {
  create("abort");
  ASSERT_TRUE(died(run_in_child()));

  const std::vector<MarkedCrash> marked = read_crash_marker(dir() / "crash-marker");
  ASSERT_EQ(marked.size(), 1U);
  EXPECT_EQ(marked[0].signal, SIGABRT);
  EXPECT_EQ(marked[0].node, "c");

  Study study = Study::open(dir(), registry_);
  // Before any run, the status already names the crash.
  const StudyPlan plan = plan_study(study, false);
  ASSERT_NE(plan.find("c"), nullptr);
  EXPECT_EQ(plan.find("c")->state, NodeState::kFailed);
  EXPECT_NE(plan.find("c")->reason.find("SIGABRT"), std::string::npos);

  for (int attempt = 0; attempt < 2; ++attempt) {
    const RunSummary summary = run(study);
    EXPECT_EQ(summary.outcome, RunOutcome::kFailed);
    EXPECT_EQ(summary.failed, std::vector<std::string>{"c"});
    EXPECT_EQ(summary.blocked, std::vector<std::string>{"d"});
    const std::optional<ExecutionRecord> last = last_execution(study.database(), "c");
    ASSERT_TRUE(last.has_value());
    EXPECT_EQ(last->status, ExecutionStatus::kFailed);
    EXPECT_NE(last->error.find("crashed mmm"), std::string::npos) << last->error;
    EXPECT_NE(last->error.find("SIGABRT"), std::string::npos) << last->error;
    EXPECT_NE(last->error.find("--retry-crashed"), std::string::npos) << last->error;
    EXPECT_EQ(last->error.find("would crash here"), std::string::npos) << last->error;
  }
  EXPECT_FALSE(std::filesystem::exists(dir() / "crash-marker"));
  EXPECT_TRUE(find_crash(study.database(), "c", last_execution(study.database(), "c")->cache_key)
                  .has_value());

  // Asked to, it runs again (and here throws: proof that it ran).
  const RunSummary retried = run(study, true);
  EXPECT_EQ(retried.failed, std::vector<std::string>{"c"});
  EXPECT_NE(last_execution(study.database(), "c")->error.find("would crash here"),
            std::string::npos);

  // Another parameter is another cache key: it runs normally.
  study.set_param("c", "how", "none");
  const RunSummary fixed = run(study);
  EXPECT_EQ(fixed.outcome, RunOutcome::kDone) << last_execution(study.database(), "c")->error;
  EXPECT_EQ(last_execution(study.database(), "c")->status, ExecutionStatus::kDone);
}

TEST_F(NodeCrashTest, ASegmentationFaultIsRecorded) {
  create("segv");
  ASSERT_TRUE(died(run_in_child()));
  const std::vector<MarkedCrash> marked = read_crash_marker(dir() / "crash-marker");
  ASSERT_EQ(marked.size(), 1U);
  EXPECT_EQ(marked[0].signal, SIGSEGV);
  Study study = Study::open(dir(), registry_);
  EXPECT_EQ(run(study).failed, std::vector<std::string>{"c"});
  EXPECT_NE(last_execution(study.database(), "c")->error.find("SIGSEGV"), std::string::npos);
}

TEST_F(NodeCrashTest, AStackOverflowIsRecorded) {
#if defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "ThreadSanitizer's fault handler deadlocks on a stack overflow";
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
  GTEST_SKIP() << "ThreadSanitizer's fault handler deadlocks on a stack overflow";
#endif
#endif
  create("stack");
  ASSERT_TRUE(died(run_in_child()));
  const std::vector<MarkedCrash> marked = read_crash_marker(dir() / "crash-marker");
  ASSERT_EQ(marked.size(), 1U);
  EXPECT_EQ(marked[0].signal, SIGSEGV);
  EXPECT_EQ(marked[0].node, "c");
}

TEST(CrashMarkerTest, LinesThatDoNotParseAreSkipped) {
  const test::ScratchDir scratch("crash-marker");
  const auto marker = test::write_file(
      scratch / "crash-marker", "11\tfit\tabc\nnot a line\n\t\t\nx1\tn\tk\n6\tn\t\n6\tscale\tdef");
  const std::vector<MarkedCrash> crashes = read_crash_marker(marker);
  ASSERT_EQ(crashes.size(), 2U);
  EXPECT_EQ(crashes[0].node, "fit");
  EXPECT_EQ(crashes[1].cache_key, "def");
  EXPECT_TRUE(read_crash_marker(scratch / "absent").empty());
}

TEST(CrashMarkerTest, TheHandlersFoundBeforeAreRestored) {
  struct sigaction before {};
  ::sigaction(SIGSEGV, nullptr, &before);
  {
    const CrashHandlers outer;
    const CrashHandlers inner;
    struct sigaction during {};
    ::sigaction(SIGSEGV, nullptr, &during);
    EXPECT_NE(during.sa_flags & SA_SIGINFO, 0);
  }
  struct sigaction after {};
  ::sigaction(SIGSEGV, nullptr, &after);
  EXPECT_EQ(after.sa_flags & SA_SIGINFO, before.sa_flags & SA_SIGINFO);
  EXPECT_EQ(reinterpret_cast<void*>(after.sa_sigaction),
            reinterpret_cast<void*>(before.sa_sigaction));
}

}  // namespace
}  // namespace mmm::workflow
