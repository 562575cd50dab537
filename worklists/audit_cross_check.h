#pragma once
// Cross-checks of a study's tasks against its audit trail (audit_verify.h
// runs them after checking the chain itself): the chain proves what was
// recorded, these show whether the tables and artifacts the study uses still
// say the same.
//
//   every task in the tasks table     was opened by an entry of the chain
//                                     (kTaskUnaudited otherwise: the chain was
//                                     emptied or the task was forged);
//   an accepted task's values         equal the `after` of its last accept or
//                                     correct entry (kValueMismatch otherwise:
//                                     the tasks table was edited);
//   the artifacts of its result       still hold the bytes they are named by
//                                     (kArtifactChanged otherwise: a stored
//                                     result was edited in place).

#include <filesystem>
#include <vector>

#include "workflow/store/sqlite.h"
#include "worklists/audit_verify.h"

namespace mmm::worklists {

// The problems found (none when the study has no tasks table). Reads only.
std::vector<AuditProblem> cross_check_tasks(workflow::Database& database,
                                            const std::filesystem::path& study_dir);

}  // namespace mmm::worklists
