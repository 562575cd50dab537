// Reading PNG files through libspng (Debian's libspng-dev), which parses,
// inflates and unfilters them; this file sets its limits, picks the sample
// format and turns its error codes into messages that name the file.

#include <spng.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string_view>

#include "core/errors.h"
#include "core/image/file_bytes.h"
#include "core/image/png.h"

namespace mmm::image {

namespace fs = std::filesystem;

namespace {

constexpr std::array<std::uint8_t, 8> kPngSignature = {137, 80, 78, 71, 13, 10, 26, 10};
// Ancillary chunks (text, profiles) above this size, or more of them in
// total than kMaxAncillaryBytes, are refused instead of being held in memory.
constexpr std::size_t kMaxChunkBytes = std::size_t{16} << 20U;
constexpr std::size_t kMaxAncillaryBytes = std::size_t{64} << 20U;

struct SpngContextDeleter {
  void operator()(spng_ctx* context) const { spng_ctx_free(context); }
};
using SpngContext = std::unique_ptr<spng_ctx, SpngContextDeleter>;

std::string describe_png_format(int colour_type, int bit_depth) {
  std::string kind;
  switch (colour_type) {
    case SPNG_COLOR_TYPE_GRAYSCALE:
      kind = "grayscale";
      break;
    case SPNG_COLOR_TYPE_TRUECOLOR:
      kind = "RGB";
      break;
    case SPNG_COLOR_TYPE_INDEXED:
      kind = "palette (indexed colour)";
      break;
    case SPNG_COLOR_TYPE_GRAYSCALE_ALPHA:
      kind = "grayscale + alpha";
      break;
    case SPNG_COLOR_TYPE_TRUECOLOR_ALPHA:
      kind = "RGBA";
      break;
    default:
      kind = "colour type " + std::to_string(colour_type);
  }
  return std::to_string(bit_depth) + "-bit " + kind;
}

// What an spng error code means for the person holding the file.
std::string explain_spng_error(int code) {
  switch (code) {
    case SPNG_IO_EOF:
    case SPNG_IO_ERROR:
    case SPNG_EOF:
      return "truncated: the file ends before its IEND chunk (was it cut short?)";
    case SPNG_ECHUNK_CRC:
      return "a chunk's CRC mismatch: the file is corrupt";
    case SPNG_EIDAT_TOO_SHORT:
      return "truncated image data: the zlib stream stops before all the rows the IHDR size "
             "needs (rows are missing)";
    case SPNG_EIDAT_STREAM:
      return "image data is corrupt: the zlib stream does not match the IHDR size";
    case SPNG_EZLIB:
      return "image data is corrupt: not a valid zlib stream";
    case SPNG_EFILTER:
      return "a row has an invalid filter type (PNG defines 0 to 4): the file is corrupt";
    case SPNG_ECHUNK_UNKNOWN_CRITICAL:
      return "an unknown critical chunk; this reader cannot decode the image";
    case SPNG_ECHUNK_LIMITS:
      return "an ancillary chunk larger than " + std::to_string(kMaxChunkBytes >> 20U) +
             " MiB (or more than " + std::to_string(kMaxAncillaryBytes >> 20U) +
             " MiB of them): refused";
    case SPNG_ECHUNK_POS:
      return "chunks out of order, or no IDAT before IEND (corrupt file)";
    case SPNG_ENOIHDR:
      return "the first chunk is not IHDR (corrupt file)";
    case SPNG_EMEM:
      return "out of memory while decoding the image";
    default:
      return std::string("corrupt file: ") + spng_strerror(code);
  }
}

[[noreturn]] void fail(const fs::path& path, int code) {
  throw IoError(path, explain_spng_error(code));
}

// Refuses what this reader does not decode, with a hint to convert.
void check_supported(const fs::path& path, const spng_ihdr& header) {
  if (header.interlace_method != SPNG_INTERLACE_NONE) {
    throw IoError(path,
                  "Adam7-interlaced PNGs are not supported; re-save the image without "
                  "interlacing (e.g. `convert in.png -interlace none out.png`)");
  }
  const int type = header.color_type;
  const int depth = header.bit_depth;
  const bool supported =
      (type == SPNG_COLOR_TYPE_GRAYSCALE && (depth == 8 || depth == 16)) ||
      ((type == SPNG_COLOR_TYPE_TRUECOLOR || type == SPNG_COLOR_TYPE_TRUECOLOR_ALPHA) &&
       depth == 8);
  if (!supported) {
    throw IoError(path, "holds " + describe_png_format(type, depth) +
                            " samples; supported are 8- or 16-bit grayscale, 8-bit RGB and "
                            "8-bit RGBA (convert it, e.g. `convert in.png -depth 8 "
                            "-type TrueColor out.png`)");
  }
}

// Decodes into ImageT after the size was checked against kPngMaxDecodedBytes.
template <typename ImageT>
ImageT decode_samples(const fs::path& path, spng_ctx* context, const spng_ihdr& header,
                      int format) {
  ImageT image(static_cast<int>(header.width), static_cast<int>(header.height));
  std::size_t expected = 0;
  if (const int status = spng_decoded_image_size(context, format, &expected); status != 0) {
    fail(path, status);
  }
  const std::size_t bytes = image.pixels.size() * sizeof(typename ImageT::Sample);
  if (expected != bytes) {
    throw IoError(path, "decoder and header disagree on the image size (" +
                            std::to_string(expected) + " vs " + std::to_string(bytes) +
                            " bytes): the file is corrupt");
  }
  if (const int status = spng_decode_image(context, image.pixels.data(), bytes, format, 0);
      status != 0) {
    fail(path, status);
  }
  return image;
}

}  // namespace

PngContent decode_png(const fs::path& path, const std::string& file) {
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(file.data());
  if (file.size() < kPngSignature.size() ||
      !std::equal(kPngSignature.begin(), kPngSignature.end(), bytes)) {
    if (file.size() >= 4 && std::memcmp(file.data() + 1, "PNG", 3) == 0) {
      throw IoError(path,
                    "PNG signature damaged (line endings converted? the file was probably "
                    "transferred in text mode)");
    }
    throw IoError(path, "not a PNG file (the 8-byte PNG signature is missing)");
  }
  const SpngContext context(spng_ctx_new(0));
  if (!context) throw IoError(path, "out of memory before decoding");
  spng_ctx* ctx = context.get();
  // Every CRC is checked, ancillary chunks' too.
  spng_set_crc_action(ctx, SPNG_CRC_ERROR, SPNG_CRC_ERROR);
  spng_set_image_limits(ctx, kPngMaxSide, kPngMaxSide);
  spng_set_chunk_limits(ctx, kMaxChunkBytes, kMaxAncillaryBytes);
  if (const int status = spng_set_png_buffer(ctx, file.data(), file.size()); status != 0) {
    fail(path, status);
  }
  spng_ihdr header{};
  if (const int status = spng_get_ihdr(ctx, &header); status != 0) {
    if (status == SPNG_EUSER_WIDTH || status == SPNG_EUSER_HEIGHT) {
      throw IoError(path, "the header gives an image wider or taller than " +
                              std::to_string(kPngMaxSide) +
                              " pixels: refused before decoding (crop or downsample it)");
    }
    fail(path, status);
  }
  check_supported(path, header);
  const std::uint64_t channels = header.color_type == SPNG_COLOR_TYPE_GRAYSCALE   ? 1
                                 : header.color_type == SPNG_COLOR_TYPE_TRUECOLOR ? 3
                                                                                  : 4;
  const std::uint64_t decoded =
      std::uint64_t{header.width} * header.height * channels * (header.bit_depth / 8U);
  if (decoded > kPngMaxDecodedBytes) {
    throw IoError(path, "the header gives a " + std::to_string(header.width) + " x " +
                            std::to_string(header.height) + " " +
                            describe_png_format(header.color_type, header.bit_depth) + " image, " +
                            std::to_string(decoded >> 20U) + " MiB decoded; " + "the limit is " +
                            std::to_string(kPngMaxDecodedBytes >> 20U) +
                            " MiB: refused before decoding (crop or downsample it)");
  }

  PngContent content;
  if (header.color_type == SPNG_COLOR_TYPE_GRAYSCALE && header.bit_depth == 8) {
    content.image = decode_samples<GrayImage8>(path, ctx, header, SPNG_FMT_G8);
  } else if (header.color_type == SPNG_COLOR_TYPE_GRAYSCALE) {
    // SPNG_FMT_PNG: the file's own format, 16-bit samples in host order.
    content.image = decode_samples<GrayImage16>(path, ctx, header, SPNG_FMT_PNG);
  } else if (header.color_type == SPNG_COLOR_TYPE_TRUECOLOR) {
    content.image = decode_samples<RgbImage8>(path, ctx, header, SPNG_FMT_RGB8);
  } else {
    content.image = decode_samples<RgbaImage8>(path, ctx, header, SPNG_FMT_RGBA8);
  }

  // The chunks after the image data, to IEND: a file cut short there, or
  // damaged there, is refused too (libspng stops at IEND's type without
  // reading its CRC: the complete chunk must be there).
  if (const int status = spng_decode_chunks(ctx); status != 0) fail(path, status);
  constexpr std::string_view kIend("\0\0\0\0IEND\xAE\x42\x60\x82", 12);
  if (file.rfind(kIend) == std::string::npos) fail(path, SPNG_EOF);

  std::uint32_t count = 0;
  if (spng_get_text(ctx, nullptr, &count) == 0 && count > 0) {
    std::vector<spng_text> chunks(count);
    if (const int status = spng_get_text(ctx, chunks.data(), &count); status != 0) {
      fail(path, status);
    }
    for (const spng_text& chunk : chunks) {
      if (chunk.type != SPNG_TEXT) continue;
      content.text.push_back({std::string(chunk.keyword), std::string(chunk.text, chunk.length)});
    }
  }
  return content;
}

PngContent read_png(const fs::path& path) {
  return decode_png(path, detail::read_file_bytes(path, "a PNG file", kPngMaxFileBytes));
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
