#include "core/mesh/io/vtp_series.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <system_error>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"

namespace mmm::mesh {

namespace {

// Part names and the stem become file names: keep them to characters that
// are safe on every file system and in ParaView's pipeline browser.
bool is_safe_name(const std::string& name) {
  return !name.empty() && name != "." && name != ".." &&
         std::all_of(name.begin(), name.end(), [](char c) {
           return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                  c == '_' || c == '-' || c == '.';
         });
}

void check_name(const std::string& name, const char* what) {
  if (!is_safe_name(name)) {
    throw InvalidInputError(std::string("animation ") + what + " '" + name +
                            "' is not a safe file-name fragment: use letters, digits, '_', '-' "
                            "and '.' (e.g. 'femur_r', 'soleus_r-fibres')");
  }
}

// 7 -> "0007"; wider numbers keep all their digits.
std::string padded_frame(int frame) {
  std::string digits = std::to_string(frame);
  constexpr std::size_t kWidth = 4;
  if (digits.size() < kWidth) digits.insert(0, kWidth - digits.size(), '0');
  return digits;
}

}  // namespace

VtpSeriesWriter::VtpSeriesWriter(std::filesystem::path folder, std::string stem)
    : folder_(std::move(folder)), stem_(std::move(stem)) {
  check_name(stem_, "stem");
}

std::filesystem::path VtpSeriesWriter::pvd_path() const { return folder_ / (stem_ + ".pvd"); }

std::filesystem::path VtpSeriesWriter::prepare(double time, int frame, const std::string& part) {
  if (finished_) {
    throw std::logic_error("VtpSeriesWriter: frame added to '" + pvd_path().string() +
                           "' after finish()");
  }
  check_name(part, "part");
  if (!std::isfinite(time)) {
    throw InvalidInputError("animation part '" + part + "' frame " + std::to_string(frame) +
                            " has a non-finite time (NaN or inf)");
  }
  if (frame < 0) {
    throw InvalidInputError("animation part '" + part + "' has frame number " +
                            std::to_string(frame) + "; frames are numbered from 0");
  }
  if (frames_taken_.contains({part, frame})) {
    throw InvalidInputError("animation part '" + part + "' frame " + std::to_string(frame) +
                            " was already added (each part takes a frame number once)");
  }
  if (times_taken_.contains({part, time})) {
    std::string time_text;
    io_detail::append_number(time_text, time);
    throw InvalidInputError("animation part '" + part + "' already has a frame at time " +
                            time_text + " (ParaView shows one data set per part and time step)");
  }
  const std::filesystem::path subfolder = folder_ / stem_;
  std::error_code error;
  std::filesystem::create_directories(subfolder, error);
  if (error) throw IoError(subfolder, "cannot create the animation folder: " + error.message());
  return std::filesystem::path(stem_) / (part + "_" + padded_frame(frame) + ".vtp");
}

void VtpSeriesWriter::record(double time, int frame, const std::string& part,
                             const std::filesystem::path& relative) {
  auto known = std::find(parts_.begin(), parts_.end(), part);
  if (known == parts_.end()) known = parts_.insert(parts_.end(), part);
  entries_.push_back(
      PvdEntry{time, relative, static_cast<int>(std::distance(parts_.begin(), known)), part});
  frames_taken_.emplace(part, frame);
  times_taken_.emplace(part, time);
  written_.push_back(folder_ / relative);
}

void VtpSeriesWriter::add_surface(double time, int frame, const std::string& part,
                                  const IndexedMesh& mesh, const VtpArrays& arrays) {
  const std::filesystem::path relative = prepare(time, frame, part);
  write_vtp(mesh, folder_ / relative, arrays);
  record(time, frame, part, relative);
}

void VtpSeriesWriter::add_polylines(double time, int frame, const std::string& part,
                                    const Polylines& lines, const VtpArrays& arrays) {
  const std::filesystem::path relative = prepare(time, frame, part);
  write_vtp_polylines(lines, folder_ / relative, arrays);
  record(time, frame, part, relative);
}

void VtpSeriesWriter::finish() {
  if (finished_) {
    throw std::logic_error("VtpSeriesWriter: finish() called twice for '" + pvd_path().string() +
                           "'");
  }
  if (entries_.empty()) {
    throw InvalidInputError("cannot write " + pvd_path().string() +
                            ": no frame was added (an empty animation; add_surface or "
                            "add_polylines first)");
  }
  std::vector<PvdEntry> sorted = entries_;
  std::stable_sort(sorted.begin(), sorted.end(), [](const PvdEntry& a, const PvdEntry& b) {
    return a.time != b.time ? a.time < b.time : a.part < b.part;
  });
  write_pvd(sorted, pvd_path());
  finished_ = true;
  written_.push_back(pvd_path());
}

}  // namespace mmm::mesh
