// mmm cohort create|run|status, mmm gc: many studies under one root.
//
// `cohort run` drives every study to its next manual step or to the end by
// running `mmm run STUDY` in child processes, -j at a time (each run is the
// ordinary restartable run: killing the coordinator kills its runs, which
// the next `cohort run` resumes). Each run's output goes to
// ROOT/.mmm-cohort/logs/<study>.log.

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "app/report/cohort_report_page.h"
#include "core/errors.h"
#include "worklists/cohort.h"
#include "worklists/root_gc.h"
#include "worklists/worklist.h"

namespace mmm::app {
namespace {

namespace fs = std::filesystem;
using CohortJson = nlohmann::json;

struct CohortCreateArgs {
  std::string root;
  std::string workflow;
  std::string patients;
  std::vector<std::string> inputs;
};

void run_cohort_create(const CohortCreateArgs& args, const workflow::NodeRegistry& registry) {
  worklists::CohortCreateOptions options;
  options.workflow_file = args.workflow;
  options.patients_csv = args.patients;
  options.provenance = this_program();
  for (const std::string& input : args.inputs) {
    auto [name, value] = split_assignment(input, "--input");
    if (!options.shared_inputs.emplace(name, value).second) {
      throw InvalidInputError("--input " + name + " is given twice");
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const worklists::CohortCreateResult result =
      worklists::create_cohort(args.root, options, registry);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "cohort " << args.root << ": " << result.created.size() << " studies created";
  if (!result.existing.empty()) std::cout << ", " << result.existing.size() << " already there";
  std::cout << " in " << std::fixed << std::setprecision(1) << seconds << " s; shared store "
            << result.store.string() << "\nnext: mmm cohort run " << args.root << " -j 2\n";
}

struct CohortRunArgs {
  std::string root;
  int jobs = 2;
  std::string executor = "local";
  int node_jobs = 4;  // Slurm jobs out at once per study
  std::vector<std::string> slurm_args;
};

struct CohortRunningStudy {
  std::string study;
  std::chrono::steady_clock::time_point started;
};

// Starts `mmm run DIR --quiet` with its output in `log`; the child dies with
// the coordinator (PR_SET_PDEATHSIG), so a killed coordinator leaves no run
// behind that the next one would wait for.
pid_t start_study_run(const fs::path& exe, const fs::path& study, const fs::path& log,
                      const CohortRunArgs& args) {
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw IoError(study, std::string("cannot start a run: fork: ") + strerror(errno));
  if (pid > 0) return pid;
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);  // the coordinator died before the prctl
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd >= 0) {
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
  }
  const std::string exe_text = exe.string();
  const std::string dir_text = study.string();
  std::vector<std::string> words = {exe_text, "run", dir_text, "--quiet"};
  if (args.executor == "slurm") {
    words.insert(words.end(), {"--executor", "slurm", "-j", std::to_string(args.node_jobs)});
    for (const std::string& extra : args.slurm_args) words.push_back("--slurm-arg=" + extra);
  }
  std::vector<char*> argv;
  argv.reserve(words.size() + 1);
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  ::execv(exe_text.c_str(), argv.data());
  ::_exit(127);
}

std::string run_outcome_of(int status) {
  if (WIFSIGNALED(status))
    return "failed (killed by signal " + std::to_string(WTERMSIG(status)) + ")";
  switch (WEXITSTATUS(status)) {
    case kExitOk:
      return "done";
    case kExitWaiting:
      return "waiting";
    case kExitLocked:
      return "busy";
    default:
      return "failed";
  }
}

void run_cohort(const CohortRunArgs& args) {
  const fs::path root = args.root;
  const std::vector<fs::path> studies = worklists::find_studies(root);
  if (studies.empty()) {
    throw InvalidInputError("no study under " + root.string() + "; hint: mmm cohort create " +
                            root.string() + " --workflow WF --patients patients.csv");
  }
  const fs::path logs = root / ".mmm-cohort" / "logs";
  fs::create_directories(logs);
  const fs::path exe = this_executable_path();
  std::map<pid_t, CohortRunningStudy> running;
  std::map<std::string, int> counts;
  std::vector<double> seconds;
  std::size_t next = 0;
  std::size_t finished = 0;
  const auto start = std::chrono::steady_clock::now();
  while (next < studies.size() || !running.empty()) {
    while (next < studies.size() && static_cast<int>(running.size()) < args.jobs) {
      const fs::path& dir = studies[next++];
      std::string name = dir.lexically_relative(root).generic_string();
      std::string log_name = name;
      std::replace(log_name.begin(), log_name.end(), '/', '_');
      const pid_t pid = start_study_run(exe, dir, logs / (log_name + ".log"), args);
      running.emplace(pid, CohortRunningStudy{std::move(name), std::chrono::steady_clock::now()});
    }
    int status = 0;
    const pid_t done = ::waitpid(-1, &status, 0);
    if (done < 0) {
      if (errno == EINTR) continue;
      throw IoError(root, std::string("waiting for the runs: ") + strerror(errno));
    }
    const auto it = running.find(done);
    if (it == running.end()) continue;
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.started)
            .count();
    const std::string outcome = run_outcome_of(status);
    ++counts[outcome.substr(0, outcome.find(' '))];
    seconds.push_back(took);
    ++finished;
    std::cout << "[" << finished << "/" << studies.size() << "] " << it->second.study << ": "
              << outcome << " in " << std::fixed << std::setprecision(1) << took << " s\n"
              << std::flush;
    running.erase(it);
  }
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::sort(seconds.begin(), seconds.end());
  std::cout << "cohort " << args.root << ": " << studies.size() << " studies in " << std::fixed
            << std::setprecision(1) << total << " s (-j " << args.jobs << ", " << args.executor
            << ", median " << seconds[seconds.size() / 2] << " s per study):";
  for (const auto& [state, count] : counts) std::cout << ' ' << count << ' ' << state;
  std::cout << "\nlogs: " << logs.string() << "; next: mmm cohort status " << args.root << '\n';
  if (counts.contains("failed")) {
    set_exit_code(kExitFailed);
  } else if (counts.contains("waiting") || counts.contains("busy")) {
    set_exit_code(kExitWaiting);
  }
}

struct CohortStatusArgs {
  std::string root;
  bool json = false;
};

void run_cohort_status(const CohortStatusArgs& args) {
  const worklists::CohortStatus status = worklists::cohort_status(args.root);
  if (args.json) {
    CohortJson out;
    out["counts"] = status.counts;
    out["waiting_on"] = status.waiting_on;
    CohortJson studies = CohortJson::array();
    for (const worklists::CohortStudyState& study : status.studies) {
      studies.push_back({{"study", study.study},
                         {"state", study.state},
                         {"detail", study.detail},
                         {"last_run_finished_at", study.last_run_finished_at},
                         {"last_run_seconds", study.last_run_seconds}});
    }
    out["studies"] = std::move(studies);
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << status.studies.size() << " studies:";
  for (const auto& [state, count] : status.counts) std::cout << ' ' << count << ' ' << state;
  std::cout << '\n';
  if (!status.waiting_on.empty()) {
    std::cout << "open tasks:";
    for (const auto& [who, count] : status.waiting_on) {
      std::cout << ' ' << count << (who.empty() ? " for any operator" : " held by " + who) << ';';
    }
    std::cout << '\n';
  }
  for (const worklists::CohortStudyState& study : status.studies) {
    if (study.state == "done" || study.state == "created") continue;
    std::cout << "  " << std::left << std::setw(24) << study.study << std::setw(12) << study.state
              << study.detail << '\n';
  }
}

struct CohortReportArgs {
  std::string root;
  std::string out;
};

void run_cohort_report(const CohortReportArgs& args) {
  const fs::path out =
      args.out.empty() ? fs::path(args.root) / "cohort_report" : fs::path(args.out);
  const report::CohortReportResult result = report::write_cohort_report(args.root, out);
  std::cout << "cohort report of " << result.studies << " studies (" << result.outliers
            << " outlier figures): " << result.index.string() << '\n';
}

struct CollectArgs {
  std::string root;
  bool apply = false;
  double grace_minutes = 60;
  bool json = false;
};

double mebibytes_of(std::uintmax_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

void run_collect_garbage(const CollectArgs& args) {
  worklists::GcOptions options;
  options.apply = args.apply;
  options.grace = std::chrono::seconds(static_cast<long>(args.grace_minutes * 60));
  const worklists::GcReport report = worklists::collect_garbage(args.root, options);
  if (args.json) {
    CohortJson out = {{"applied", report.applied},
                      {"studies", report.studies},
                      {"busy_studies", report.busy_studies},
                      {"study_blobs", report.study_blobs.size()},
                      {"shared_blobs", report.shared_blobs.size()},
                      {"freed_bytes", report.freed_bytes},
                      {"kept_bytes", report.kept_bytes}};
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << std::fixed << std::setprecision(1) << (report.applied ? "removed " : "would remove ")
            << report.study_blobs.size() << " unreferenced blobs from " << report.studies
            << " studies and " << report.shared_blobs.size()
            << " from the shared store: " << mebibytes_of(report.freed_bytes) << " MB freed, "
            << mebibytes_of(report.kept_bytes) << " MB kept\n";
  for (const std::string& busy : report.busy_studies) {
    std::cout << "  skipped " << busy << ": a runner holds it\n";
  }
  if (!report.applied && (!report.study_blobs.empty() || !report.shared_blobs.empty())) {
    std::cout << "a dry run: nothing was removed; mmm gc " << args.root << " --apply removes it\n";
  }
}

}  // namespace

void register_cohort_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto* cohort = app.add_subcommand(
      "cohort", "Many patients as one piece of work: create, run and follow the studies of a root");
  cohort->require_subcommand(1);

  auto create_args = std::make_shared<CohortCreateArgs>();
  auto* create = cohort->add_subcommand(
      "create", "Create one study per row of a patients file (id and study inputs) under ROOT");
  create->add_option("ROOT", create_args->root, "Root folder of the cohort")->required();
  create->add_option("--workflow,-w", create_args->workflow, "Workflow file (.yaml)")->required();
  create
      ->add_option("--patients", create_args->patients,
                   "CSV file: a header 'id,INPUT,...', one row per patient; paths relative to it")
      ->required();
  create->add_option("--input,-i", create_args->inputs,
                     "Study input NAME=VALUE for every patient (e.g. the atlas); repeatable");
  create->callback([create_args, &registry] { run_cohort_create(*create_args, registry); });

  auto run_args = std::make_shared<CohortRunArgs>();
  auto* run = cohort->add_subcommand(
      "run", "Run every study of ROOT to its next manual step or to the end (re-run to continue)");
  run->add_option("ROOT", run_args->root, "Root folder of the cohort")->required();
  run->add_option("--jobs,-j", run_args->jobs, "Studies run at the same time")
      ->check(CLI::Range(1, 1024));
  run->add_option("--executor", run_args->executor,
                  "Where the nodes run: local (here) or slurm (each node a Slurm job; needs a "
                  "shared file system)")
      ->check(CLI::IsMember({"local", "slurm"}));
  run->add_option("--node-jobs", run_args->node_jobs,
                  "With slurm: jobs out at once per study (default 4)")
      ->check(CLI::Range(1, 256));
  run->add_option("--slurm-arg", run_args->slurm_args,
                  "With slurm: an extra srun argument for every job (e.g. --partition=short); "
                  "repeatable");
  run->callback([run_args] { run_cohort(*run_args); });

  auto status_args = std::make_shared<CohortStatusArgs>();
  auto* status = cohort->add_subcommand(
      "status", "Per state counts, who is waiting on whom, failures with their error");
  status->add_option("ROOT", status_args->root, "Root folder of the cohort")->required();
  status->add_flag("--json", status_args->json, "Machine-readable output");
  status->callback([status_args] { run_cohort_status(*status_args); });

  auto report_args = std::make_shared<CohortReportArgs>();
  auto* report_command = cohort->add_subcommand(
      "report",
      "One offline page across the cohort: distributions, outliers, operators, throughput");
  report_command->add_option("ROOT", report_args->root, "Root folder of the cohort")->required();
  report_command->add_option("-o,--out", report_args->out,
                             "Report folder (default: ROOT/cohort_report)");
  report_command->callback([report_args] { run_cohort_report(*report_args); });

  auto gc_args = std::make_shared<CollectArgs>();
  auto* gc = app.add_subcommand(
      "gc", "Remove the artifacts no study under ROOT references (a dry run unless --apply)");
  gc->add_option("ROOT", gc_args->root, "Root folder of the studies")->required();
  gc->add_flag("--apply", gc_args->apply, "Remove them (otherwise only report)");
  gc->add_option("--grace-minutes", gc_args->grace_minutes,
                 "Keep blobs written or linked within the last MINUTES (default 60)")
      ->check(CLI::Range(0.0, 1e6));
  gc->add_flag("--json", gc_args->json, "Machine-readable output");
  gc->callback([gc_args] { run_collect_garbage(*gc_args); });
}

}  // namespace mmm::app
