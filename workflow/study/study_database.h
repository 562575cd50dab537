#pragma once
// The tables of a study database (study.db) and their format version.
//
//   meta(key, value)                 provenance and facts about the study
//   inputs(name, ...)                study inputs: type, content hash, origin
//   param_overrides(node, param, ..) parameters set with `mmm study set`
//   runs(id, ...)                    one row per `mmm run`: who, where, outcome
//   executions(id, ...)              one row per node execution (or manual
//                                    result): cache key, outputs, status,
//                                    times, error, reason it ran
//   logs(execution_id, ...)          log lines of each execution
//   crashes(node, cache_key, ...)    nodes that crashed the process, with the
//                                    signal (not run again with that key)
//   exports(name, hash, file)        the exported outputs currently in outputs/

#include "workflow/store/sqlite.h"

namespace mmm::workflow {

// Version of the table layout written into meta.format.
inline constexpr int kStudyFormat = 1;

// Creates the tables (first use) and checks the format of an existing study
// database; throws IoError naming the file when it was written by an
// incompatible version.
void prepare_study_database(Database& database);

}  // namespace mmm::workflow
