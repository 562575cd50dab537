#include "core/image/png.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <span>
#include <sstream>
#include <string_view>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/file_bytes.h"

namespace mmm::image {

namespace fs = std::filesystem;

namespace {

constexpr std::array<std::uint8_t, 8> kSignature = {137, 80, 78, 71, 13, 10, 26, 10};
// Largest IDAT written: libpng's default is 8 KiB; larger chunks cost nothing
// and keep a radiograph's chunk list short.
constexpr std::size_t kMaxIdatBytes = std::size_t{256} * 1024;
// The PNG limit on chunk lengths and image dimensions (2^31 - 1).
constexpr std::uint32_t kPngMaxValue = 0x7FFFFFFFU;
// Largest filtered image data accepted when reading (2 GiB): far above any
// radiograph (a 2000 x 6000 16-bit EOS image is 24 MB) and a guard against a
// corrupt IHDR asking for terabytes.
constexpr std::uint64_t kMaxImageBytes = std::uint64_t{1} << 31U;

// PNG colour types.
constexpr int kGray = 0;
constexpr int kRgb = 2;
constexpr int kPalette = 3;
constexpr int kGrayAlpha = 4;
constexpr int kRgba = 6;

void append_u32(std::string& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out.push_back(static_cast<char>((value >> static_cast<unsigned>(shift)) & 0xFFU));
  }
}

std::uint32_t load_u32(const std::uint8_t* bytes) {
  return (std::uint32_t{bytes[0]} << 24U) | (std::uint32_t{bytes[1]} << 16U) |
         (std::uint32_t{bytes[2]} << 8U) | std::uint32_t{bytes[3]};
}

std::uint32_t crc_of(const std::uint8_t* bytes, std::size_t size) {
  return static_cast<std::uint32_t>(crc32_z(crc32_z(0, nullptr, 0), bytes, size));
}

std::string hex32(std::uint32_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << value;
  return out.str();
}

// Appends length, type, data and the CRC-32 of type + data.
void append_chunk(std::string& out, std::string_view type, std::span<const std::uint8_t> data) {
  append_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.append(type);
  out.append(reinterpret_cast<const char*>(data.data()), data.size());
  append_u32(out,
             crc_of(reinterpret_cast<const std::uint8_t*>(out.data() + start), out.size() - start));
}

void append_chunk(std::string& out, std::string_view type, std::string_view data) {
  append_chunk(out, type,
               std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
}

// Throws InvalidInputError unless the keyword and text make a valid tEXt chunk.
void check_text(const PngText& text) {
  const std::string& key = text.key;
  const auto fail = [&](const std::string& problem) {
    throw InvalidInputError("PNG tEXt keyword '" + key + "': " + problem);
  };
  if (key.empty() || key.size() > 79) {
    fail("must have 1 to 79 characters, has " + std::to_string(key.size()));
  }
  for (const char c : key) {
    const auto byte = static_cast<unsigned char>(c);
    if (!((byte >= 32 && byte <= 126) || byte >= 161)) {
      fail("holds a non-printable byte " + std::to_string(byte));
    }
  }
  if (key.front() == ' ' || key.back() == ' ' || key.find("  ") != std::string::npos) {
    fail("must not start or end with a space or hold two spaces in a row");
  }
  if (text.value.find('\0') != std::string::npos) fail("its text holds a NUL byte");
}

std::uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a);
  const int pb = std::abs(p - b);
  const int pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<std::uint8_t>(a);
  if (pb <= pc) return static_cast<std::uint8_t>(b);
  return static_cast<std::uint8_t>(c);
}

// Predictor of byte i of a row from its left neighbour a (bpp bytes back),
// the byte above b and the one above-left c (0 outside the image).
std::uint8_t predict(PngFilter filter, int a, int b, int c) {
  switch (filter) {
    case PngFilter::kNone:
      return 0;
    case PngFilter::kSub:
      return static_cast<std::uint8_t>(a);
    case PngFilter::kUp:
      return static_cast<std::uint8_t>(b);
    case PngFilter::kAverage:
      return static_cast<std::uint8_t>((a + b) / 2);
    case PngFilter::kPaeth:
      return paeth(a, b, c);
  }
  return 0;
}

// Filters one row (`row` and `prior` have the same length; prior is all zero
// for the first row) into out[0] = filter type, out[1..] = filtered bytes.
void filter_row(PngFilter filter, std::span<const std::uint8_t> row,
                std::span<const std::uint8_t> prior, std::size_t bpp, std::uint8_t* out) {
  out[0] = static_cast<std::uint8_t>(filter);
  for (std::size_t i = 0; i < row.size(); ++i) {
    const int a = i >= bpp ? row[i - bpp] : 0;
    const int c = i >= bpp ? prior[i - bpp] : 0;
    out[i + 1] = static_cast<std::uint8_t>(row[i] - predict(filter, a, prior[i], c));
  }
}

// Sum of the filtered bytes read as signed values, in absolute value.
std::uint64_t filter_cost(const std::uint8_t* filtered, std::size_t size) {
  std::uint64_t cost = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const int value = filtered[i];
    cost += static_cast<std::uint64_t>(value < 128 ? value : 256 - value);
  }
  return cost;
}

// The unfiltered bytes of every row, big-endian for 16-bit samples.
template <typename ImageT>
std::vector<std::uint8_t> raw_bytes(const ImageT& image) {
  using Sample = typename ImageT::Sample;
  std::vector<std::uint8_t> raw;
  if constexpr (sizeof(Sample) == 1) {
    raw.assign(image.pixels.begin(), image.pixels.end());
  } else {
    raw.reserve(image.pixels.size() * 2);
    for (const Sample sample : image.pixels) {
      raw.push_back(static_cast<std::uint8_t>(sample >> 8U));
      raw.push_back(static_cast<std::uint8_t>(sample & 0xFFU));
    }
  }
  return raw;
}

template <typename ImageT>
std::string encode_png(const ImageT& image, int colour_type, const PngWriteOptions& options) {
  using Sample = typename ImageT::Sample;
  if (image.width <= 0 || image.height <= 0) {
    throw InvalidInputError("cannot write an empty image as PNG (size " +
                            std::to_string(image.width) + " x " + std::to_string(image.height) +
                            ")");
  }
  if (image.pixels.size() != image.sample_count()) {
    throw InvalidInputError("image of " + std::to_string(image.width) + " x " +
                            std::to_string(image.height) + " x " +
                            std::to_string(ImageT::kChannels) + " samples holds " +
                            std::to_string(image.pixels.size()));
  }
  if (options.compression_level < 0 || options.compression_level > 9) {
    throw InvalidInputError("PNG compression level must be in [0, 9], got " +
                            std::to_string(options.compression_level));
  }
  for (const PngText& text : options.text) check_text(text);

  const std::size_t bpp = sizeof(Sample) * ImageT::kChannels;
  const std::size_t row_bytes = bpp * static_cast<std::size_t>(image.width);
  const std::vector<std::uint8_t> raw = raw_bytes(image);
  const std::vector<std::uint8_t> zero_row(row_bytes, 0);
  std::vector<std::uint8_t> filtered((row_bytes + 1) * static_cast<std::size_t>(image.height));
  std::vector<std::uint8_t> candidate(row_bytes + 1);
  constexpr std::array kAllFilters = {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp,
                                      PngFilter::kAverage, PngFilter::kPaeth};
  for (std::size_t y = 0; y < static_cast<std::size_t>(image.height); ++y) {
    const std::span row(raw.data() + y * row_bytes, row_bytes);
    const std::span prior = y == 0 ? std::span(zero_row.data(), row_bytes)
                                   : std::span(raw.data() + (y - 1) * row_bytes, row_bytes);
    std::uint8_t* out = filtered.data() + y * (row_bytes + 1);
    if (!options.adaptive_filter) {
      filter_row(options.filter, row, prior, bpp, out);
      continue;
    }
    std::uint64_t best = UINT64_MAX;
    for (const PngFilter filter : kAllFilters) {
      filter_row(filter, row, prior, bpp, candidate.data());
      const std::uint64_t cost = filter_cost(candidate.data() + 1, row_bytes);
      if (cost < best) {
        best = cost;
        std::copy(candidate.begin(), candidate.end(), out);
      }
    }
  }

  uLongf compressed_size = compressBound(filtered.size());
  std::vector<std::uint8_t> compressed(compressed_size);
  const int status = compress2(compressed.data(), &compressed_size, filtered.data(),
                               filtered.size(), options.compression_level);
  if (status != Z_OK) {
    throw InvalidInputError("zlib could not compress the image (error " + std::to_string(status) +
                            "; out of memory?)");
  }
  compressed.resize(compressed_size);

  std::string out(reinterpret_cast<const char*>(kSignature.data()), kSignature.size());
  std::string header;
  append_u32(header, static_cast<std::uint32_t>(image.width));
  append_u32(header, static_cast<std::uint32_t>(image.height));
  header.push_back(static_cast<char>(8 * sizeof(Sample)));  // bit depth
  header.push_back(static_cast<char>(colour_type));
  header.append(3, '\0');  // compression 0 (deflate), filter method 0, no interlace
  append_chunk(out, "IHDR", header);
  for (const PngText& text : options.text) {
    append_chunk(out, "tEXt", text.key + '\0' + text.value);
  }
  for (std::size_t start = 0; start < compressed.size(); start += kMaxIdatBytes) {
    const std::size_t size = std::min(kMaxIdatBytes, compressed.size() - start);
    append_chunk(out, "IDAT", std::span(compressed.data() + start, size));
  }
  append_chunk(out, "IEND", std::string_view());
  return out;
}

std::string describe_format(int colour_type, int bit_depth) {
  std::string kind;
  switch (colour_type) {
    case kGray:
      kind = "grayscale";
      break;
    case kRgb:
      kind = "RGB";
      break;
    case kPalette:
      kind = "palette (indexed colour)";
      break;
    case kGrayAlpha:
      kind = "grayscale + alpha";
      break;
    case kRgba:
      kind = "RGBA";
      break;
    default:
      kind = "colour type " + std::to_string(colour_type);
  }
  return std::to_string(bit_depth) + "-bit " + kind;
}

struct Header {
  int width = 0;
  int height = 0;
  int bit_depth = 0;
  int colour_type = 0;
};

Header parse_header(const fs::path& path, const std::uint8_t* data, std::uint32_t length) {
  if (length != 13) {
    throw IoError(path, "IHDR chunk has " + std::to_string(length) +
                            " data bytes, expected 13 (corrupt file)");
  }
  const std::uint32_t width = load_u32(data);
  const std::uint32_t height = load_u32(data + 4);
  if (width == 0 || height == 0 || width > kPngMaxValue || height > kPngMaxValue) {
    throw IoError(path, "IHDR gives an invalid image size " + std::to_string(width) + " x " +
                            std::to_string(height) + " (each must be in [1, 2^31 - 1])");
  }
  Header header{static_cast<int>(width), static_cast<int>(height), data[8], data[9]};
  if (data[10] != 0 || data[11] != 0) {
    throw IoError(path, "IHDR names compression method " + std::to_string(data[10]) +
                            " and filter method " + std::to_string(data[11]) +
                            "; PNG defines only method 0 for both (corrupt file)");
  }
  if (data[12] == 1) {
    throw IoError(path,
                  "Adam7-interlaced PNGs are not supported; re-save the image without "
                  "interlacing (e.g. `convert in.png -interlace none out.png`)");
  }
  if (data[12] != 0) {
    throw IoError(path, "IHDR names interlace method " + std::to_string(data[12]) +
                            "; PNG defines only 0 and 1 (corrupt file)");
  }
  const int depth = header.bit_depth;
  const int type = header.colour_type;
  const bool supported = (type == kGray && (depth == 8 || depth == 16)) ||
                         ((type == kRgb || type == kRgba) && depth == 8);
  if (!supported) {
    throw IoError(path, "holds " + describe_format(type, depth) +
                            " samples; supported are 8- or 16-bit grayscale, 8-bit RGB and "
                            "8-bit RGBA (convert it, e.g. `convert in.png -depth 8 "
                            "-type TrueColor out.png`)");
  }
  return header;
}

// Inflates the concatenated IDAT data into exactly `expected` bytes (at most
// kMaxImageBytes, so zlib's 32-bit counters hold it) in one Z_FINISH call.
std::vector<std::uint8_t> inflate_exactly(const fs::path& path, const std::string& zdata,
                                          std::size_t expected) {
  if (zdata.size() > UINT_MAX) {
    throw IoError(path, "the IDAT chunks hold more than 4 GiB of compressed data (corrupt file)");
  }
  std::vector<std::uint8_t> out(expected);
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) throw IoError(path, "zlib could not start (out of memory?)");
  // zlib's next_in is not const-qualified but inflate never writes through it.
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(zdata.data()));
  stream.avail_in = static_cast<uInt>(zdata.size());
  stream.next_out = out.data();
  stream.avail_out = static_cast<uInt>(expected);
  const int status = inflate(&stream, Z_FINISH);
  const std::string message = stream.msg != nullptr ? stream.msg : "no message";
  const std::size_t produced = expected - stream.avail_out;
  const bool output_full = stream.avail_out == 0;
  inflateEnd(&stream);
  if (status == Z_STREAM_END && output_full) return out;
  const std::string progress =
      std::to_string(produced) + " of the " + std::to_string(expected) + " bytes";
  switch (status) {
    case Z_STREAM_END:
      throw IoError(path, "image data too short: the zlib stream ends after " + progress +
                              " the IHDR size needs (rows are missing)");
    case Z_MEM_ERROR:
      throw IoError(path, "out of memory while inflating the image data");
    case Z_OK:
    case Z_BUF_ERROR:
      if (output_full) {
        throw IoError(path, "image data is longer than the IHDR size allows (" +
                                std::to_string(expected) + " bytes); the file is corrupt");
      }
      throw IoError(path, "truncated image data: the zlib stream stops after " + progress +
                              " (was the file cut short?)");
    default:
      throw IoError(path,
                    "image data is corrupt: zlib reports '" + message + "' after " + progress);
  }
}

// Undoes the row filters: `data` holds height rows of 1 + row_bytes
// bytes; returns the unfiltered rows without their filter bytes.
std::vector<std::uint8_t> unfilter(const fs::path& path, const std::vector<std::uint8_t>& data,
                                   std::size_t height, std::size_t row_bytes, std::size_t bpp) {
  std::vector<std::uint8_t> rows(height * row_bytes);
  const std::vector<std::uint8_t> zero_row(row_bytes, 0);
  for (std::size_t y = 0; y < height; ++y) {
    const std::uint8_t* in = data.data() + y * (row_bytes + 1);
    const std::uint8_t type = in[0];
    ++in;
    std::uint8_t* row = rows.data() + y * row_bytes;
    const std::uint8_t* prior = y == 0 ? zero_row.data() : row - row_bytes;
    if (type > 4) {
      throw IoError(path, "row " + std::to_string(y) + " has filter type " + std::to_string(type) +
                              "; PNG defines 0 to 4 (corrupt file)");
    }
    const auto filter = static_cast<PngFilter>(type);
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int a = i >= bpp ? row[i - bpp] : 0;
      const int c = i >= bpp ? prior[i - bpp] : 0;
      row[i] = static_cast<std::uint8_t>(in[i] + predict(filter, a, prior[i], c));
    }
  }
  return rows;
}

template <typename ImageT>
ImageT to_image(const Header& header, const std::vector<std::uint8_t>& rows) {
  ImageT image(header.width, header.height);
  if constexpr (sizeof(typename ImageT::Sample) == 1) {
    std::copy(rows.begin(), rows.end(), image.pixels.begin());
  } else {
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
      image.pixels[i] = static_cast<std::uint16_t>((rows[2 * i] << 8U) | rows[2 * i + 1]);
    }
  }
  return image;
}

}  // namespace

void write_png(const GrayImage8& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png(image, kGray, options));
}

void write_png(const GrayImage16& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png(image, kGray, options));
}

void write_png(const RgbImage8& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png(image, kRgb, options));
}

PngContent decode_png(const fs::path& path, const std::string& file) {
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(file.data());
  const std::size_t size = file.size();
  if (size < kSignature.size() || !std::equal(kSignature.begin(), kSignature.end(), bytes)) {
    if (size >= 4 && std::memcmp(file.data() + 1, "PNG", 3) == 0) {
      throw IoError(path,
                    "PNG signature damaged (line endings converted? the file was probably "
                    "transferred in text mode)");
    }
    throw IoError(path, "not a PNG file (the 8-byte PNG signature is missing)");
  }
  PngContent content;
  Header header;
  bool have_header = false;
  bool have_end = false;
  std::string zdata;
  std::size_t pos = kSignature.size();
  while (!have_end) {
    if (pos == size) {
      throw IoError(path, "truncated: the file ends after " + std::to_string(size) +
                              " bytes without an IEND chunk");
    }
    if (size - pos < 8) {
      throw IoError(
          path, "truncated: the file ends inside a chunk header at byte " + std::to_string(pos));
    }
    const std::uint32_t length = load_u32(bytes + pos);
    const std::string type(file.data() + pos + 4, 4);
    const std::string where = "chunk '" + type + "' at byte " + std::to_string(pos);
    for (const char c : type) {
      if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'))) {
        throw IoError(path, "chunk at byte " + std::to_string(pos) +
                                " has an invalid type (not 4 letters): the file is corrupt");
      }
    }
    if (length > kPngMaxValue) {
      throw IoError(path, where + " declares " + std::to_string(length) +
                              " data bytes, above the PNG limit 2^31 - 1 (corrupt file)");
    }
    if (size - pos - 8 < std::size_t{length} + 4) {
      throw IoError(path, "truncated: " + where + " declares " + std::to_string(length) +
                              " data bytes + 4 CRC bytes, but only " +
                              std::to_string(size - pos - 8) + " bytes remain");
    }
    const std::uint8_t* data = bytes + pos + 8;
    const std::uint32_t stored_crc = load_u32(data + length);
    const std::uint32_t computed_crc = crc_of(bytes + pos + 4, std::size_t{length} + 4);
    if (stored_crc != computed_crc) {
      throw IoError(path, where + ": CRC mismatch (stored " + hex32(stored_crc) + ", computed " +
                              hex32(computed_crc) + "): the file is corrupt");
    }
    if (!have_header && type != "IHDR") {
      throw IoError(path, "the first chunk is '" + type + "', expected IHDR (corrupt file)");
    }
    if (type == "IHDR") {
      if (have_header) throw IoError(path, where + ": a second IHDR (corrupt file)");
      header = parse_header(path, data, length);
      have_header = true;
    } else if (type == "IDAT") {
      zdata.append(reinterpret_cast<const char*>(data), length);
    } else if (type == "IEND") {
      have_end = true;
    } else if (type == "tEXt") {
      const std::string_view chunk(reinterpret_cast<const char*>(data), length);
      const std::size_t nul = chunk.find('\0');
      if (nul == std::string_view::npos) {
        throw IoError(path, where + ": tEXt without the NUL byte ending its keyword");
      }
      content.text.push_back(
          {std::string(chunk.substr(0, nul)), std::string(chunk.substr(nul + 1))});
    } else if (type == "PLTE") {
      // A suggested palette for truecolour images: nothing to apply.
    } else if ((static_cast<unsigned char>(type[0]) & 0x20U) == 0) {
      throw IoError(path, where + ": unknown critical chunk; this reader cannot decode the image");
    }
    pos += std::size_t{length} + 12;
  }
  if (zdata.empty()) throw IoError(path, "no IDAT chunk: the file holds no image data");

  const std::size_t channels = header.colour_type == kGray ? 1 : header.colour_type == kRgb ? 3 : 4;
  const std::size_t bpp = channels * static_cast<std::size_t>(header.bit_depth / 8);
  const std::uint64_t row_bytes = std::uint64_t{bpp} * static_cast<std::uint64_t>(header.width);
  const std::uint64_t total = (row_bytes + 1) * static_cast<std::uint64_t>(header.height);
  if (total > kMaxImageBytes) {
    throw IoError(path, "image of " + std::to_string(header.width) + " x " +
                            std::to_string(header.height) + " " +
                            describe_format(header.colour_type, header.bit_depth) +
                            " pixels is too large for this reader (limit 2 GiB of row data)");
  }
  const std::vector<std::uint8_t> filtered =
      inflate_exactly(path, zdata, static_cast<std::size_t>(total));
  const std::vector<std::uint8_t> rows =
      unfilter(path, filtered, static_cast<std::size_t>(header.height),
               static_cast<std::size_t>(row_bytes), bpp);
  if (header.colour_type == kGray && header.bit_depth == 8) {
    content.image = to_image<GrayImage8>(header, rows);
  } else if (header.colour_type == kGray) {
    content.image = to_image<GrayImage16>(header, rows);
  } else if (header.colour_type == kRgb) {
    content.image = to_image<RgbImage8>(header, rows);
  } else {
    content.image = to_image<RgbaImage8>(header, rows);
  }
  return content;
}

PngContent read_png(const fs::path& path) {
  return decode_png(path, detail::read_file_bytes(path, "a PNG file"));
}

GrayImage16 read_png_gray16(const fs::path& path) {
  PngContent content = read_png(path);
  if (auto* gray16 = std::get_if<GrayImage16>(&content.image)) return std::move(*gray16);
  if (const auto* gray8 = std::get_if<GrayImage8>(&content.image)) {
    GrayImage16 wide(gray8->width, gray8->height);
    for (std::size_t i = 0; i < wide.pixels.size(); ++i) {
      wide.pixels[i] = static_cast<std::uint16_t>(gray8->pixels[i] * 257U);
    }
    return wide;
  }
  const bool rgb = std::holds_alternative<RgbImage8>(content.image);
  throw IoError(path, std::string("holds 8-bit ") + (rgb ? "RGB" : "RGBA") +
                          ", expected a grayscale radiograph (convert it to grayscale first)");
}

}  // namespace mmm::image
