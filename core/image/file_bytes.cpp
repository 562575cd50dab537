#include "core/image/file_bytes.h"

#include <cstdint>
#include <fstream>
#include <random>
#include <system_error>

#include "core/errors.h"

namespace mmm::image::detail {

namespace fs = std::filesystem;

namespace {

// 64 random bits in hex: concurrent writers of the same file (threads or
// processes) never share a temporary.
std::string temporary_suffix() {
  std::random_device device;
  std::string suffix = ".tmp-";
  constexpr std::string_view kHex = "0123456789abcdef";
  for (int word = 0; word < 2; ++word) {
    std::uint32_t value = device();
    for (int k = 0; k < 8; ++k, value >>= 4U) suffix.push_back(kHex[value & 0xFU]);
  }
  return suffix;
}

}  // namespace

std::string read_file_bytes(const fs::path& path, std::string_view kind) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::not_found) {
    throw IoError(path, "no such file (check the path and the working directory)");
  }
  if (error) throw IoError(path, "cannot access the file: " + error.message());
  if (fs::is_directory(status)) {
    throw IoError(path, "is a directory, not " + std::string(kind));
  }
  if (!fs::is_regular_file(status)) {
    throw IoError(path, "is not a regular file, not " + std::string(kind));
  }
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) throw IoError(path, "cannot determine the file size: " + error.message());
  if (size == 0) throw IoError(path, "file is empty (0 bytes); was it written completely?");
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

void write_file_atomically(const fs::path& path, std::string_view bytes) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    throw IoError(path, "is a directory; cannot write a file in its place");
  }
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, error)) {
    throw IoError(path, "cannot write: the folder '" + parent.string() +
                            "' does not exist (create it first)");
  }
  const fs::path temp = parent / ("." + path.filename().string() + temporary_suffix());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path, "cannot open a temporary file beside it for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      out.close();
      fs::remove(temp, error);
      throw IoError(path, "writing failed (disk full?)");
    }
  }
  fs::rename(temp, path, error);
  if (error) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw IoError(path, "cannot rename the temporary file onto it: " + error.message());
  }
}

}  // namespace mmm::image::detail
