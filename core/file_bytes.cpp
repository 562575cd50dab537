#include "core/file_bytes.h"

#include <fstream>
#include <random>
#include <system_error>

#include "core/errors.h"

namespace mmm {

namespace fs = std::filesystem;

namespace {

std::string random_suffix() {
  std::random_device device;
  std::string suffix;
  constexpr std::string_view kHex = "0123456789abcdef";
  for (int i = 0; i < 4; ++i) {
    unsigned value = device();
    for (int k = 0; k < 4; ++k) {
      suffix.push_back(kHex[value & 0xFU]);
      value >>= 4U;
    }
  }
  return suffix;
}

}  // namespace

std::string read_file_bytes(const fs::path& path, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "cannot open the file for reading (check its permissions)");
  std::string data(static_cast<std::size_t>(size), '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  const auto got = static_cast<std::uintmax_t>(in.gcount());
  if (got != size) {
    throw IoError(path, "could not read the whole file: got " + std::to_string(got) + " of " +
                            std::to_string(size) + " bytes (is it being written?)");
  }
  return data;
}

void write_file_atomically(const fs::path& path, std::string_view bytes, std::string_view kind) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    throw IoError(path, "is a directory; cannot write " + std::string(kind) + " in its place");
  }
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, error)) {
    throw IoError(path, "cannot write: the folder '" + parent.string() +
                            "' does not exist (create it first)");
  }
  const fs::path temp = parent / ("." + path.filename().string() + ".tmp-" + random_suffix());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw IoError(path, "cannot create the temporary file '" + temp.filename().string() +
                              "' beside it (is the folder writable?)");
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      fs::remove(temp, error);
      throw IoError(path, "writing " + std::to_string(bytes.size()) +
                              " bytes failed (disk full or quota exceeded?)");
    }
  }
  fs::rename(temp, path, error);
  if (error) {
    const std::string reason = error.message();
    fs::remove(temp, error);
    throw IoError(path, "cannot move the written temporary file into place: " + reason);
  }
}

void replace_directory(const std::filesystem::path& staged, const std::filesystem::path& target) {
  const std::filesystem::path previous = target.string() + ".previous";
  std::filesystem::remove_all(previous);
  if (std::filesystem::exists(target)) std::filesystem::rename(target, previous);
  std::filesystem::rename(staged, target);
  std::filesystem::remove_all(previous);
}

}  // namespace mmm
