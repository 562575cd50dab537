#pragma once
// The node types a program knows: each a spec (its contract), a run
// function and, for a manual node type, its task behaviour (what its tasks
// show and how a submission is evaluated: manual_task.h). nodes/ fills the
// registry of the mmm executable; tests build their own with test node types.
//
//   struct DecimateMesh {
//     static NodeSpec spec();
//     static void run(NodeContext& context);
//   };
//   registry.add<DecimateMesh>();
//
//   struct LandmarkStation {  // manual: spec().manual()
//     static NodeSpec spec();
//     static void run(NodeContext& context);  // never called by the engine
//     static ManualTaskBehaviour task_behaviour();
//   };
//   registry.add<LandmarkStation>();

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/manual_task.h"
#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::workflow {

using RunFunction = std::function<void(NodeContext& context)>;

struct NodeType {
  NodeSpec spec;
  RunFunction run;
  ManualTaskBehaviour task;  // manual node types only (complete); empty otherwise
};

// What a study stores in place of a file given as an input, when the file is
// of a kind that must not be kept as it is (a DICOM radiograph carries the
// patient's name, IDs and dates: only its pixels and geometry are kept).
struct FileImporter {
  std::string name;  // for messages, e.g. "DICOM de-identification"
  // Decides from the first kImporterHeadBytes of the file (fewer for a
  // shorter file).
  std::function<bool(std::string_view head)> accepts;
  // The bytes to store instead; throws IoError naming `origin` when the file
  // cannot be converted (the study input is then refused).
  std::function<std::string(std::string_view bytes, const std::filesystem::path& origin)> convert;
};
inline constexpr std::size_t kImporterHeadBytes = 132;

// The same for a folder given where a file is expected (a DICOM series as
// exported from a PACS): the study stores what `convert` makes of it.
struct FolderImporter {
  std::string name;  // for messages, e.g. "DICOM series de-identification"
  // Decides with a bounded look into the folder.
  std::function<bool(const std::filesystem::path& folder)> accepts;
  // The bytes to store for the folder; throws IoError naming the folder (or
  // a file in it) when it cannot be converted.
  std::function<std::string(const std::filesystem::path& folder)> convert;
};

class NodeRegistry {
 public:
  // Throws InvalidInputError when a type of that name is already registered,
  // when a manual type comes without a complete task behaviour and when a
  // computing type comes with one.
  void add(NodeSpec spec, RunFunction run, ManualTaskBehaviour task = {});
  template <class T>
  void add() {
    if constexpr (requires { T::task_behaviour(); }) {
      add(T::spec(), &T::run, T::task_behaviour());
    } else {
      add(T::spec(), &T::run);
    }
  }

  // nullptr for an unknown name.
  [[nodiscard]] const NodeType* find(std::string_view name) const;
  // All types, sorted by name.
  [[nodiscard]] std::vector<const NodeType*> all() const;
  // Names close to `name` (edit distance <= 2 or a shared prefix), for hints.
  [[nodiscard]] std::vector<std::string> similar_names(std::string_view name) const;

  // File importers are tried in the order added; the first that accepts a
  // file converts it.
  void add_file_importer(FileImporter importer);
  // The importer that accepts a file starting with `head`, or nullptr.
  [[nodiscard]] const FileImporter* importer_for(std::string_view head) const;

  // Folder importers likewise, for a folder given for a File input.
  void add_folder_importer(FolderImporter importer);
  [[nodiscard]] const FolderImporter* folder_importer_for(
      const std::filesystem::path& folder) const;
  // The names of the folder importers, for hints ("" when there is none).
  [[nodiscard]] std::string folder_importer_names() const;

 private:
  std::map<std::string, NodeType, std::less<>> types_;
  std::vector<FileImporter> importers_;
  std::vector<FolderImporter> folder_importers_;
};

}  // namespace mmm::workflow
