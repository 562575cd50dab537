#include "core/image/file_bytes.h"

#include <cstdint>
#include <system_error>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace mmm::image::detail {

namespace fs = std::filesystem;

std::string read_file_bytes(const fs::path& path, std::string_view kind, std::uintmax_t max_bytes) {
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
  if (size > max_bytes) {
    throw IoError(path, "is " + std::to_string(size >> 20U) + " MiB, above the limit of " +
                            std::to_string(max_bytes >> 20U) + " MiB for " + std::string(kind) +
                            ": refused before reading (is it the right file?)");
  }
  return mmm::read_file_bytes(path, size);
}

}  // namespace mmm::image::detail
