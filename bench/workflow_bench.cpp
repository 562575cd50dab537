// Suite `workflow`: the engine's own cost, measured on a 1,000-node workflow
// of no-op nodes (10 layers of 100; each node takes the output of one node of
// the layer before and stores one small artifact). Run with
// `bench/run workflow`; ns/item is the time per node.
//
//   first_run_j1    create nothing, run everything: schedule, cache-key,
//                   store the output, record the execution (group commit)
//   first_run_j2    the same on two worker threads
//   no_change_rerun open the finished study and run it again: everything is
//                   a cache hit (the "does nothing in under a second" case)
//   plan            what `mmm status` computes: every node's state and reason

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "workflow/node_registry.h"
#include "workflow/run/run_study.h"
#include "workflow/run/study_plan.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/study.h"

namespace {

using mmm::workflow::NodeContext;
using mmm::workflow::NodeRegistry;
using mmm::workflow::NodeSpec;
using mmm::workflow::Study;
using mmm::workflow::StudyLock;

constexpr int kLayers = 10;
constexpr int kWidth = 100;
constexpr int kNodes = kLayers * kWidth;

const NodeRegistry& registry() {
  static const NodeRegistry kRegistry = [] {
    NodeRegistry r;
    r.add(NodeSpec{"noop", 1, "Passes its index on"}
              .optional_input<mmm::workflow::port::Integer>("previous", "Upstream value")
              .param<std::int64_t>("index", 0, "Node number")
              .output<mmm::workflow::port::Integer>("value", "The index"),
          [](NodeContext& context) {
            context.set_output("value", std::to_string(context.integer("index")));
          });
    return r;
  }();
  return kRegistry;
}

std::filesystem::path bench_root() {
  static const std::filesystem::path kRoot = [] {
    std::random_device random;
    std::filesystem::path root =
        std::filesystem::temp_directory_path() / ("mmm-bench-workflow-" + std::to_string(random()));
    std::filesystem::create_directories(root);
    return root;
  }();
  return kRoot;
}

std::filesystem::path workflow_file() {
  std::filesystem::path file = bench_root() / "noop1000.yaml";
  if (std::filesystem::exists(file)) return file;
  std::ofstream out(file);
  out << "mmm_workflow: 1\nname: noop1000\nnodes:\n";
  for (int layer = 0; layer < kLayers; ++layer) {
    for (int i = 0; i < kWidth; ++i) {
      const int index = layer * kWidth + i;
      out << "  - id: n" << index << "\n    type: noop\n    params: {index: " << index << "}\n";
      if (layer > 0) out << "    inputs: {previous: n" << index - kWidth << ".value}\n";
    }
  }
  out << "outputs:\n  last: n" << kNodes - 1 << ".value\n";
  return file;
}

std::filesystem::path fresh_study_dir() {
  static int counter = 0;
  return bench_root() / ("study-" + std::to_string(counter++));
}

void run_once(const std::filesystem::path& dir, int jobs) {
  Study study = Study::open(dir, registry());
  const StudyLock lock = StudyLock::acquire(dir, std::chrono::milliseconds(0));
  mmm::workflow::RunOptions options;
  options.jobs = jobs;
  options.provenance = {"bench", "bench"};
  const mmm::workflow::RunSummary summary = mmm::workflow::run_study(study, lock, options);
  benchmark::DoNotOptimize(summary.executed.size());
}

void first_run(benchmark::State& state) {
  const int jobs = static_cast<int>(state.range(0));
  for (auto _ : state) {
    state.PauseTiming();
    const std::filesystem::path dir = fresh_study_dir();
    Study::create(dir, {workflow_file(), {}, {"bench", "bench"}}, registry());
    state.ResumeTiming();
    run_once(dir, jobs);
    state.PauseTiming();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kNodes);
}
BENCHMARK(first_run)
    ->Name("first_run_j1")
    ->Arg(1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(first_run)
    ->Name("first_run_j2")
    ->Arg(2)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

const std::filesystem::path& finished_study() {
  static const std::filesystem::path kDir = [] {
    std::filesystem::path dir = fresh_study_dir();
    Study::create(dir, {workflow_file(), {}, {"bench", "bench"}}, registry());
    run_once(dir, 1);
    return dir;
  }();
  return kDir;
}

void no_change_rerun(benchmark::State& state) {
  const std::filesystem::path& dir = finished_study();
  for (auto _ : state) run_once(dir, 1);
  state.SetItemsProcessed(state.iterations() * kNodes);
}
BENCHMARK(no_change_rerun)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

void plan(benchmark::State& state) {
  const std::filesystem::path& dir = finished_study();
  for (auto _ : state) {
    Study study = Study::open(dir, registry());
    const mmm::workflow::StudyPlan result = mmm::workflow::plan_study(study, false);
    benchmark::DoNotOptimize(result.nodes.size());
  }
  state.SetItemsProcessed(state.iterations() * kNodes);
}
BENCHMARK(plan)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ignored;
  std::filesystem::remove_all(bench_root(), ignored);
  return 0;
}
