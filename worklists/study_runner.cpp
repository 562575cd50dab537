#include "worklists/study_runner.h"

#include "workflow/store/study_lock.h"
#include "worklists/task_actions.h"

namespace mmm::worklists {

StudyRunResult run_study_with_tasks(workflow::Study& study, const workflow::RunOptions& options,
                                    std::chrono::milliseconds wait) {
  StudyRunResult result;
  std::optional<workflow::StudyLock> lock;
  try {
    lock.emplace(workflow::StudyLock::acquire(study.dir(), wait));
  } catch (const workflow::StudyLockedError& error) {
    result.locked = true;
    result.lock_holder = error.what();
    return result;
  }
  prepare_worklist_tables(study);
  result.summary = workflow::run_study(study, *lock, options);
  result.opened =
      open_waiting_tasks(study, {kSystemOperator, options.provenance.mmm_version.empty()
                                                      ? std::string("unknown")
                                                      : options.provenance.mmm_version});
  return result;
}

}  // namespace mmm::worklists
