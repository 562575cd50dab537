// Suite `cohort`: following a cohort of 1,000 studies. Each study has run
// (one no-op node: a runs row, an execution) and holds one open landmark
// task, as studies waiting for an operator do. Run with `bench/run cohort`.
//
//   cohort_status_1000  `mmm cohort status`: every study's state, its
//                       failures and waiting tasks, from its database
//   worklist_1000       `mmm worklist`: the open tasks across the root

#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "workflow/node_registry.h"
#include "workflow/run/run_study.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/study.h"
#include "worklists/cohort.h"
#include "worklists/task_store.h"
#include "worklists/worklist.h"

namespace {

namespace fs = std::filesystem;
using mmm::workflow::Study;

constexpr int kStudies = 1000;

const mmm::workflow::NodeRegistry& registry() {
  static const mmm::workflow::NodeRegistry kRegistry = [] {
    mmm::workflow::NodeRegistry r;
    r.add(mmm::workflow::NodeSpec{"noop", 1, "Passes a number on"}
              .output<mmm::workflow::port::Integer>("value", "1"),
          [](mmm::workflow::NodeContext& context) { context.set_output("value", "1"); });
    return r;
  }();
  return kRegistry;
}

const fs::path& cohort_root() {
  static const fs::path kRoot = [] {
    std::random_device random;
    const fs::path base =
        fs::temp_directory_path() / ("mmm-bench-cohort-" + std::to_string(random()));
    fs::create_directories(base / "root");
    const fs::path workflow = base / "one.yaml";
    std::ofstream(workflow) << "mmm_workflow: 1\nname: one\nnodes:\n  - {id: n, type: noop}\n";
    for (int k = 0; k < kStudies; ++k) {
      const fs::path dir = base / "root" / ("p" + std::to_string(1000 + k));
      Study study = Study::create(dir, {workflow, {}, {"bench", "bench"}}, registry());
      {
        const auto lock = mmm::workflow::StudyLock::acquire(dir, std::chrono::milliseconds(0));
        (void)mmm::workflow::run_study(study, lock, {.jobs = 1, .provenance = {"bench", "bench"}});
      }
      mmm::worklists::prepare_task_tables(study.database());
      mmm::worklists::Task task;
      task.id = mmm::worklists::new_task_id();
      task.node = "landmarks";
      task.node_type = "landmark_station";
      task.cache_key = std::string(64, 'a');
      task.created_at = "2026-11-29T10:00:00.000Z";
      task.updated_at = task.created_at;
      task.request = {{"kind", "landmarks"}};
      mmm::worklists::insert_task(study.database(), task);
    }
    return base / "root";
  }();
  return kRoot;
}

void cohort_status_1000(benchmark::State& state) {
  const fs::path& root = cohort_root();
  for (auto _ : state) {
    const mmm::worklists::CohortStatus status = mmm::worklists::cohort_status(root);
    if (status.studies.size() != kStudies) state.SkipWithError("not every study was read");
    benchmark::DoNotOptimize(status.counts.size());
  }
  state.SetItemsProcessed(state.iterations() * kStudies);
}
BENCHMARK(cohort_status_1000)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

void worklist_1000(benchmark::State& state) {
  const fs::path& root = cohort_root();
  for (auto _ : state) {
    const auto entries = mmm::worklists::list_worklist(root);
    if (entries.size() != kStudies) state.SkipWithError("not every task was listed");
    benchmark::DoNotOptimize(entries.size());
  }
  state.SetItemsProcessed(state.iterations() * kStudies);
}
BENCHMARK(worklist_1000)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ignored;
  fs::remove_all(cohort_root().parent_path(), ignored);
  return 0;
}
