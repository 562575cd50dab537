#include "workflow/node_registry.h"

#include <algorithm>

#include "core/errors.h"
#include "core/suggest.h"

namespace mmm::workflow {

void NodeRegistry::add(NodeSpec spec, RunFunction run, ManualTaskBehaviour task) {
  if (types_.contains(spec.name())) {
    throw InvalidInputError("node type '" + spec.name() + "' is registered twice");
  }
  if (spec.is_manual() && !task.complete()) {
    throw InvalidInputError(
        "node type '" + spec.name() +
        "' is manual but has no complete task behaviour (kind, request, evaluate, submission "
        "fields); hint: register it with a ManualTaskBehaviour (workflow/manual_task.h)");
  }
  if (!spec.is_manual() && !task.empty()) {
    throw InvalidInputError("node type '" + spec.name() +
                            "' computes its result but was registered with a task behaviour; "
                            "hint: only a manual node (NodeSpec::manual()) has tasks");
  }
  std::string name = spec.name();
  types_.emplace(std::move(name), NodeType{std::move(spec), std::move(run), std::move(task)});
}

void NodeRegistry::add_file_importer(FileImporter importer) {
  if (!importer.accepts || !importer.convert) {
    throw InvalidInputError("file importer '" + importer.name +
                            "' needs both an accepts and a convert function");
  }
  importers_.push_back(std::move(importer));
}

const FileImporter* NodeRegistry::importer_for(std::string_view head) const {
  for (const FileImporter& importer : importers_) {
    if (importer.accepts(head)) return &importer;
  }
  return nullptr;
}

void NodeRegistry::add_folder_importer(FolderImporter importer) {
  if (!importer.accepts || !importer.convert) {
    throw InvalidInputError("folder importer '" + importer.name +
                            "' needs both an accepts and a convert function");
  }
  folder_importers_.push_back(std::move(importer));
}

const FolderImporter* NodeRegistry::folder_importer_for(const std::filesystem::path& folder) const {
  for (const FolderImporter& importer : folder_importers_) {
    if (importer.accepts(folder)) return &importer;
  }
  return nullptr;
}

std::string NodeRegistry::folder_importer_names() const {
  std::string names;
  for (const FolderImporter& importer : folder_importers_) {
    names += (names.empty() ? "" : ", ") + importer.name;
  }
  return names;
}

const NodeType* NodeRegistry::find(std::string_view name) const {
  const auto it = types_.find(name);
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<const NodeType*> NodeRegistry::all() const {
  std::vector<const NodeType*> out;
  out.reserve(types_.size());
  for (const auto& [name, type] : types_) out.push_back(&type);
  return out;
}

std::vector<std::string> NodeRegistry::similar_names(std::string_view name) const {
  std::vector<std::string> out;
  for (const auto& [candidate, type] : types_) {
    const bool prefix = candidate.size() >= 3 && name.size() >= 3 &&
                        candidate.compare(0, 3, name.substr(0, 3)) == 0;
    if (edit_distance(candidate, name) <= 2 || prefix) out.push_back(candidate);
  }
  return out;
}

}  // namespace mmm::workflow
