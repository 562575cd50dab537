#pragma once
// Whole-file reading, with checks worded for the image formats of core/image/
// (PNG, view sidecars). Not part of the public contract: use png.h and
// projection.h (writing goes through core/file_bytes.h).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace mmm::image::detail {

// The whole content of a regular file. Throws IoError naming the path when it
// does not exist ("no such file"), is a directory, is empty or cannot be read;
// `kind` names what was expected ("a PNG file") in those messages. A file
// larger than `max_bytes` is refused before it is read, the limit named.
std::string read_file_bytes(const std::filesystem::path& path, std::string_view kind,
                            std::uintmax_t max_bytes);

}  // namespace mmm::image::detail
