#pragma once
// Whole-file reading and atomic writing for the image formats of core/image/
// (PNG, view sidecars). Not part of the public contract: use png.h and
// projection.h.

#include <filesystem>
#include <string>
#include <string_view>

namespace mmm::image::detail {

// The whole content of a regular file. Throws IoError naming the path when it
// does not exist ("no such file"), is a directory, is empty or cannot be read;
// `kind` names what was expected ("a PNG file") in those messages.
std::string read_file_bytes(const std::filesystem::path& path, std::string_view kind);

// Writes `bytes` to a temporary sibling of `path` and renames it onto `path`,
// so that a crash never leaves a half-written file under the final name. The
// parent folder must exist. Throws IoError on failure (the temporary is
// removed).
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace mmm::image::detail
