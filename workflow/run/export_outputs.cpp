#include "workflow/run/export_outputs.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <system_error>
#include <vector>

#include "core/directory_bundle.h"
#include "core/errors.h"
#include "workflow/fault_injection.h"
#include "workflow/host_and_time.h"

namespace mmm::workflow {
namespace {

struct RecordedExport {
  std::string hash;
  std::string file;
};

std::map<std::string, RecordedExport> recorded_exports(Database& database) {
  std::map<std::string, RecordedExport> exports;
  Statement select = database.prepare("SELECT name, hash, file FROM exports");
  while (select.step()) {
    exports[select.column_text(0)] = {select.column_text(1), select.column_text(2)};
  }
  return exports;
}

void sync_path(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// Copies the blob to `target` through a temporary file in the same folder.
void copy_atomically(const std::filesystem::path& blob, const std::filesystem::path& target) {
  const std::filesystem::path temporary =
      target.parent_path() / ("." + target.filename().string() + ".tmp");
  std::error_code error;
  std::filesystem::remove(temporary, error);  // left by a crashed export
  std::filesystem::copy_file(blob, temporary, error);
  if (error) throw IoError(temporary, "cannot write the exported output: " + error.message());
  std::filesystem::permissions(temporary, std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::add, error);
  sync_path(temporary, O_RDONLY);
  fault_point("export.before_rename");
  std::filesystem::rename(temporary, target, error);
  if (error)
    throw IoError(target, "cannot move the exported output into place: " + error.message());
  sync_path(target.parent_path(), O_RDONLY | O_DIRECTORY);
}

// An Atlas export (or a File holding a folder bundle) is also unpacked
// beside its bundle, as the folder people and tools open (atlas.yaml +
// meshes/, motion.pvd + frames): into a temporary folder first, then swapped
// in, so the folder is always whole.
void unpack_atlas_atomically(const std::string& bundle, const std::filesystem::path& target) {
  const std::filesystem::path temporary =
      target.parent_path() / ("." + target.filename().string() + ".tmp");
  std::error_code error;
  std::filesystem::remove_all(temporary, error);
  unpack_directory(bundle, temporary, "exported atlas '" + target.filename().string() + "'");
  std::filesystem::remove_all(target, error);
  std::filesystem::rename(temporary, target, error);
  if (error) throw IoError(target, "cannot move the exported atlas into place: " + error.message());
  sync_path(target.parent_path(), O_RDONLY | O_DIRECTORY);
}

std::string read_all(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The current result an export shows; nullptr when its node has none.
const OutputArtifact* current_artifact(
    const std::map<std::string, std::map<std::string, OutputArtifact>>& results,
    const WorkflowOutput& output) {
  const auto node = results.find(output.source.node);
  if (node == results.end()) return nullptr;
  const auto port = node->second.find(output.source.port);
  return port == node->second.end() ? nullptr : &port->second;
}

// Whether two files hold the same bytes (sizes first, then 1 MiB at a time:
// an exported animation is hundreds of MB).
bool same_content(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(a, error);
  if (error || size != std::filesystem::file_size(b, error) || error) return false;
  std::ifstream in_a(a, std::ios::binary);
  std::ifstream in_b(b, std::ios::binary);
  if (!in_a || !in_b) return false;
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  std::vector<char> chunk_a(kChunk);
  std::vector<char> chunk_b(kChunk);
  for (std::uintmax_t left = size; left > 0;) {
    const auto n = static_cast<std::streamsize>(std::min<std::uintmax_t>(left, kChunk));
    in_a.read(chunk_a.data(), n);
    in_b.read(chunk_b.data(), n);
    if (in_a.gcount() != n || in_b.gcount() != n) return false;
    if (!std::equal(chunk_a.begin(), chunk_a.begin() + n, chunk_b.begin())) return false;
    left -= static_cast<std::uintmax_t>(n);
  }
  return true;
}

// Whether the first line is a CSV header: names separated by at least one
// comma, nothing that would make it markup or binary.
bool csv_header(const std::string& head) {
  const std::size_t end = head.find('\n');
  if (end == std::string::npos || end == 0) return false;
  const std::string line = head.substr(0, end);
  if (std::count(line.begin(), line.end(), ',') < 1) return false;
  return std::all_of(line.begin(), line.end(), [](char c) {
    return c == ',' || c == '_' || c == '.' || c == ' ' || c == '"' || c == '\r' ||
           std::isalnum(static_cast<unsigned char>(c)) != 0;
  });
}

// Extension of an opaque File from its first bytes, so that pictures,
// documents and the files of motion analysis open with a double click.
std::string sniffed_extension(const std::filesystem::path& blob) {
  std::ifstream in(blob, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.starts_with("\x89PNG\r\n\x1a\n")) return ".png";
  if (head.starts_with("<svg") ||
      (head.starts_with("<?xml") && head.find("<svg") != std::string::npos)) {
    return ".svg";
  }
  if (head.starts_with("%PDF")) return ".pdf";
  if (head.starts_with("mmm-bundle 1\n")) return ".bundle";  // a folder (core/directory_bundle.h)
  if (head.starts_with("PathFileType")) return ".trc";
  // OpenSim storage: a header ending in "endheader" with a column count.
  if (head.find("\nendheader") != std::string::npos &&
      (head.find("nColumns=") != std::string::npos ||
       head.find("datacolumns") != std::string::npos)) {
    return ".mot";
  }
  if (head.starts_with("<?xml") && head.find("<OpenSimDocument") != std::string::npos) {
    return ".osim";
  }
  if (csv_header(head)) return ".csv";
  return "";
}

}  // namespace

std::string export_file_name(const std::string& name, PortType type,
                             const std::filesystem::path& blob) {
  if (type == PortType::kFile && !blob.empty()) return name + sniffed_extension(blob);
  return name + std::string(port_type_info(type).extension);
}

ExportReport export_outputs(
    Study& study, const std::map<std::string, std::map<std::string, OutputArtifact>>& available) {
  ExportReport report;
  const std::filesystem::path folder = study.outputs_dir();
  std::filesystem::create_directories(folder);
  std::map<std::string, RecordedExport> recorded = recorded_exports(study.database());
  for (const WorkflowOutput& output : study.workflow().outputs) {
    const OutputArtifact* artifact = current_artifact(available, output);
    const auto previous = recorded.find(output.name);
    std::error_code error;
    if (artifact == nullptr) {
      if (previous == recorded.end()) continue;
      std::filesystem::remove(folder / previous->second.file, error);
      if (previous->second.file.ends_with(port_type_info(PortType::kAtlas).extension) ||
          previous->second.file.ends_with(".bundle")) {
        std::filesystem::remove_all(folder / output.name, error);
      }
      Transaction transaction(study.database());
      study.database()
          .prepare("DELETE FROM exports WHERE name = ?")
          .bind_text(1, output.name)
          .step();
      transaction.commit();
      report.removed.push_back(output.name);
      continue;
    }
    const std::filesystem::path blob = study.artifacts().path_of(artifact->hash);
    const std::string file = export_file_name(output.name, artifact->type, blob);
    const std::filesystem::path target = folder / file;
    // Folder-shaped values (an atlas, a File holding a folder bundle such as
    // an animation) are also unpacked into outputs/<name>/.
    const bool atlas = artifact->type == PortType::kAtlas || file.ends_with(".bundle");
    if (previous != recorded.end() && previous->second.hash == artifact->hash &&
        previous->second.file == file && std::filesystem::is_regular_file(target, error) &&
        same_content(target, blob) &&
        (!atlas || std::filesystem::is_directory(folder / output.name, error))) {
      continue;  // already current
    }
    if (previous != recorded.end() && previous->second.file != file) {
      std::filesystem::remove(folder / previous->second.file, error);
    }
    copy_atomically(blob, target);
    if (atlas) unpack_atlas_atomically(read_all(blob), folder / output.name);
    Transaction transaction(study.database());
    study.database()
        .prepare(
            "INSERT OR REPLACE INTO exports(name, hash, file, exported_at) VALUES (?, ?, ?, ?)")
        .bind_text(1, output.name)
        .bind_text(2, artifact->hash)
        .bind_text(3, file)
        .bind_text(4, utc_now())
        .step();
    transaction.commit();
    report.written.push_back(output.name);
  }
  return report;
}

std::vector<std::string> stale_exports(
    Study& study, const std::map<std::string, std::map<std::string, OutputArtifact>>& results) {
  std::vector<std::string> stale;
  const std::filesystem::path folder = study.outputs_dir();
  const std::map<std::string, RecordedExport> recorded = recorded_exports(study.database());
  for (const WorkflowOutput& output : study.workflow().outputs) {
    const OutputArtifact* artifact = current_artifact(results, output);
    const auto previous = recorded.find(output.name);
    const std::string name = "'" + output.name + "': ";
    if (artifact == nullptr) {
      if (previous != recorded.end()) {
        stale.push_back(name + "outputs/" + previous->second.file +
                        " is left from an earlier result (the node has no current one)");
      }
      continue;
    }
    if (previous == recorded.end()) {
      stale.push_back(name + "the result is not exported yet");
      continue;
    }
    const std::filesystem::path target = folder / previous->second.file;
    if (previous->second.hash != artifact->hash) {
      stale.push_back(name + "outputs/" + previous->second.file + " holds an earlier result");
      continue;
    }
    std::error_code error;
    const std::filesystem::path blob = study.artifacts().path_of(artifact->hash);
    if (!std::filesystem::is_regular_file(target, error)) {
      stale.push_back(name + "outputs/" + previous->second.file + " is missing");
    } else if (!same_content(target, blob)) {
      stale.push_back(name + "outputs/" + previous->second.file +
                      " was changed after it was exported");
    }
  }
  return stale;
}

}  // namespace mmm::workflow
