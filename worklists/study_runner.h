#pragma once
// Running a study with its worklist: run_study (workflow/run/run_study.h),
// then open the tasks of the manual nodes that wait for a person. `mmm run`,
// `mmm task submit` (continuing after an accepted submission) and `mmm serve`
// (resuming within a second of an acceptance) all go through here.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "workflow/run/run_study.h"
#include "workflow/study/study.h"
#include "worklists/task.h"

namespace mmm::worklists {

struct StudyRunResult {
  bool locked = false;      // another runner holds the study: nothing was run
  std::string lock_holder;  // who, when locked (the lock error's text)
  std::optional<workflow::RunSummary> summary;
  std::vector<Task> opened;  // tasks opened after the run
};

// How long a runner waits for the study lock by default: `mmm status` and
// the web server's listings hold it for a moment while they refresh changed
// inputs, which must not make a run or a task's resume give up.
inline constexpr std::chrono::milliseconds kBriefLockWait{5000};

// Takes the study's runner lock (waiting up to `wait`), runs it and opens
// the tasks. When the lock is held by another runner, returns locked = true
// without running.
StudyRunResult run_study_with_tasks(workflow::Study& study, const workflow::RunOptions& options,
                                    std::chrono::milliseconds wait = kBriefLockWait);

}  // namespace mmm::worklists
