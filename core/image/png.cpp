#include "core/image/png.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <span>
#include <string_view>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace mmm::image {

namespace fs = std::filesystem;

namespace {

constexpr std::array<std::uint8_t, 8> kSignature = {137, 80, 78, 71, 13, 10, 26, 10};
// Largest IDAT written: libpng's default is 8 KiB; larger chunks cost nothing
// and keep a radiograph's chunk list short.
constexpr std::size_t kMaxIdatBytes = std::size_t{256} * 1024;

// PNG colour types.
constexpr int kGray = 0;
constexpr int kRgb = 2;

void append_u32(std::string& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out.push_back(static_cast<char>((value >> static_cast<unsigned>(shift)) & 0xFFU));
  }
}

std::uint32_t crc_of(const std::uint8_t* bytes, std::size_t size) {
  return static_cast<std::uint32_t>(crc32_z(crc32_z(0, nullptr, 0), bytes, size));
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
std::string encode_png_bytes(const ImageT& image, int colour_type, const PngWriteOptions& options) {
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

}  // namespace

void write_png(const GrayImage8& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png_bytes(image, kGray, options));
}

void write_png(const GrayImage16& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png_bytes(image, kGray, options));
}

void write_png(const RgbImage8& image, const fs::path& path, const PngWriteOptions& options) {
  write_file_atomically(path, encode_png_bytes(image, kRgb, options));
}

std::string encode_png(const GrayImage8& image, const PngWriteOptions& options) {
  return encode_png_bytes(image, kGray, options);
}

std::string encode_png(const GrayImage16& image, const PngWriteOptions& options) {
  return encode_png_bytes(image, kGray, options);
}

std::string encode_png(const RgbImage8& image, const PngWriteOptions& options) {
  return encode_png_bytes(image, kRgb, options);
}

}  // namespace mmm::image
