#include "core/directory_bundle.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <optional>
#include <set>
#include <system_error>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/suggest.h"

namespace mmm {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kMagic = "mmm-bundle";
constexpr std::string_view kFirstLine = "mmm-bundle 1";
constexpr std::string_view kEndLine = "end";

// Why `path` cannot be a bundle path, or "" when it can. One rule for both
// directions: pack refuses to write what unpack would refuse to read.
std::string path_problem(std::string_view path) {
  if (path.empty()) return "it is empty";
  if (path.front() == '/') return "it is absolute";
  for (const char c : path) {
    if (c == '\\') return "it contains a backslash";
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "it contains a control character";
  }
  std::size_t start = 0;
  while (true) {
    const std::size_t slash = path.find('/', start);
    const std::string_view component = path.substr(
        start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
    if (component.empty()) return "it has an empty component ('//' or a trailing '/')";
    if (component == "." || component == "..") {
      return "it has a '" + std::string(component) + "' component";
    }
    if (slash == std::string_view::npos) return "";
    start = slash + 1;
  }
}

// ---- packing ----------------------------------------------------------------

struct SourceFile {
  std::string relative;  // bundle path
  fs::path location;     // where to read the bytes (the target, for a link)
};

// Whether the canonical path `target` is `root` or below it.
bool is_within(const fs::path& root, const fs::path& target) {
  return std::mismatch(root.begin(), root.end(), target.begin(), target.end()).first == root.end();
}

// Adds the file reached through the symbolic link `link`, which must point to
// a regular file inside `root`. Links to folders are refused rather than
// followed: one may point at its own ancestor and the walk would never end.
void add_link_target(const fs::path& root, const fs::path& link, std::string relative,
                     std::vector<SourceFile>& files) {
  std::error_code error;
  const fs::path target = fs::canonical(link, error);
  if (error) {
    throw IoError(link, "is a symbolic link whose target cannot be resolved (" + error.message() +
                            "); remove it or copy the file in its place");
  }
  if (!is_within(root, target)) {
    throw IoError(link, "is a symbolic link to '" + target.string() +
                            "', outside the folder being bundled; copy the file in instead");
  }
  const fs::file_status status = fs::status(target, error);
  if (fs::is_directory(status)) {
    throw IoError(link,
                  "is a symbolic link to a folder; bundles follow links to files only "
                  "(a folder link may loop back on itself): copy the folder in instead");
  }
  if (!fs::is_regular_file(status)) {
    throw IoError(link, "is a symbolic link to something that is not a regular file");
  }
  files.push_back({std::move(relative), target});
}

void collect_files(const fs::path& root, const fs::path& folder, const std::string& prefix,
                   std::vector<SourceFile>& files) {
  std::error_code error;
  fs::directory_iterator entries(folder, error);
  if (error) throw IoError(folder, "cannot list the folder: " + error.message());
  for (; entries != fs::directory_iterator(); entries.increment(error)) {
    const fs::path& path = entries->path();
    std::string relative = prefix + path.filename().string();
    if (const std::string problem = path_problem(relative); !problem.empty()) {
      throw IoError(path, "cannot be put in a bundle: " + problem + " in its name");
    }
    const fs::file_status status = entries->symlink_status(error);
    if (error) throw IoError(path, "cannot be examined: " + error.message());
    if (fs::is_symlink(status)) {
      add_link_target(root, path, std::move(relative), files);
    } else if (fs::is_directory(status)) {
      collect_files(root, path, relative + "/", files);
    } else if (fs::is_regular_file(status)) {
      files.push_back({std::move(relative), path});
    } else {
      throw IoError(path, "is neither a regular file nor a folder (a fifo, socket or device?)");
    }
  }
  if (error) throw IoError(folder, "cannot list the folder: " + error.message());
}

// ---- reading ----------------------------------------------------------------

bool is_digit(char c) { return c >= '0' && c <= '9'; }

struct BundleEntry {
  std::string_view path;
  std::string_view bytes;
};

// A printable excerpt of a header line for messages: at most 60 characters,
// anything unprintable shown as '?'.
std::string excerpt(std::string_view line) {
  constexpr std::size_t kLongest = 60;
  std::string text;
  for (const char c : line.substr(0, kLongest)) {
    text +=
        (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) ? '?' : c;
  }
  if (line.size() > kLongest) text += "...";
  return "'" + text + "'";
}

// Reads and checks a whole bundle, keeping views into it. Everything is
// checked before a caller acts on any entry.
class BundleParser {
 public:
  BundleParser(std::string_view bundle, std::string_view what) : bundle_(bundle), what_(what) {}

  std::vector<BundleEntry> parse() {
    read_first_line();
    std::vector<BundleEntry> entries;
    // Files of the bundle; a later path may not treat one as a folder.
    std::set<std::string_view> file_paths;
    for (std::size_t number = 1;; ++number) {
      const std::size_t line_start = offset_;
      const std::optional<std::string_view> line = next_line();
      if (!line) {
        throw error(number, line_start,
                    "the bundle ends without its closing 'end' line (truncated?)");
      }
      if (*line == kEndLine) {
        if (offset_ != bundle_.size()) {
          throw error(number, line_start,
                      std::to_string(bundle_.size() - offset_) +
                          " byte(s) follow the closing 'end' line (trailing garbage)");
        }
        return entries;
      }
      BundleEntry entry = read_entry(number, line_start, *line);
      check_place(number, line_start, entry.path, entries, file_paths);
      file_paths.insert(entry.path);
      entries.push_back(entry);
    }
  }

 private:
  InvalidInputError error(std::size_t entry, std::size_t at, const std::string& problem) const {
    const std::string where =
        entry == 0 ? "first line"
                   : "entry " + std::to_string(entry) + " at byte offset " + std::to_string(at);
    return InvalidInputError{std::string(what_) + ": malformed directory bundle, " + where + ": " +
                             problem};
  }

  // The line starting at offset_ without its '\n' (offset_ moves past it), or
  // std::nullopt when no line break follows.
  std::optional<std::string_view> next_line() {
    const std::size_t end = bundle_.find('\n', offset_);
    if (end == std::string_view::npos) return std::nullopt;
    const std::string_view line = bundle_.substr(offset_, end - offset_);
    offset_ = end + 1;
    return line;
  }

  void read_first_line() {
    const std::optional<std::string_view> line = next_line();
    if (!line) {
      throw error(0, 0, "no line break in the bundle (truncated, or not a directory bundle)");
    }
    if (*line == kFirstLine) return;
    if (line->starts_with(std::string(kMagic) + " ")) {
      const std::string_view version = line->substr(kMagic.size() + 1);
      if (!version.empty() && std::all_of(version.begin(), version.end(), is_digit)) {
        throw error(0, 0,
                    "unsupported format version " + excerpt(version) +
                        " (this build reads version 1; a newer mmm wrote it?)");
      }
    }
    throw error(0, 0,
                "expected '" + std::string(kFirstLine) + "', got " + excerpt(*line) +
                    " (not a directory bundle)");
  }

  BundleEntry read_entry(std::size_t number, std::size_t at, std::string_view line) {
    const std::size_t space = line.find(' ');
    if (space == std::string_view::npos) {
      throw error(
          number, at,
          "malformed header line " + excerpt(line) + " (expected '<size> <path>' or 'end')");
    }
    const std::string_view size_text = line.substr(0, space);
    const std::string_view path = line.substr(space + 1);
    const bool digits_only =
        !size_text.empty() && std::all_of(size_text.begin(), size_text.end(), is_digit);
    if (!digits_only || (size_text.size() > 1 && size_text.front() == '0')) {
      throw error(number, at,
                  "malformed size " + excerpt(size_text) +
                      " in the header line (expected a decimal byte count without leading zeros)");
    }
    std::uint64_t size = 0;
    // Only digits were given, so the one possible failure is overflow.
    if (std::from_chars(size_text.data(), size_text.data() + size_text.size(), size).ec !=
        std::errc()) {
      throw error(number, at, "size " + excerpt(size_text) + " is too large");
    }
    if (const std::string problem = path_problem(path); !problem.empty()) {
      throw error(number, at,
                  "unsafe path " + excerpt(path) + ": " + problem +
                      " (paths must stay inside the target folder)");
    }
    const std::size_t left = bundle_.size() - offset_;
    if (size > left) {
      throw error(number, at,
                  "file " + excerpt(path) + " of " + std::to_string(size) +
                      " bytes runs past the end of the bundle (" + std::to_string(left) +
                      " bytes left; truncated?)");
    }
    const BundleEntry entry{path, bundle_.substr(offset_, static_cast<std::size_t>(size))};
    offset_ += static_cast<std::size_t>(size);
    return entry;
  }

  // Paths come in strictly increasing bytewise order (which also rules out
  // repeats), and no path runs through an earlier file as if it were a
  // folder. In that order a file "a" always precedes every "a/...", so
  // checking the prefixes of each new path against earlier files suffices.
  void check_place(std::size_t number, std::size_t at, std::string_view path,
                   const std::vector<BundleEntry>& previous,
                   const std::set<std::string_view>& file_paths) const {
    if (!previous.empty()) {
      const std::string_view last = previous.back().path;
      if (path == last) throw error(number, at, "repeats the path " + excerpt(path));
      if (path < last) {
        throw error(number, at,
                    "path " + excerpt(path) + " comes after " + excerpt(last) +
                        " (paths must be in bytewise order)");
      }
    }
    for (std::size_t slash = path.find('/'); slash != std::string_view::npos;
         slash = path.find('/', slash + 1)) {
      const std::string_view folder = path.substr(0, slash);
      if (file_paths.contains(folder)) {
        throw error(number, at,
                    "path " + excerpt(path) + " needs " + excerpt(folder) +
                        " to be a folder, but the bundle holds a file of that name");
      }
    }
  }

  std::string_view bundle_;
  std::string_view what_;
  std::size_t offset_ = 0;
};

std::vector<BundleEntry> parse_bundle(std::string_view bundle, std::string_view what) {
  return BundleParser(bundle, what).parse();
}

// ---- writing ----------------------------------------------------------------

// Creates the folders of `relative` (a checked bundle path) below `dir`,
// refusing to go through a symbolic link or a file on the way: the bundle is
// checked, but the folder it is written into may hold anything.
void make_parent_folders(const fs::path& dir, std::string_view relative) {
  fs::path folder = dir;
  for (std::size_t slash = relative.find('/'), start = 0; slash != std::string_view::npos;
       start = slash + 1, slash = relative.find('/', start)) {
    folder /= std::string(relative.substr(start, slash - start));
    std::error_code error;
    const fs::file_status status = fs::symlink_status(folder, error);
    if (fs::is_symlink(status)) {
      throw IoError(folder,
                    "is a symbolic link; a bundle is never written through one (it could lead "
                    "outside '" +
                        dir.string() + "'): remove it or unpack into an empty folder");
    }
    if (fs::is_directory(status)) continue;
    if (fs::exists(status)) {
      throw IoError(folder,
                    "is a file where the bundle needs a folder; unpack into an empty folder");
    }
    if (!fs::create_directory(folder, error) && error) {
      throw IoError(folder, "cannot create the folder: " + error.message());
    }
  }
}

}  // namespace

std::string pack_directory(const fs::path& dir) {
  std::error_code error;
  const fs::file_status status = fs::status(dir, error);
  if (status.type() == fs::file_type::not_found) {
    throw IoError(dir, "no such folder; give the folder to bundle");
  }
  if (error) throw IoError(dir, "cannot examine the folder: " + error.message());
  if (!fs::is_directory(status)) throw IoError(dir, "is not a folder; give the folder to bundle");
  const fs::path root = fs::canonical(dir, error);
  if (error) throw IoError(dir, "cannot resolve the folder: " + error.message());

  std::vector<SourceFile> files;
  collect_files(root, dir, "", files);
  // Bytewise order: std::string compares as unsigned char (char_traits<char>).
  std::sort(files.begin(), files.end(),
            [](const SourceFile& a, const SourceFile& b) { return a.relative < b.relative; });

  std::string bundle = std::string(kFirstLine) + "\n";
  for (const SourceFile& file : files) {
    const std::uintmax_t size = fs::file_size(file.location, error);
    if (error) throw IoError(file.location, "cannot read the file size: " + error.message());
    bundle += std::to_string(size) + " " + file.relative + "\n";
    bundle += read_file_bytes(file.location, size);
  }
  bundle += std::string(kEndLine) + "\n";
  return bundle;
}

void unpack_directory(std::string_view bundle, const fs::path& dir, std::string_view what) {
  const std::vector<BundleEntry> entries = parse_bundle(bundle, what);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw IoError(dir, "cannot create the folder to unpack " + std::string(what) + " into" +
                           (error ? ": " + error.message() : std::string()));
  }
  for (const BundleEntry& entry : entries) {
    make_parent_folders(dir, entry.path);
    write_file_atomically(dir / std::string(entry.path), entry.bytes, "a bundled file");
  }
}

std::vector<std::string> bundle_file_names(std::string_view bundle, std::string_view what) {
  const std::vector<BundleEntry> entries = parse_bundle(bundle, what);
  std::vector<std::string> names;
  names.reserve(entries.size());
  for (const BundleEntry& entry : entries) names.emplace_back(entry.path);
  return names;
}

std::string bundle_file(std::string_view bundle, std::string_view relative_path,
                        std::string_view what) {
  const std::vector<BundleEntry> entries = parse_bundle(bundle, what);
  for (const BundleEntry& entry : entries) {
    if (entry.path == relative_path) return std::string(entry.bytes);
  }
  std::vector<std::string> names;
  names.reserve(entries.size());
  for (const BundleEntry& entry : entries) names.emplace_back(entry.path);
  throw InvalidInputError(std::string(what) + ": the bundle holds no file '" +
                          std::string(relative_path) + "'" + did_you_mean(relative_path, names) +
                          " (it holds " + std::to_string(names.size()) + " file(s))");
}

}  // namespace mmm
