#include "workflow/study/study.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>
#include <utility>

#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/suggest.h"
#include "workflow/definition/workflow_loader.h"
#include "workflow/host_and_time.h"
#include "workflow/store/shared_store.h"
#include "workflow/study/cache_key.h"
#include "workflow/study/study_database.h"
#include "workflow/study/value_text.h"

namespace mmm::workflow {
namespace {

constexpr const char* kDatabaseFile = "study.db";
constexpr const char* kWorkflowFile = "workflow.yaml";

// Only an Atlas may be given as a folder: its value is a folder on disk,
// stored as the folder's bundle (core/directory_bundle.h). A file given for
// an Atlas is taken as an already-packed bundle.
bool accepts_folder(PortType type) { return type == PortType::kAtlas; }

// A cheap fingerprint of an input's origin on disk, to notice a change
// without reading the content. A folder (an Atlas given unpacked) has the
// total size of its files and the newest modification time of any file or
// folder in it: editing a file moves its time, while adding, removing or
// renaming one moves the time of the folder that holds it.
struct FileStamp {
  std::int64_t size = 0;
  std::int64_t mtime_ns = 0;
  bool is_directory = false;
  // For a folder given for a File input: the importer that takes it (e.g. a
  // DICOM series), or nullptr when the folder cannot be used.
  const FolderImporter* folder_importer = nullptr;
};

std::int64_t mtime_ns_of(const struct stat& info) {
  return static_cast<std::int64_t>(info.st_mtim.tv_sec) * 1'000'000'000 +
         static_cast<std::int64_t>(info.st_mtim.tv_nsec);
}

// Links are followed (stat), as pack_directory() records a linked file's
// target bytes; links to folders are not walked (packing refuses them).
FileStamp directory_stamp(const std::filesystem::path& dir, const struct stat& dir_info) {
  FileStamp stamp{0, mtime_ns_of(dir_info), true};
  std::error_code error;
  std::filesystem::recursive_directory_iterator entries(dir, error);
  for (; !error && entries != std::filesystem::recursive_directory_iterator();
       entries.increment(error)) {
    struct stat info {};
    if (::stat(entries->path().c_str(), &info) != 0) continue;  // dangling: packing reports it
    if (S_ISREG(info.st_mode)) stamp.size += static_cast<std::int64_t>(info.st_size);
    if (S_ISREG(info.st_mode) || S_ISDIR(info.st_mode)) {
      stamp.mtime_ns = std::max(stamp.mtime_ns, mtime_ns_of(info));
    }
  }
  if (error) throw IoError(dir, "cannot list the folder: " + error.message());
  return stamp;
}

// The stamp of a regular file or a folder given for an input of type
// `type`; std::nullopt when `origin` is neither (or does not exist). A folder
// given where none is accepted, and that no folder importer takes (their
// look is bounded), is not walked (a mistyped "/" costs little): its stamp
// only says that it is a folder.
std::optional<FileStamp> stamp_of(const std::filesystem::path& origin, PortType type,
                                  const NodeRegistry& registry) {
  struct stat info {};
  if (::stat(origin.c_str(), &info) != 0) return std::nullopt;
  if (S_ISDIR(info.st_mode)) {
    if (accepts_folder(type)) return directory_stamp(origin, info);
    const FolderImporter* importer = registry.folder_importer_for(origin);
    if (importer == nullptr) return FileStamp{0, 0, true};
    FileStamp stamp = directory_stamp(origin, info);
    stamp.folder_importer = importer;
    return stamp;
  }
  if (!S_ISREG(info.st_mode)) return std::nullopt;
  return FileStamp{static_cast<std::int64_t>(info.st_size), mtime_ns_of(info), false};
}

// What to write after --input NAME= in hints.
std::string input_value_hint(PortType type) {
  if (is_value_type(type)) return "VALUE";
  return accepts_folder(type) ? "DIR" : "PATH";
}

// What store_origin() stored: the artifact, and the name of the importer
// that converted the origin ("" when it was stored as given).
struct StoredOrigin {
  std::string hash;
  std::string importer;
};

// Stores the content of an input's origin: a file's bytes, a folder's
// bundle, or what an importer makes of either.
StoredOrigin store_origin(ArtifactStore& artifacts, const std::filesystem::path& origin,
                          const FileStamp& stamp, const NodeRegistry& registry) {
  if (stamp.size > kMaxStudyInputBytes) {
    throw IoError(origin, std::string(stamp.is_directory ? "holds " : "is ") +
                              std::to_string(stamp.size) + " bytes; a study input is at most " +
                              std::to_string(kMaxStudyInputBytes) +
                              " (1 GiB); hint: check that this is the file you meant");
  }
  if (stamp.is_directory) {
    if (stamp.folder_importer != nullptr) {
      return {artifacts.put(stamp.folder_importer->convert(origin)), stamp.folder_importer->name};
    }
    return {artifacts.put(pack_directory(origin)), ""};
  }
  // A file of a kind that must not be stored as given (e.g. DICOM, with the
  // patient's identity in it) is stored as its importer converts it.
  const auto size = static_cast<std::uintmax_t>(stamp.size);
  const std::string head =
      read_file_bytes(origin, std::min<std::uintmax_t>(size, kImporterHeadBytes));
  if (const FileImporter* importer = registry.importer_for(head)) {
    return {artifacts.put(importer->convert(read_file_bytes(origin, size), origin)),
            importer->name};
  }
  return {artifacts.put_file(origin), ""};
}

// What a study records as `given` for an input that an importer converted.
// Importers exist to keep out what identifies a patient, and a path often
// does (an export's folders are named after the patient): the path is not
// kept, so such an input is not followed by refresh_file_inputs(); giving
// it again (set_input) replaces it.
std::string imported_origin_label(const std::string& importer) {
  return "(" + importer + "; the path is not kept)";
}

// True when `record` remembers where its content came from on disk.
bool origin_is_kept(const StudyInputRecord& record) {
  return record.is_file && std::filesystem::path(record.given).is_absolute();
}

std::string diagnostics_text(const LoadResult& result) {
  std::string text;
  for (const Diagnostic& d : result.diagnostics) text += "\n  " + d.text();
  return text;
}

WorkflowDefinition load_valid_workflow(const std::filesystem::path& file,
                                       const NodeRegistry& registry, std::string_view context) {
  LoadResult result = load_workflow(file, registry);
  if (!result.valid()) {
    throw InvalidInputError(std::string(context) + ": the workflow " + file.string() + " has " +
                            std::to_string(result.diagnostics.size()) +
                            " problem(s):" + diagnostics_text(result) +
                            "\nhint: check it with 'mmm validate " + file.string() + "'");
  }
  return std::move(result.definition);
}

std::vector<std::string> input_names(const WorkflowDefinition& workflow) {
  std::vector<std::string> names;
  for (const StudyInput& input : workflow.inputs) names.push_back(input.name);
  return names;
}

std::string read_file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot read the workflow file");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

void write_file_durably(const std::filesystem::path& file, std::string_view bytes) {
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw IoError(file, "cannot write");
  }
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

// The prefix of the hidden sibling folders in which `dir` is built.
std::string staging_prefix(const std::filesystem::path& dir) {
  return "." + dir.filename().string() + ".creating-";
}

// A fresh sibling folder name for building the study before it appears:
// PREFIX<pid>-<random>-<host>, so that a later create can tell an abandoned one.
std::filesystem::path staging_dir_for(const std::filesystem::path& dir) {
  std::random_device random;
  return dir.parent_path() / (staging_prefix(dir) + std::to_string(::getpid()) + "-" +
                              std::to_string(random()) + "-" + host_name());
}

// Removes the staging folders of earlier creates of `dir` that were killed
// before they could clean up: made on this machine by a process that is gone,
// or (another machine's, on a shared file system) a day old.
void remove_abandoned_staging(const std::filesystem::path& dir) {
  const std::string prefix = staging_prefix(dir);
  const std::string this_host = host_name();
  const auto now = std::filesystem::file_time_type::clock::now();
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir.parent_path(), error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(prefix)) continue;
    const std::string rest = name.substr(prefix.size());  // pid-random-host
    const std::size_t first = rest.find('-');
    const std::size_t second = first == std::string::npos ? first : rest.find('-', first + 1);
    bool abandoned = false;
    if (second != std::string::npos && rest.substr(second + 1) == this_host) {
      long pid = 0;
      try {
        pid = std::stol(rest.substr(0, first));
      } catch (const std::exception&) {
        pid = 0;
      }
      abandoned = pid <= 0 || (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH);
    } else {
      std::error_code time_error;
      const auto written = std::filesystem::last_write_time(entry.path(), time_error);
      abandoned = !time_error && now - written > std::chrono::hours(24);
    }
    if (abandoned) std::filesystem::remove_all(entry.path(), error);
  }
}

void insert_meta(Database& database, const std::string& key, const std::string& value) {
  database.prepare("INSERT OR REPLACE INTO meta(key, value) VALUES (?, ?)")
      .bind_text(1, key)
      .bind_text(2, value)
      .step();
}

}  // namespace

Study::Study(std::filesystem::path dir, WorkflowDefinition workflow, const NodeRegistry& registry)
    : dir_(std::move(dir)),
      workflow_(std::move(workflow)),
      registry_(&registry),
      database_(dir_ / kDatabaseFile),
      artifacts_(dir_ / "artifacts") {
  prepare_study_database(database_);
  // Under a cohort's root, blobs are shared with the other studies.
  if (const std::optional<std::filesystem::path> pool = find_shared_store(dir_)) {
    artifacts_.share_with(*pool);
  }
}

Study Study::create(const std::filesystem::path& dir, const CreateStudyOptions& options,
                    const NodeRegistry& registry) {
  std::error_code error;
  if (std::filesystem::exists(dir, error) && !std::filesystem::is_empty(dir, error)) {
    throw IoError(dir,
                  "cannot create a study here: the folder exists and is not empty; "
                  "hint: choose a new folder, or 'mmm run " +
                      dir.string() + "' if it is already a study");
  }
  WorkflowDefinition workflow =
      load_valid_workflow(options.workflow_file, registry, "cannot create the study");

  // Check the inputs before touching the disk: every problem at once.
  std::vector<std::string> problems;
  const std::vector<std::string> known = input_names(workflow);
  for (const auto& [name, text] : options.inputs) {
    if (workflow.find_input(name) == nullptr) {
      problems.push_back("unknown study input '" + name + "'" + did_you_mean(name, known) +
                         " (the workflow declares: " + join_names(known) + ")");
    }
  }
  for (const StudyInput& input : workflow.inputs) {
    if (!options.inputs.contains(input.name) && !input.default_value) {
      problems.push_back("study input '" + input.name + "' (" + input.type_name +
                         ") has no default: give it with --input " + input.name + "=" +
                         input_value_hint(*input.type));
    }
  }
  if (!problems.empty()) {
    std::string text = "cannot create the study " + dir.string() + ":";
    for (const std::string& problem : problems) text += "\n  " + problem;
    throw InvalidInputError(text);
  }

  // Build the study in a hidden sibling folder, then rename it into place, so
  // that a failure (bad input file, full disk, crash) leaves nothing behind.
  const std::filesystem::path absolute_dir = std::filesystem::absolute(dir).lexically_normal();
  std::filesystem::create_directories(absolute_dir.parent_path(), error);
  remove_abandoned_staging(absolute_dir);
  const std::filesystem::path staging = staging_dir_for(absolute_dir);
  std::filesystem::create_directory(staging, error);
  if (error) throw IoError(staging, "cannot create the study folder: " + error.message());
  try {
    write_file_durably(staging / kWorkflowFile, read_file_bytes(options.workflow_file));
    {
      Study study(staging, workflow, registry);
      Transaction transaction(study.database_);
      insert_meta(study.database_, "created_at", utc_now());
      insert_meta(study.database_, "host", host_name());
      insert_meta(study.database_, "mmm_version", options.provenance.mmm_version);
      insert_meta(study.database_, "git_revision", options.provenance.git_revision);
      insert_meta(study.database_, "workflow_name", workflow.name);
      insert_meta(study.database_, "workflow_hash", workflow_hash(workflow));
      insert_meta(study.database_, "workflow_origin",
                  std::filesystem::absolute(options.workflow_file).lexically_normal().string());
      for (const StudyInput& input : workflow.inputs) {
        const auto given = options.inputs.find(input.name);
        const std::string text =
            given != options.inputs.end() ? given->second : param_value_text(*input.default_value);
        study.write_input(study.import_input(input, text));
      }
      transaction.commit();
    }
    std::filesystem::create_directory(staging / "outputs");
    std::filesystem::create_directory(staging / "scratch");
    // rename(2) replaces an empty folder atomically; a non-empty one fails.
    if (::rename(staging.c_str(), absolute_dir.c_str()) != 0) {
      throw IoError(dir, "cannot move the new study into place: " +
                             std::error_code(errno, std::generic_category()).message());
    }
  } catch (...) {
    std::filesystem::remove_all(staging, error);
    throw;
  }
  return open(absolute_dir, registry);
}

Study Study::open(const std::filesystem::path& dir, const NodeRegistry& registry) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(dir / kDatabaseFile, error) ||
      !std::filesystem::is_regular_file(dir / kWorkflowFile, error)) {
    throw IoError(dir,
                  "not a study folder (no study.db and workflow.yaml); hint: create one with "
                  "'mmm study create " +
                      dir.string() + " --workflow WF.yaml'");
  }
  WorkflowDefinition workflow =
      load_valid_workflow(dir / kWorkflowFile, registry, "cannot open the study");
  const std::filesystem::path absolute_dir = std::filesystem::absolute(dir).lexically_normal();
  return {absolute_dir, std::move(workflow), registry};
}

std::map<std::string, std::string> Study::meta() {
  std::map<std::string, std::string> values;
  Statement select = database_.prepare("SELECT key, value FROM meta");
  while (select.step()) values[select.column_text(0)] = select.column_text(1);
  return values;
}

std::map<std::string, StudyInputRecord> Study::inputs() {
  std::map<std::string, StudyInputRecord> records;
  Statement select = database_.prepare(
      "SELECT name, type, hash, is_file, given, source_size, source_mtime_ns, updated_at "
      "FROM inputs");
  while (select.step()) {
    StudyInputRecord record;
    record.name = select.column_text(0);
    const std::optional<PortType> type = port_type_from_name(select.column_text(1));
    if (!type) {
      throw IoError(database_.path(),
                    "input '" + record.name + "' has unknown type '" + select.column_text(1) + "'");
    }
    record.type = *type;
    record.hash = select.column_text(2);
    record.is_file = select.column_int64(3) != 0;
    record.given = select.column_text(4);
    record.source_size = select.column_int64(5);
    record.source_mtime_ns = select.column_int64(6);
    record.updated_at = select.column_text(7);
    records.emplace(record.name, std::move(record));
  }
  return records;
}

StudyInputRecord Study::import_input(const StudyInput& declared, std::string_view text) {
  StudyInputRecord record;
  record.name = declared.name;
  record.type = *declared.type;
  record.updated_at = utc_now();
  const std::string what = "study input '" + declared.name + "' (" + declared.type_name + ")";
  if (is_value_type(record.type)) {
    const ParamValue value = parse_value_text(record.type, text, what);
    record.hash = artifacts_.put(value_artifact_bytes(value));
    record.given = param_value_text(value);
    return record;
  }
  const std::filesystem::path origin = std::filesystem::absolute(text).lexically_normal();
  const std::optional<FileStamp> stamp = stamp_of(origin, record.type, *registry_);
  const std::string hint = "; hint: give the path of the " +
                           std::string(accepts_folder(record.type) ? "atlas folder (or of a "
                                                                     "packed bundle file)"
                                                                   : "file") +
                           " with --input " + declared.name + "=" + input_value_hint(record.type);
  if (!stamp) {
    throw IoError(origin,
                  what +
                      (accepts_folder(record.type) ? ": no such folder or file"
                                                   : ": no such file (or not a regular file)") +
                      hint);
  }
  if (stamp->is_directory && !accepts_folder(record.type) && stamp->folder_importer == nullptr) {
    const std::string importers = registry_->folder_importer_names();
    throw IoError(origin, what + ": is a folder, but only Atlas inputs" +
                              (importers.empty()
                                   ? std::string()
                                   : ", and folders that an importer takes (" + importers + "),") +
                              " may be given as a folder" + hint);
  }
  // A folder input is still "a file's content" for the record: its origin is
  // re-checked by refresh_file_inputs() like a file's.
  record.is_file = true;
  const StoredOrigin stored = store_origin(artifacts_, origin, *stamp, *registry_);
  record.hash = stored.hash;
  if (stored.importer.empty()) {
    record.given = origin.string();
    record.source_size = stamp->size;
    record.source_mtime_ns = stamp->mtime_ns;
  } else {
    record.given = imported_origin_label(stored.importer);
  }
  return record;
}

void Study::write_input(const StudyInputRecord& record) {
  database_
      .prepare(
          "INSERT OR REPLACE INTO inputs(name, type, hash, is_file, given, source_size, "
          "source_mtime_ns, updated_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?)")
      .bind_text(1, record.name)
      .bind_text(2, port_type_name(record.type))
      .bind_text(3, record.hash)
      .bind_int64(4, record.is_file ? 1 : 0)
      .bind_text(5, record.given)
      .bind_int64(6, record.source_size)
      .bind_int64(7, record.source_mtime_ns)
      .bind_text(8, record.updated_at)
      .step();
}

bool Study::set_input(std::string_view name, std::string_view text) {
  const StudyInput* declared = workflow_.find_input(name);
  if (declared == nullptr) {
    const std::vector<std::string> known = input_names(workflow_);
    throw InvalidInputError("unknown study input '" + std::string(name) + "'" +
                            did_you_mean(name, known) +
                            " (the workflow declares: " + join_names(known) + ")");
  }
  const StudyInputRecord record = import_input(*declared, text);
  const std::map<std::string, StudyInputRecord> before = inputs();
  const auto previous = before.find(declared->name);
  Transaction transaction(database_);
  write_input(record);
  transaction.commit();
  return previous == before.end() || previous->second.hash != record.hash;
}

std::vector<std::string> Study::refresh_file_inputs() {
  std::vector<std::string> changes;
  for (const auto& [name, record] : inputs()) {
    if (!origin_is_kept(record)) continue;
    const std::optional<FileStamp> stamp = stamp_of(record.given, record.type, *registry_);
    // An origin that is gone, or became a folder where only a file will do,
    // is not a change: keep using the stored copy.
    if (!stamp || (stamp->is_directory && !accepts_folder(record.type) &&
                   stamp->folder_importer == nullptr)) {
      continue;
    }
    if (stamp->size == record.source_size && stamp->mtime_ns == record.source_mtime_ns) continue;
    StudyInputRecord updated = record;
    updated.source_size = stamp->size;
    updated.source_mtime_ns = stamp->mtime_ns;
    const StoredOrigin stored = store_origin(artifacts_, record.given, *stamp, *registry_);
    updated.hash = stored.hash;
    // The origin became a file an importer converts (a DICOM file written
    // over a PNG): from now on its path is not kept either.
    if (!stored.importer.empty()) {
      updated.given = imported_origin_label(stored.importer);
      updated.source_size = 0;
      updated.source_mtime_ns = 0;
    }
    if (updated.hash != record.hash) {
      updated.updated_at = utc_now();
      changes.push_back("study input '" + name + "' changed: " + updated.given +
                        " has new content (SHA-256 " + record.hash.substr(0, 12) + "... -> " +
                        updated.hash.substr(0, 12) + "...)");
    }
    Transaction transaction(database_);
    write_input(updated);
    transaction.commit();
  }
  return changes;
}

void Study::set_param(std::string_view node, std::string_view param, std::string_view text) {
  const NodeInstance* instance = workflow_.find_node(node);
  if (instance == nullptr) {
    std::vector<std::string> ids;
    for (const NodeInstance& n : workflow_.nodes) ids.push_back(n.id);
    throw InvalidInputError("no node '" + std::string(node) + "' in the workflow" +
                            did_you_mean(node, ids) + " (nodes: " + join_names(ids) + ")");
  }
  const NodeType* type = registry_->find(instance->type);
  if (type == nullptr) throw InvalidInputError("unknown node type '" + instance->type + "'");
  const ParamSpec* spec = type->spec.find_param(param);
  if (spec == nullptr) {
    std::vector<std::string> names;
    for (const ParamSpec& p : type->spec.params()) names.push_back(p.name);
    throw InvalidInputError("node '" + instance->id + "' (" + instance->type +
                            ") has no parameter '" + std::string(param) + "'" +
                            did_you_mean(param, names) + " (parameters: " + join_names(names) +
                            ")");
  }
  const ParamValue value =
      parse_param_text(*spec, text, "parameter '" + instance->id + "." + spec->name + "'");
  Transaction transaction(database_);
  database_
      .prepare(
          "INSERT OR REPLACE INTO param_overrides(node, param, value_json, set_at) "
          "VALUES (?, ?, ?, ?)")
      .bind_text(1, instance->id)
      .bind_text(2, spec->name)
      .bind_text(3, param_value_json(value).dump())
      .bind_text(4, utc_now())
      .step();
  transaction.commit();
}

std::map<std::string, std::map<std::string, ParamValue>> Study::param_overrides() {
  std::map<std::string, std::map<std::string, ParamValue>> overrides;
  Statement select = database_.prepare("SELECT node, param, value_json FROM param_overrides");
  while (select.step()) {
    overrides[select.column_text(0)][select.column_text(1)] =
        param_value_from_json(nlohmann::json::parse(select.column_text(2)));
  }
  return overrides;
}

std::map<std::string, ParamValue> Study::given_params(const NodeInstance& node) {
  std::map<std::string, ParamValue> params = node.param_values();
  Statement select =
      database_.prepare("SELECT param, value_json FROM param_overrides WHERE node = ?");
  select.bind_text(1, node.id);
  while (select.step()) {
    params[select.column_text(0)] =
        param_value_from_json(nlohmann::json::parse(select.column_text(1)));
  }
  return params;
}

}  // namespace mmm::workflow
