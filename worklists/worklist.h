#pragma once
// The worklist: the tasks of every study under a root folder, for operators
// (`mmm worklist`, the web page), and finding a task by its id.
//
// A study is any folder holding study.db, at most 4 levels below the root
// (artifacts/, outputs/ and scratch/ folders of studies are not entered).
// Listing opens each study's database read-only-in-spirit (no writes), so it
// never waits for a runner.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "workflow/store/sqlite.h"
#include "worklists/task.h"

namespace mmm::worklists {

struct WorklistEntry {
  std::filesystem::path study_dir;
  std::string study;    // path relative to the root, e.g. "cohort/patient_7"
  std::string patient;  // the study input 'patient' when there is one, else the folder name
  Task task;
  double age_seconds = 0;  // since the task opened
};

struct WorklistFilter {
  std::optional<std::string> assignee;  // only tasks assigned to this operator
  std::optional<TaskState> state;
  bool include_closed = false;  // also accepted and cancelled tasks (default: only open work)
};

// Every study folder under `root`, sorted. Throws IoError when root is not a
// folder.
std::vector<std::filesystem::path> find_studies(const std::filesystem::path& root);

// The tasks of every study under root matching `filter`, oldest first.
std::vector<WorklistEntry> list_worklist(const std::filesystem::path& root,
                                         const WorklistFilter& filter = {});

// The task with this id (or unique id prefix of at least 4 characters) under
// root; "STUDY/ID" looks in that study only (STUDY as the worklist names it).
// Throws InvalidInputError when there is none (with a hint), when the id is
// in several studies (a copied study folder keeps its task ids: the studies
// are named, none is picked) or the prefix is ambiguous (listing the matches).
WorklistEntry locate_task(const std::filesystem::path& root, const std::string& given);

// The study input 'patient' (its code on worklists and reports) when the
// study has one, else the study folder's name.
std::string patient_of(workflow::Database& database, const std::filesystem::path& dir);

// Seconds since the epoch of a recorded time, "2026-11-22T14:03:00.123Z"
// (0 when unreadable).
double utc_seconds(const std::string& text);

// "3 h 12 min", "45 s", "2 d 4 h": an age for people.
std::string format_age(double seconds);

}  // namespace mmm::worklists
