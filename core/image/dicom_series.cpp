// A folder of DICOM radiographs: a bounded walk, the de-identified series
// document, and the choice of a view's image by its View Position.

#include "core/image/dicom_series.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/deidentified_radiograph.h"

namespace mmm::image {

namespace fs = std::filesystem;
using SeriesJson = nlohmann::json;

namespace {

constexpr std::string_view kSeriesFormat = "mmm-deidentified-radiograph-series";
constexpr int kSeriesVersion = 1;
// What a PS3.10 file needs to be recognised (preamble + "DICM").
constexpr std::uintmax_t kDicomHeadBytes = 132;

bool is_dicomdir(const fs::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return name == "DICOMDIR";
}

bool file_looks_like_dicom(const fs::path& path, std::uintmax_t size) {
  if (is_dicomdir(path)) return false;
  return looks_like_dicom(read_file_bytes(path, std::min(size, kDicomHeadBytes)));
}

// Calls `visit` for every regular file under `folder` (sorted by path)
// until it returns false. Throws IoError naming what broke a bound when
// `strict`; otherwise stops quietly there.
void walk_folder(const fs::path& folder, bool strict,
                 const std::function<bool(const fs::path&, std::uintmax_t)>& visit) {
  std::vector<std::pair<fs::path, int>> pending = {{folder, 0}};
  std::size_t entries = 0;
  while (!pending.empty()) {
    const auto [dir, depth] = pending.back();
    pending.pop_back();
    std::error_code error;
    std::vector<fs::directory_entry> children;
    for (fs::directory_iterator it(dir, error); !error && it != fs::directory_iterator();
         it.increment(error)) {
      if (++entries > kDicomFolderMaxEntries) {
        if (!strict) return;
        throw IoError(folder, "holds more than " + std::to_string(kDicomFolderMaxEntries) +
                                  " files and folders; hint: give the folder of the series "
                                  "(or the radiograph's file) rather than a whole archive");
      }
      children.push_back(*it);
    }
    if (error) {
      if (!strict) return;
      throw IoError(dir, "cannot list the folder: " + error.message());
    }
    std::sort(children.begin(), children.end(),
              [](const fs::directory_entry& a, const fs::directory_entry& b) {
                return a.path() < b.path();
              });
    std::vector<fs::path> subfolders;
    for (const fs::directory_entry& child : children) {
      const bool link = child.is_symlink(error);
      if (child.is_directory(error)) {
        if (link) {
          if (!strict) continue;
          throw IoError(child.path(),
                        "is a link to a folder, which is not followed; hint: copy "
                        "the series into one folder");
        }
        if (depth + 1 > kDicomFolderMaxDepth) {
          if (!strict) continue;
          throw IoError(child.path(), "is nested more than " +
                                          std::to_string(kDicomFolderMaxDepth) +
                                          " folders deep in " + folder.string() +
                                          "; hint: give the folder of the series itself");
        }
        subfolders.push_back(child.path());
        continue;
      }
      if (!child.is_regular_file(error)) continue;
      const std::uintmax_t size = child.file_size(error);
      if (error) continue;
      if (!visit(child.path(), size)) return;
    }
    // Depth first, in path order: push in reverse so the first comes out first.
    std::reverse(subfolders.begin(), subfolders.end());
    for (const fs::path& subfolder : subfolders) pending.emplace_back(subfolder, depth + 1);
  }
}

const std::set<std::string, std::less<>>& frontal_positions() {
  static const std::set<std::string, std::less<>> positions = {"AP", "PA"};
  return positions;
}
const std::set<std::string, std::less<>>& lateral_positions() {
  static const std::set<std::string, std::less<>> positions = {"LL", "RL", "LATERAL"};
  return positions;
}

std::string image_list(const std::vector<DicomRadiograph>& images) {
  std::string text;
  for (std::size_t k = 0; k < images.size(); ++k) {
    const DicomRadiograph& image = images[k];
    text += "\n  image " + std::to_string(k + 1) + ": " + std::to_string(image.columns) + " x " +
            std::to_string(image.rows) + ", View Position (0018,5101) " +
            (image.view_position ? "'" + *image.view_position + "'" : "absent");
  }
  return text;
}

}  // namespace

bool folder_holds_dicom(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return false;
  bool found = false;
  walk_folder(folder, false, [&found](const fs::path& path, std::uintmax_t size) {
    found = file_looks_like_dicom(path, size);
    return !found;
  });
  return found;
}

std::vector<DicomRadiograph> read_dicom_folder(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    throw IoError(folder, "is not a folder; hint: give a folder of DICOM files or one file");
  }
  std::vector<fs::path> files;
  walk_folder(folder, true, [&files, &folder](const fs::path& path, std::uintmax_t size) {
    if (!file_looks_like_dicom(path, size)) return true;
    if (files.size() == kDicomFolderMaxImages) {
      throw IoError(folder, "holds more than " + std::to_string(kDicomFolderMaxImages) +
                                " DICOM files; hint: give the folder of one series, or the "
                                "radiograph's file");
    }
    files.push_back(path);
    return true;
  });
  if (files.empty()) {
    throw IoError(folder,
                  "holds no DICOM file (none starts with the DICM preamble); hint: give "
                  "the folder of the series, or the radiograph's file");
  }
  std::vector<DicomRadiograph> images;
  std::set<std::string, std::less<>> seen;
  for (const fs::path& file : files) {
    DicomRadiograph image = read_dicom_radiograph(file);
    if (!seen.insert(image.sop_instance_uid_sha256).second) continue;  // a copy
    images.push_back(std::move(image));
  }
  return images;
}

std::string deidentified_series_text(const std::vector<DicomRadiograph>& images) {
  if (images.empty()) throw InvalidInputError("a de-identified series needs at least one image");
  // Keys in nlohmann's order ("format" < "images" < "version"), so that
  // is_deidentified_series() can tell the document by its first bytes.
  std::string text = R"({"format":")" + std::string(kSeriesFormat) + R"(","images":[)";
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (k > 0) text += ',';
    text += deidentified_radiograph_text(images[k]);
  }
  text += R"(],"version":)" + std::to_string(kSeriesVersion) + "}";
  return text;
}

bool is_deidentified_series(std::string_view bytes) {
  const std::string head = R"({"format":")" + std::string(kSeriesFormat) + "\"";
  return bytes.starts_with(head);
}

std::vector<DicomRadiograph> deidentified_series_from_text(std::string_view text,
                                                           const fs::path& source) {
  SeriesJson root;
  try {
    root = parse_json(text, JsonLimits{kDeidentifiedSeriesMaxBytes, 9});
  } catch (const SeriesJson::parse_error& error) {
    throw IoError(source, std::string("is not a de-identified series (JSON): ") + error.what());
  }
  if (!root.is_object()) throw IoError(source, "a de-identified series must be a JSON object");
  for (const auto& [key, value] : root.items()) {
    if (key != "format" && key != "version" && key != "images") {
      throw IoError(source, "unknown field '" + key + "' in a de-identified series");
    }
  }
  if (!root.contains("format") || root["format"] != kSeriesFormat) {
    throw IoError(source, "field 'format' must be \"" + std::string(kSeriesFormat) + "\"");
  }
  if (!root.contains("version") || root["version"] != kSeriesVersion) {
    throw IoError(source, "field 'version' must be " + std::to_string(kSeriesVersion) +
                              "; hint: create the study again with this version of mmm");
  }
  const auto images_field = root.find("images");
  if (images_field == root.end() || !images_field->is_array() || images_field->empty() ||
      images_field->size() > kDicomFolderMaxImages) {
    throw IoError(source, "field 'images' must be an array of 1 to " +
                              std::to_string(kDicomFolderMaxImages) + " de-identified radiographs");
  }
  std::vector<DicomRadiograph> images;
  images.reserve(images_field->size());
  for (std::size_t k = 0; k < images_field->size(); ++k) {
    const fs::path where = source.string() + " (image " + std::to_string(k + 1) + ")";
    images.push_back(deidentified_radiograph_from_text((*images_field)[k].dump(), where));
  }
  return images;
}

SeriesChoice choose_view_image(const std::vector<DicomRadiograph>& images,
                               std::string_view view_name, const fs::path& source) {
  if (images.empty()) throw IoError(source, "holds no radiograph");
  const std::set<std::string, std::less<>>* positions = nullptr;
  if (view_name == "frontal") positions = &frontal_positions();
  if (view_name == "lateral") positions = &lateral_positions();
  if (positions == nullptr) {
    throw IoError(source, "cannot choose an image for the view '" + std::string(view_name) +
                              "' (known: frontal, lateral)");
  }
  if (images.size() == 1) {
    return {0, "the folder's only radiograph"};
  }
  std::vector<std::size_t> matches;
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (images[k].view_position && positions->contains(*images[k].view_position)) {
      matches.push_back(k);
    }
  }
  const std::string wanted = view_name == "frontal" ? "AP or PA" : "LL, RL or LATERAL";
  if (matches.size() != 1) {
    throw IoError(source, "holds " + std::to_string(images.size()) + " radiographs and " +
                              (matches.empty() ? "none" : std::to_string(matches.size())) +
                              " with a View Position (0018,5101) of " + wanted + " for the " +
                              std::string(view_name) + " view:" + image_list(images) +
                              "\nhint: give that view's file, or a folder holding only its series");
  }
  const std::size_t index = matches.front();
  return {index, "image " + std::to_string(index + 1) + " of " + std::to_string(images.size()) +
                     ", View Position " + *images[index].view_position};
}

}  // namespace mmm::image
