// mmm study create|set, mmm run: making and running studies.

#include <unistd.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "app/commands/study_report.h"
#include "core/errors.h"
#include "workflow/run/progress_display.h"
#include "workflow/run/run_study.h"
#include "workflow/study/study.h"
#include "worklists/study_runner.h"

namespace mmm::app {
namespace {

struct CreateArgs {
  std::string dir;
  std::string workflow;
  std::vector<std::string> inputs;
};

void run_create(const CreateArgs& args, const workflow::NodeRegistry& registry) {
  workflow::CreateStudyOptions options;
  options.workflow_file = args.workflow;
  options.provenance = this_program();
  for (const std::string& input : args.inputs) {
    auto [name, value] = split_assignment(input, "--input");
    if (options.inputs.contains(name)) {
      throw InvalidInputError("--input " + name + " is given twice");
    }
    options.inputs.emplace(std::move(name), std::move(value));
  }
  workflow::Study study = workflow::Study::create(args.dir, options, registry);
  std::cout << "created study " << study.dir().string() << " (workflow '" << study.workflow().name
            << "', " << study.workflow().nodes.size() << " nodes, " << study.inputs().size()
            << " inputs)\nnext: mmm run " << args.dir << '\n';
}

struct SetArgs {
  std::string dir;
  std::vector<std::string> assignments;
};

void run_set(const SetArgs& args, const workflow::NodeRegistry& registry) {
  workflow::Study study = workflow::Study::open(args.dir, registry);
  for (const std::string& assignment : args.assignments) {
    const auto [target, value] = split_assignment(assignment, "setting");
    const std::size_t dot = target.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == target.size()) {
      throw InvalidInputError("setting '" + assignment +
                              "' must be NODE.PARAM=VALUE or study.INPUT=VALUE");
    }
    const std::string owner = target.substr(0, dot);
    const std::string name = target.substr(dot + 1);
    if (owner == workflow::kStudyNode) {
      const bool changed = study.set_input(name, value);
      std::cout << "study input '" << name << "' " << (changed ? "set" : "unchanged (same content)")
                << '\n';
    } else {
      study.set_param(owner, name, value);
      std::cout << "parameter " << owner << "." << name << " = " << value << '\n';
    }
  }
  std::cout << "next: mmm status " << args.dir << " (what will re-run), mmm run " << args.dir
            << '\n';
}

struct RunArgs {
  std::string dir;
  int jobs = 1;
  double wait_seconds = std::chrono::duration<double>(worklists::kBriefLockWait).count();
  bool quiet = false;
  bool show_cached = false;
  bool retry_crashed = false;
  std::string executor = "local";
  std::vector<std::string> slurm_args;
};

void print_summary(const workflow::RunSummary& summary, const std::string& dir) {
  const auto list = [](const std::vector<std::string>& nodes) {
    std::string text;
    for (const std::string& node : nodes) text += (text.empty() ? "" : ", ") + node;
    return text;
  };
  if (summary.executed.empty() && summary.failed.empty() && summary.input_changes.empty()) {
    std::cout << "nothing to do: " << summary.cached.size() << " node(s) up to date (cached)";
  } else {
    std::cout << summary.executed.size() << " node(s) ran, " << summary.cached.size() << " cached";
    if (!summary.failed.empty()) std::cout << ", " << summary.failed.size() << " failed";
  }
  std::cout << " in " << std::fixed << std::setprecision(summary.seconds < 1 ? 3 : 1)
            << summary.seconds << " s\n";
  if (!summary.exported.empty()) {
    std::cout << "exported to " << dir << "/outputs: " << list(summary.exported) << '\n';
  }
  switch (summary.outcome) {
    case workflow::RunOutcome::kDone:
      std::cout << "study done\n";
      break;
    case workflow::RunOutcome::kWaiting:
      std::cout << "study waiting for a person: " << list(summary.waiting)
                << " (manual); blocked until then: " << list(summary.blocked) << '\n';
      break;
    case workflow::RunOutcome::kFailed:
      std::cerr << "study failed: " << list(summary.failed);
      if (!summary.blocked.empty()) std::cerr << "; not reached: " << list(summary.blocked);
      std::cerr << "\nhint: 'mmm explain " << dir << " NODE' shows the error and the log; fix "
                << "the input or parameter ('mmm study set') and run again\n";
      break;
  }
}

void run_run(const RunArgs& args, const workflow::NodeRegistry& registry) {
  workflow::Study study = workflow::Study::open(args.dir, registry);
  const bool terminal = ::isatty(STDERR_FILENO) == 1 && !args.quiet;
  std::unique_ptr<workflow::RunObserver> display = workflow::make_progress_display(
      std::cerr, {.terminal = terminal, .show_cached = args.show_cached});
  workflow::RunOptions options;
  options.jobs = args.jobs;
  options.retry_crashed = args.retry_crashed;
  options.provenance = this_program();
  options.observer = args.quiet ? nullptr : display.get();
  if (args.executor == "slurm") {
    options.executor = workflow::Executor::kSlurm;
    options.slurm.executable = this_executable_path();
    options.slurm.srun_arguments = args.slurm_args;
  }
  const worklists::StudyRunResult result = worklists::run_study_with_tasks(
      study, options, std::chrono::milliseconds(static_cast<long>(args.wait_seconds * 1000)));
  if (result.locked) {
    std::cerr << "mmm: " << result.lock_holder
              << "\nhint: wait for it to finish, or run with --wait SECONDS to wait for it\n";
    set_exit_code(kExitLocked);
    return;
  }
  const workflow::RunSummary& summary = *result.summary;
  print_summary(summary, args.dir);
  for (const worklists::Task& task : result.opened) {
    std::cout << "task " << task.id << " opened for node '" << task.node
              << "': see 'mmm worklist', 'mmm task show " << task.id << "'\n";
  }
  switch (summary.outcome) {
    case workflow::RunOutcome::kDone:
      set_exit_code(kExitOk);
      break;
    case workflow::RunOutcome::kWaiting:
      set_exit_code(kExitWaiting);
      break;
    case workflow::RunOutcome::kFailed:
      set_exit_code(kExitFailed);
      break;
  }
}

}  // namespace

void register_study_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto* study = app.add_subcommand("study", "Create a study or change its inputs and parameters");
  study->require_subcommand(1);

  auto create_args = std::make_shared<CreateArgs>();
  auto* create = study->add_subcommand(
      "create", "Create a study folder from a workflow: copies it, imports the inputs");
  create->add_option("DIR", create_args->dir, "New study folder (must not exist or be empty)")
      ->required();
  create->add_option("--workflow,-w", create_args->workflow, "Workflow file (.yaml)")->required();
  create->add_option(
      "--input,-i", create_args->inputs,
      "Study input NAME=PATH (files), NAME=DIR (an atlas folder) or NAME=VALUE (numbers, "
      "text); repeatable");
  create->callback([create_args, &registry] { run_create(*create_args, registry); });

  auto set_args = std::make_shared<SetArgs>();
  auto* set = study->add_subcommand(
      "set", "Change a node parameter (NODE.PARAM=VALUE) or a study input (study.NAME=VALUE)");
  set->add_option("DIR", set_args->dir, "Study folder")->required();
  set->add_option("SETTING", set_args->assignments, "NODE.PARAM=VALUE or study.INPUT=VALUE")
      ->required();
  set->callback([set_args, &registry] { run_set(*set_args, registry); });

  auto run_args = std::make_shared<RunArgs>();
  auto* run = app.add_subcommand(
      "run", "Run a study: compute what is missing or out of date, reuse the rest");
  run->add_option("DIR", run_args->dir, "Study folder")->required();
  run->add_option("--jobs,-j", run_args->jobs, "Nodes run at the same time")
      ->check(CLI::Range(1, 256));
  run->add_option("--wait", run_args->wait_seconds,
                  "When another runner holds the study, wait up to SECONDS for it (default 5: "
                  "mmm status holds it for a moment)")
      ->check(CLI::Range(0.0, 1e6));
  run->add_option("--executor", run_args->executor,
                  "Where the nodes run: local (threads of this process) or slurm (each node a "
                  "Slurm job, -j of them at once; needs a shared file system)")
      ->check(CLI::IsMember({"local", "slurm"}));
  run->add_option("--slurm-arg", run_args->slurm_args,
                  "With --executor slurm: an extra srun argument for every job (e.g. "
                  "--partition=short, --time=60); repeatable");
  run->add_flag("--quiet,-q", run_args->quiet, "Print only the summary");
  run->add_flag("--show-cached", run_args->show_cached, "Print a line for every reused node");
  run->add_flag("--retry-crashed", run_args->retry_crashed,
                "Run again the nodes that crashed mmm with the same inputs and parameters "
                "(otherwise they are reported as failed)");
  run->callback([run_args, &registry] { run_run(*run_args, registry); });

  register_study_report_commands(app, registry);
}

}  // namespace mmm::app
