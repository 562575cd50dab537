#pragma once
// A study: one run of one workflow for one patient, kept in a folder that
// survives any crash and can be moved, copied or archived as a whole.
//
//   DIR/study.db       SQLite (WAL): provenance, inputs, parameter overrides,
//                      runs, executions with their log lines (study_database.h)
//   DIR/workflow.yaml  the workflow, copied at creation (the study's own copy:
//                      editing the original later changes nothing)
//   DIR/artifacts/     content-addressed store of every value (artifact_store.h)
//   DIR/outputs/       the workflow's exported outputs, written atomically
//   DIR/scratch/       private folders of running nodes (emptied at each run)
//   DIR/.lock          runner lock (study_lock.h)
//
// Nothing in the database is an absolute path except the origin of file
// inputs, which is only used to notice that the user changed the file (the
// content itself is in the store), so a moved study loses nothing.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/definition/workflow_definition.h"
#include "workflow/node_registry.h"
#include "workflow/store/artifact_store.h"
#include "workflow/store/sqlite.h"

namespace mmm::workflow {

// The largest study input: a file's size, or the sum of a folder's files. A
// larger one is refused (naming this limit) before anything is copied.
inline constexpr std::int64_t kMaxStudyInputBytes = std::int64_t{1} << 30;

// The program that creates or runs a study, recorded with it.
struct Provenance {
  std::string mmm_version;   // e.g. "0.1.0"
  std::string git_revision;  // `git describe --always --dirty` of the build, or "unknown"
};

// A study input as recorded: its current content is the artifact `hash`.
struct StudyInputRecord {
  std::string name;
  PortType type = PortType::kFile;
  std::string hash;
  bool is_file = false;  // a file's content (else a value typed by the user)
  // The value text, or the absolute path of the file or folder given; for
  // content an importer converted (a DICOM file), a label instead: the path
  // is not kept (it may name the patient), nor followed on refresh.
  std::string given;
  std::int64_t source_size = 0;      // files: size and modification time at import,
  std::int64_t source_mtime_ns = 0;  // to notice a changed file cheaply
  std::string updated_at;
};

struct CreateStudyOptions {
  std::filesystem::path workflow_file;
  // Study input name -> file path (File and other artifact types) or value
  // text (Number, Integer, String, Bool). Inputs with a default may be left out.
  std::map<std::string, std::string> inputs;
  Provenance provenance;
};

class Study {
 public:
  // Creates the study folder `dir` (which must not exist, or be an empty
  // folder): validates the workflow against `registry`, copies it, imports
  // every input into the artifact store and records provenance. Throws
  // InvalidInputError listing every problem (workflow diagnostics with
  // file:line:col, unknown, missing or ill-typed inputs) and IoError for file
  // problems; on failure nothing is left behind. The hidden staging folders
  // of earlier creates of `dir` that were killed meanwhile are removed.
  static Study create(const std::filesystem::path& dir, const CreateStudyOptions& options,
                      const NodeRegistry& registry);

  // Opens an existing study. Throws IoError when `dir` is not a study (with a
  // hint to `mmm study create`) and InvalidInputError when its workflow no
  // longer validates against `registry` (e.g. a node type was removed).
  static Study open(const std::filesystem::path& dir, const NodeRegistry& registry);

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::filesystem::path outputs_dir() const { return dir_ / "outputs"; }
  [[nodiscard]] std::filesystem::path scratch_dir() const { return dir_ / "scratch"; }
  // Where a node that crashes the process is named (workflow/run/crash_marker.h).
  [[nodiscard]] std::filesystem::path crash_marker() const { return dir_ / "crash-marker"; }
  [[nodiscard]] const WorkflowDefinition& workflow() const { return workflow_; }
  [[nodiscard]] const NodeRegistry& registry() const { return *registry_; }
  [[nodiscard]] Database& database() { return database_; }
  [[nodiscard]] const ArtifactStore& artifacts() const { return artifacts_; }
  [[nodiscard]] ArtifactStore& artifacts() { return artifacts_; }

  // Provenance and facts recorded at creation: format, created_at, host,
  // mmm_version, git_revision, workflow_name, workflow_hash.
  [[nodiscard]] std::map<std::string, std::string> meta();

  // Every recorded input, by name.
  [[nodiscard]] std::map<std::string, StudyInputRecord> inputs();

  // Sets the study input `name` from command-line text: a file path is
  // imported into the store, a value is parsed by the input's type. Returns
  // whether the content changed. Throws InvalidInputError for an unknown name
  // (with the known ones) or a bad value, IoError for an unreadable file.
  bool set_input(std::string_view name, std::string_view text);

  // Re-imports every file input whose origin changed on disk since it was
  // imported (size or modification time differs and the content hash too).
  // Returns one sentence per input whose content changed. An origin that no
  // longer exists is not a change: the stored copy stays in use.
  std::vector<std::string> refresh_file_inputs();

  // Overrides parameter `param` of node `node` (value text parsed by the
  // parameter's type and checked against its spec). Throws InvalidInputError
  // naming the node/parameter with the known names or the accepted values.
  void set_param(std::string_view node, std::string_view param, std::string_view text);

  // The parameters of a node as given: the workflow file's values with the
  // study's overrides on top (defaults not applied).
  [[nodiscard]] std::map<std::string, ParamValue> given_params(const NodeInstance& node);

  // Every override: node -> parameter -> value.
  [[nodiscard]] std::map<std::string, std::map<std::string, ParamValue>> param_overrides();

 private:
  Study(std::filesystem::path dir, WorkflowDefinition workflow, const NodeRegistry& registry);

  StudyInputRecord import_input(const StudyInput& declared, std::string_view text);
  void write_input(const StudyInputRecord& record);

  std::filesystem::path dir_;
  WorkflowDefinition workflow_;
  const NodeRegistry* registry_;
  Database database_;
  ArtifactStore artifacts_;
};

}  // namespace mmm::workflow
