// Cohort creation from the patients file, and the cohort's status from each
// study's database without opening the study (no workflow load, no locks).

#include "worklists/cohort.h"

#include <csignal>

#include <cerrno>

#include "core/errors.h"
#include "workflow/definition/workflow_loader.h"
#include "workflow/host_and_time.h"
#include "workflow/store/shared_store.h"
#include "workflow/store/sqlite.h"
#include "workflow/store/study_lock.h"
#include "worklists/cohort_patients.h"
#include "worklists/task_store.h"
#include "worklists/worklist.h"

namespace mmm::worklists {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStudyDatabase = "study.db";

// Seconds between two recorded times (0 when either is unreadable).
double seconds_between(const std::string& from, const std::string& to) {
  const double a = utc_seconds(from);
  const double b = utc_seconds(to);
  return a <= 0 || b <= 0 ? 0.0 : b - a;
}

// A runner holds the study: its lock file names a live process of this
// machine (a record left by a killed runner names a dead one). Read only:
// probing the lock itself could make a runner starting now fail to get it.
bool runner_alive(const fs::path& study) {
  const std::optional<workflow::StudyLockHolder> holder = workflow::StudyLock::read_holder(study);
  if (!holder || holder->pid <= 0) return false;
  if (holder->host != workflow::host_name()) return true;  // another machine: trust it
  return ::kill(static_cast<pid_t>(holder->pid), 0) == 0 || errno == EPERM;
}

std::string first_line(const std::string& text) {
  const std::size_t end = text.find('\n');
  std::string line = end == std::string::npos ? text : text.substr(0, end);
  if (line.size() > 200) line = line.substr(0, 197) + "...";
  return line;
}

}  // namespace

CohortCreateResult create_cohort(const fs::path& root, const CohortCreateOptions& options,
                                 const workflow::NodeRegistry& registry) {
  const workflow::LoadResult loaded = workflow::load_workflow(options.workflow_file, registry);
  if (!loaded.valid()) {
    std::string all;
    for (const workflow::Diagnostic& d : loaded.diagnostics) all += "\n  " + d.text();
    throw InvalidInputError("cohort create: the workflow " + options.workflow_file.string() +
                            " has " + std::to_string(loaded.diagnostics.size()) +
                            " problem(s):" + all + "\nhint: check it with 'mmm validate " +
                            options.workflow_file.string() + "'");
  }
  const std::vector<CohortPatient> patients =
      read_cohort_patients(options.patients_csv, loaded.definition, options.shared_inputs);
  CohortCreateResult result;
  result.store = workflow::create_shared_store(root);
  for (const CohortPatient& patient : patients) {
    const fs::path dir = root / patient.id;
    std::error_code error;
    if (fs::exists(dir / kStudyDatabase, error)) {
      result.existing.push_back(patient.id);
      continue;
    }
    try {
      (void)workflow::Study::create(
          dir, {options.workflow_file, patient.inputs, options.provenance}, registry);
    } catch (const std::exception& failure) {
      throw IoError(dir, "cohort create: the study of line " + std::to_string(patient.line) + " (" +
                             patient.id + ") could not be created: " + failure.what() +
                             "\nhint: the studies before it are created; fix this row and run "
                             "the command again to create the rest");
    }
    result.created.push_back(patient.id);
  }
  return result;
}

CohortStatus cohort_status(const fs::path& root) {
  CohortStatus status;
  for (const fs::path& dir : find_studies(root)) {
    CohortStudyState study;
    study.study = dir.lexically_relative(root).generic_string();
    workflow::Database database(dir / kStudyDatabase);
    workflow::Statement last = database.prepare(
        "SELECT id, status, started_at, COALESCE(finished_at, '') FROM runs ORDER BY id DESC "
        "LIMIT 1");
    std::int64_t run_id = 0;
    const bool running = runner_alive(dir);
    if (!last.step()) {
      study.state = running ? "running" : "created";
    } else {
      run_id = last.column_int64(0);
      study.state = last.column_text(1);
      study.last_run_finished_at = last.column_text(3);
      study.last_run_seconds = seconds_between(last.column_text(2), study.last_run_finished_at);
      if (running) {
        study.state = "running";
      } else if (study.last_run_finished_at.empty()) {
        study.state = "interrupted";
      }
    }
    if (study.state == "failed") {
      workflow::Statement failed = database.prepare(
          "SELECT node, error FROM executions WHERE run_id = ? AND status = 'failed' ORDER BY "
          "id LIMIT 1");
      failed.bind_int64(1, run_id);
      if (failed.step()) {
        study.detail = failed.column_text(0) + ": " + first_line(failed.column_text(1));
      }
    }
    if (tasks_table_exists(database)) {
      workflow::Statement tasks = database.prepare(
          "SELECT node, state, assignee FROM tasks WHERE state NOT IN ('accepted', 'cancelled') "
          "ORDER BY created_at");
      while (tasks.step()) {
        const std::string assignee = tasks.column_text(2);
        ++status.waiting_on[assignee];
        if (study.state == "waiting") {
          study.detail += (study.detail.empty() ? "" : "; ") + tasks.column_text(0) + " " +
                          tasks.column_text(1) +
                          (assignee.empty() ? " (any operator)" : " by " + assignee);
        }
      }
    }
    ++status.counts[study.state];
    status.studies.push_back(std::move(study));
  }
  return status;
}

}  // namespace mmm::worklists
