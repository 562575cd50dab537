#pragma once
// A folder as one deterministic byte string, so that a folder-shaped value
// (an atlas: atlas.yaml plus its meshes) can travel and be content-hashed like
// any other artifact. Equal folder contents always give equal bytes: nothing
// but relative paths and file bytes is recorded (no times, owners or modes),
// and the files come in one fixed order.
//
// Format (version 1), a text header line before each file's raw bytes:
//
//   mmm-bundle 1\n
//   <size> <relative/path>\n<exactly size bytes>     one per regular file,
//   <size> <relative/path>\n<exactly size bytes>     ordered by path bytewise
//   ...
//   end\n
//
//   size  decimal byte count, no sign, no leading zero ("0" for an empty file)
//   path  relative, '/'-separated, non-empty components, none "." or "..",
//         no backslash and no control character (so no line break)
//
// Only files are recorded: an empty folder is not. The form is canonical:
// readers reject anything pack_directory() would not write (paths out of
// order or repeated, sizes with leading zeros, bytes after `end`), so two
// bundles of the same files never differ and never hash differently.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mmm {

// The bundle of every regular file below `dir`, recursively (hidden files
// included). A symbolic link to a file inside `dir` is recorded under the
// link's own path with the target's bytes. The whole bundle is built in
// memory. Throws IoError naming the offending path when `dir` does not exist
// or is not a folder, for a link that points outside `dir`, dangles or points
// to a folder (which could loop back on itself), for anything that is neither
// a file nor a folder (fifo, socket, device), for a name the format cannot
// carry (line break, backslash), and for a file that cannot be read.
std::string pack_directory(const std::filesystem::path& dir);

// Writes the files of `bundle` below `dir`, creating `dir` and the subfolders
// as needed; files already there under other names are left alone, files of
// the same name are replaced (each one atomically, see write_file_atomically).
// The whole bundle is checked before anything is written, so a malformed one
// writes nothing. `what` names the bundle in messages ("study input 'atlas'").
// Throws InvalidInputError naming `what`, the entry number and byte offset for
// a wrong magic line or version, a malformed header line, a size running past
// the end, a path that is absolute or climbs out (`..`, empty components,
// backslashes), a repeated or out-of-order path, a path that needs a file to
// be a folder, a missing `end` line or bytes after it. Throws IoError when
// writing fails or an existing folder on the way is a symbolic link (writing
// through it could land outside `dir`).
void unpack_directory(std::string_view bundle, const std::filesystem::path& dir,
                      std::string_view what);

// The relative paths of the files in `bundle`, in bundle order. Checks the
// bundle like unpack_directory() (same InvalidInputError).
std::vector<std::string> bundle_file_names(std::string_view bundle, std::string_view what);

// The bytes of the file `relative_path` in `bundle`. Checks the bundle like
// unpack_directory(); throws InvalidInputError naming `what` and the path
// (with a close name when there is one) when the bundle has no such file.
std::string bundle_file(std::string_view bundle, std::string_view relative_path,
                        std::string_view what);

}  // namespace mmm
