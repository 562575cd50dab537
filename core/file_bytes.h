#pragma once
// Whole-file reading and crash-safe writing, shared by the file formats of
// core/ (meshes, PNG images, radiograph sidecars).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace mmm {

// The first `size` bytes of the file at `path` (the caller has checked that
// it is a regular file of that size). Throws IoError naming the path when it
// cannot be opened or yields fewer bytes.
std::string read_file_bytes(const std::filesystem::path& path, std::uintmax_t size);

// Writes `bytes` to a temporary sibling of `path` (a random name, so that
// concurrent writers never share one) and renames it onto `path`: a crash
// never leaves a half-written file under the final name. The parent folder
// must exist (nothing but the file is created). `kind` names what is written
// ("a mesh file") in the message for a directory in the way. Throws IoError
// on failure; the temporary file is removed.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           std::string_view kind = "a file");

// Puts the folder `staged` (complete) where `target` is: the old target is
// renamed aside, the staged one renamed in, the old one removed. A crash
// leaves either the old folder or the new one under `target`, never half of
// one (and at worst the old one beside it as "<target>.previous", removed by
// the next call). Throws std::filesystem::filesystem_error on failure.
void replace_directory(const std::filesystem::path& staged, const std::filesystem::path& target);

}  // namespace mmm
