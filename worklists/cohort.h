#pragma once
// A cohort: many studies of one workflow under one root folder, created
// from a patients file, sharing one artifact store (shared_store.h), and
// followed as one piece of work (`mmm cohort create|status`; `mmm cohort
// run` drives them, app/commands/cohort_commands.cpp).
//
//   ROOT/.mmm-store/   the shared store
//   ROOT/<id>/         one study per patient (its own study.db and audit)

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "workflow/node_registry.h"
#include "workflow/study/study.h"

namespace mmm::worklists {

struct CohortCreateOptions {
  std::filesystem::path workflow_file;
  std::filesystem::path patients_csv;
  std::map<std::string, std::string> shared_inputs;  // --input NAME=VALUE for every row
  workflow::Provenance provenance;
};

struct CohortCreateResult {
  std::vector<std::string> created;
  std::vector<std::string> existing;  // a study folder already there: left as it is
  std::filesystem::path store;
};

// Checks the workflow and every row first (nothing is created when one is
// wrong: read_cohort_patients); then creates the shared store and, in row
// order, each study not yet there. Throws InvalidInputError / IoError naming
// the file and line, or the study that could not be created (the ones
// before it stay: re-running the command creates the rest).
CohortCreateResult create_cohort(const std::filesystem::path& root,
                                 const CohortCreateOptions& options,
                                 const workflow::NodeRegistry& registry);

// Where one study of a cohort stands, from its database (read only).
struct CohortStudyState {
  std::string study;  // relative to the root
  // "created" (never run), "running", "waiting" (for an operator), "done",
  // "failed".
  std::string state;
  std::string detail;  // the failed node and its error; the waiting tasks and who holds them
  std::string last_run_finished_at;
  double last_run_seconds = 0;
};

struct CohortStatus {
  std::vector<CohortStudyState> studies;
  std::map<std::string, int> counts;  // per state
  // Operator -> tasks they hold (claimed or submitted); "" for open tasks
  // anyone may take.
  std::map<std::string, int> waiting_on;
};

// Throws IoError when root is not a folder.
CohortStatus cohort_status(const std::filesystem::path& root);

}  // namespace mmm::worklists
