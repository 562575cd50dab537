#include "worklists/worklist.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <set>

#include "core/errors.h"
#include "workflow/store/sqlite.h"
#include "worklists/task_store.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxDepth = 4;
constexpr const char* kDatabaseFile = "study.db";

void collect(const fs::path& dir, int depth, std::vector<fs::path>& studies) {
  std::error_code error;
  if (fs::exists(dir / kDatabaseFile, error)) {
    studies.push_back(dir);
    return;  // a study's own folders hold no studies
  }
  if (depth >= kMaxDepth) return;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    if (entry.is_directory(error) && !entry.path().filename().string().starts_with(".")) {
      collect(entry.path(), depth + 1, studies);
    }
  }
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string patient_of(workflow::Database& database, const fs::path& dir) {
  workflow::Statement select =
      database.prepare("SELECT given FROM inputs WHERE name = 'patient' AND is_file = 0");
  if (select.step()) {
    std::string given = select.column_text(0);
    if (!given.empty()) return given;
  }
  return dir.filename().string();
}

double utc_seconds(const std::string& text) {
  std::tm tm{};
  if (text.size() < 19 ||
      ::strptime(text.substr(0, 19).c_str(), "%Y-%m-%dT%H:%M:%S", &tm) == nullptr) {
    return 0;
  }
  auto seconds = static_cast<double>(::timegm(&tm));
  if (text.size() > 20 && text[19] == '.') seconds += std::stod("0" + text.substr(19, 4));
  return seconds;
}

std::vector<fs::path> find_studies(const fs::path& root) {
  std::error_code error;
  if (!fs::is_directory(root, error)) {
    throw IoError(root, "is not a folder; hint: --root names the folder that holds the studies");
  }
  std::vector<fs::path> studies;
  collect(root, 0, studies);
  std::sort(studies.begin(), studies.end());
  return studies;
}

std::vector<WorklistEntry> list_worklist(const fs::path& root, const WorklistFilter& filter) {
  std::vector<WorklistEntry> entries;
  const double now = now_seconds();
  for (const fs::path& dir : find_studies(root)) {
    workflow::Database database(dir / kDatabaseFile);
    if (!tasks_table_exists(database)) continue;
    const std::string patient = patient_of(database, dir);
    for (Task& task : all_tasks(database)) {
      // An accepted task with a correction awaiting review still needs a person.
      const bool closed =
          (task.state == TaskState::kAccepted && task.pending_correction.is_null()) ||
          task.state == TaskState::kCancelled;
      if (filter.state ? task.state != *filter.state : (closed && !filter.include_closed)) {
        continue;
      }
      if (filter.assignee && task.assignee != *filter.assignee) continue;
      WorklistEntry entry;
      entry.study_dir = dir;
      entry.study = dir.lexically_relative(root).generic_string();
      if (entry.study.empty() || entry.study == ".") entry.study = dir.filename().string();
      entry.patient = patient;
      entry.age_seconds = std::max(0.0, now - utc_seconds(task.created_at));
      entry.task = std::move(task);
      entries.push_back(std::move(entry));
    }
  }
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return a.task.created_at < b.task.created_at;
  });
  return entries;
}

WorklistEntry locate_task(const fs::path& root, const std::string& given) {
  // "STUDY/ID": the task of that study only (a copied study folder keeps the
  // task ids of the one it was copied from).
  const std::size_t slash = given.rfind('/');
  const std::string study = slash == std::string::npos ? "" : given.substr(0, slash);
  const std::string id = slash == std::string::npos ? given : given.substr(slash + 1);
  if (id.size() < 4) {
    throw InvalidInputError("task id '" + id + "' is too short; hint: give at least 4 characters");
  }
  std::vector<WorklistEntry> exact;
  std::vector<WorklistEntry> prefixed;
  WorklistFilter every;
  every.include_closed = true;
  for (WorklistEntry& entry : list_worklist(root, every)) {
    if (!study.empty() && entry.study != study) continue;
    if (entry.task.id == id) {
      exact.push_back(std::move(entry));
    } else if (entry.task.id.starts_with(id)) {
      prefixed.push_back(std::move(entry));
    }
  }
  std::vector<WorklistEntry>& matches = exact.empty() ? prefixed : exact;
  if (matches.size() == 1) return std::move(matches.front());
  if (matches.empty()) {
    throw InvalidInputError("no task '" + given + "' in the studies under " + root.string() +
                            "; hint: 'mmm worklist --root " + root.string() +
                            " --all' lists every task");
  }
  std::string ids;
  for (const WorklistEntry& entry : matches) {
    ids += (ids.empty() ? "" : ", ") + entry.task.id + " (" + entry.study + ")";
  }
  if (!exact.empty()) {
    throw InvalidInputError("task id '" + id +
                            "' is in several studies (was a study folder "
                            "copied?): " +
                            ids + "; hint: name the study as STUDY/" + id);
  }
  throw InvalidInputError("task id prefix '" + id + "' matches several tasks: " + ids +
                          "; hint: give more characters, or STUDY/ID");
}

std::string format_age(double seconds) {
  const auto total = static_cast<long long>(seconds);
  if (total < 60) return std::to_string(total) + " s";
  if (total < 3600) return std::to_string(total / 60) + " min";
  if (total < 86400) {
    return std::to_string(total / 3600) + " h " + std::to_string(total % 3600 / 60) + " min";
  }
  return std::to_string(total / 86400) + " d " + std::to_string(total % 86400 / 3600) + " h";
}

}  // namespace mmm::worklists
