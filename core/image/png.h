#pragma once
// PNG (ISO/IEC 15948, W3C PNG 2nd edition) reading and writing for the images
// mmm produces and consumes: radiographs (8- or 16-bit grayscale), pictures of
// meshes (8-bit RGB) and, when reading, 8-bit RGBA.
//
// A PNG file is the 8-byte signature then chunks: length (4 bytes big-endian),
// type (4 ASCII letters), data, CRC-32 of type + data. IHDR gives the size and
// sample format; the concatenated IDAT chunks hold the zlib stream of the
// filtered rows (each row: a filter-type byte, then the row's bytes); IEND
// closes the file; tEXt chunks carry "keyword\0text" metadata.
//   write: rows -> filter each row (all five filters available; by default
//          the one with the least sum of |signed bytes|, the libpng heuristic)
//          -> zlib deflate -> IDAT chunks of <= 256 KiB
//   read:  libspng (a decoder written for untrusted files and fuzzed
//          continuously upstream), with the size limits below applied to the
//          file and to the header's dimensions before anything is decoded.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/image/image.h"

namespace mmm::image {

// Reading limits. A file above kPngMaxFileBytes is refused before it is read;
// a header asking for more than kPngMaxSide pixels on a side, or for more than
// kPngMaxDecodedBytes of samples, is refused before the image data is
// inflated (a few hundred compressed bytes can claim gigabytes). An EOS
// full-body image, ~2,000 x 9,000 16-bit pixels, is 34 MiB decoded.
inline constexpr std::uintmax_t kPngMaxFileBytes = std::uintmax_t{256} << 20U;
inline constexpr std::uint32_t kPngMaxSide = 65'535;
inline constexpr std::uint64_t kPngMaxDecodedBytes = std::uint64_t{512} << 20U;

// A tEXt chunk: keyword (1-79 printable Latin-1 characters, no leading,
// trailing or doubled spaces) and text (any bytes but NUL; Latin-1 by the
// standard, mmm writes ASCII).
struct PngText {
  std::string key;
  std::string value;
  friend bool operator==(const PngText&, const PngText&) = default;
};

// Row filter of a PNG scanline (values are the PNG filter-type byte).
enum class PngFilter : std::uint8_t { kNone = 0, kSub = 1, kUp = 2, kAverage = 3, kPaeth = 4 };

struct PngWriteOptions {
  // zlib level 0 (store) to 9 (smallest, slowest). 6 is zlib's default
  // balance; radiographs compress about 2:1 at any level above 1.
  int compression_level = 6;
  // true: per row, the filter with the least sum of absolute values of the
  // filtered bytes taken as signed (libpng's heuristic, good for photos and
  // radiographs). false: every row uses `filter`.
  bool adaptive_filter = true;
  PngFilter filter = PngFilter::kNone;
  // tEXt chunks written after IHDR, in this order.
  std::vector<PngText> text;
};

// Writes an image as a non-interlaced PNG: 8-bit grayscale, 16-bit grayscale
// or 8-bit RGB. The bytes go to a temporary sibling renamed onto `path`, so a
// failed write never leaves a partial file. Throws InvalidInputError for an
// empty image, pixels.size() != width * height * channels, a compression level
// outside [0, 9] or an invalid tEXt keyword/value; IoError naming the path
// when the file cannot be written (missing folder, permissions).
void write_png(const GrayImage8& image, const std::filesystem::path& path,
               const PngWriteOptions& options = {});
void write_png(const GrayImage16& image, const std::filesystem::path& path,
               const PngWriteOptions& options = {});
void write_png(const RgbImage8& image, const std::filesystem::path& path,
               const PngWriteOptions& options = {});

// The bytes write_png would write, for a PNG held in memory (e.g. embedded
// in a JSON artifact). Throws what write_png throws for the image and options.
std::string encode_png(const GrayImage8& image, const PngWriteOptions& options = {});
std::string encode_png(const GrayImage16& image, const PngWriteOptions& options = {});
std::string encode_png(const RgbImage8& image, const PngWriteOptions& options = {});

// What read_png found: the image in the format the file stores and the tEXt
// chunks in file order.
struct PngContent {
  std::variant<GrayImage8, GrayImage16, RgbImage8, RgbaImage8> image;
  std::vector<PngText> text;
};

// Reads a non-interlaced PNG holding 8- or 16-bit grayscale (colour type 0),
// 8-bit RGB (2) or 8-bit RGBA (6), any of the five row filters, split over
// any number of IDAT chunks. Ancillary chunks other than tEXt are skipped
// (their CRC is still checked); gamma, colour profiles and transparency keys
// are not applied. Throws IoError naming the path and the problem: missing or
// empty file, a file or image above the limits above, bad signature, a chunk
// whose CRC does not match, truncation (no IEND, a zlib stream that ends
// early), a corrupt zlib stream, an invalid filter byte, an unknown critical
// chunk, or a format outside the list above (palette, gray+alpha, bit depths
// 1/2/4, 16-bit colour, interlacing), the latter with a hint to convert the
// file.
PngContent read_png(const std::filesystem::path& path);

// The same from a PNG file's bytes already in memory (e.g. an image held in
// a study artifact); errors are IoErrors naming `path`, the file the bytes
// came from.
PngContent decode_png(const std::filesystem::path& path, const std::string& file);

// The grayscale image of a PNG as 16-bit samples: 16-bit files as stored,
// 8-bit ones widened exactly (v * 257, so 255 -> 65535). Throws what read_png
// throws, and IoError when the file holds colour ("holds 8-bit RGB, expected
// grayscale").
GrayImage16 read_png_gray16(const std::filesystem::path& path);

}  // namespace mmm::image
