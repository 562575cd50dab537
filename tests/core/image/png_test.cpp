#include "core/image/png.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

template <typename ImageT>
ImageT random_image(int width, int height, std::uint32_t seed) {
  std::mt19937 rng(seed);
  ImageT image(width, height);
  for (auto& sample : image.pixels) {
    sample = static_cast<typename ImageT::Sample>(rng());
  }
  return image;
}

// A smooth ramp plus a little noise: what the filters are designed for.
GrayImage16 ramp16(int width, int height) {
  std::mt19937 rng(7);
  GrayImage16 image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.at(x, y) = static_cast<std::uint16_t>(100 * x + 37 * y + (rng() % 16));
    }
  }
  return image;
}

// --- hand-made PNG files, written independently of the writer under test ---

void put_u32(std::string& out, std::uint32_t value) {
  out.push_back(static_cast<char>(value >> 24U));
  out.push_back(static_cast<char>((value >> 16U) & 0xFFU));
  out.push_back(static_cast<char>((value >> 8U) & 0xFFU));
  out.push_back(static_cast<char>(value & 0xFFU));
}

std::string chunk(const std::string& type, const std::string& data) {
  std::string out;
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::string body = type + data;
  out += body;
  put_u32(out, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()),
                                                static_cast<uInt>(body.size()))));
  return out;
}

std::string ihdr(std::uint32_t width, std::uint32_t height, int depth, int colour, int interlace) {
  std::string data;
  put_u32(data, width);
  put_u32(data, height);
  data.push_back(static_cast<char>(depth));
  data.push_back(static_cast<char>(colour));
  data.push_back('\0');
  data.push_back('\0');
  data.push_back(static_cast<char>(interlace));
  return chunk("IHDR", data);
}

std::string zlib_compress(const std::string& raw) {
  uLongf size = compressBound(raw.size());
  std::string out(size, '\0');
  EXPECT_EQ(compress(reinterpret_cast<Bytef*>(out.data()), &size,
                     reinterpret_cast<const Bytef*>(raw.data()), raw.size()),
            Z_OK);
  out.resize(size);
  return out;
}

const std::string kSignature("\x89PNG\r\n\x1a\n", 8);

std::string read_bytes(const std::filesystem::path& path) { return test::read_text(path); }

// --- round trips ---

TEST(PngTest, Gray8RoundTrip) {
  const test::ScratchDir dir("png");
  const auto image = random_image<GrayImage8>(37, 23, 1);  // odd sizes: no alignment luck
  write_png(image, dir / "gray8.png");
  const PngContent read = read_png(dir / "gray8.png");
  ASSERT_TRUE(std::holds_alternative<GrayImage8>(read.image));
  const auto& back = std::get<GrayImage8>(read.image);
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.pixels, image.pixels);
}

TEST(PngTest, Gray16RoundTripKeepsFullRange) {
  const test::ScratchDir dir("png");
  GrayImage16 image = ramp16(41, 19);
  image.at(0, 0) = 0;
  image.at(1, 0) = 65535;
  image.at(2, 0) = 255;
  image.at(3, 0) = 256;
  write_png(image, dir / "gray16.png");
  const PngContent read = read_png(dir / "gray16.png");
  ASSERT_TRUE(std::holds_alternative<GrayImage16>(read.image));
  EXPECT_EQ(std::get<GrayImage16>(read.image).pixels, image.pixels);
}

TEST(PngTest, RgbRoundTrip) {
  const test::ScratchDir dir("png");
  const auto image = random_image<RgbImage8>(17, 29, 2);
  write_png(image, dir / "rgb.png");
  const PngContent read = read_png(dir / "rgb.png");
  ASSERT_TRUE(std::holds_alternative<RgbImage8>(read.image));
  const auto& back = std::get<RgbImage8>(read.image);
  EXPECT_EQ(back.width, 17);
  EXPECT_EQ(back.height, 29);
  EXPECT_EQ(back.pixels, image.pixels);
}

// Writing with each filter forced exercises the reader's five unfilter paths
// on 1-, 2- and 3-byte pixels (the left neighbour is bpp bytes back).
TEST(PngTest, EveryFilterTypeRoundTrips) {
  const test::ScratchDir dir("png");
  const auto gray8 = random_image<GrayImage8>(13, 11, 3);
  const GrayImage16 gray16 = ramp16(13, 11);
  const auto rgb = random_image<RgbImage8>(13, 11, 4);
  for (const PngFilter filter : {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp,
                                 PngFilter::kAverage, PngFilter::kPaeth}) {
    PngWriteOptions options;
    options.adaptive_filter = false;
    options.filter = filter;
    const int index = static_cast<int>(filter);
    write_png(gray8, dir / "g8.png", options);
    write_png(gray16, dir / "g16.png", options);
    write_png(rgb, dir / "rgb.png", options);
    EXPECT_EQ(std::get<GrayImage8>(read_png(dir / "g8.png").image).pixels, gray8.pixels)
        << "filter " << index;
    EXPECT_EQ(std::get<GrayImage16>(read_png(dir / "g16.png").image).pixels, gray16.pixels)
        << "filter " << index;
    EXPECT_EQ(std::get<RgbImage8>(read_png(dir / "rgb.png").image).pixels, rgb.pixels)
        << "filter " << index;
  }
}

TEST(PngTest, TextChunksRoundTripInOrder) {
  const test::ScratchDir dir("png");
  PngWriteOptions options;
  options.text = {{"Software", "mmm"}, {"mmm:view", "frontal"}, {"Comment", "multi\nline, ok"}};
  write_png(GrayImage8(3, 2, 9), dir / "text.png", options);
  EXPECT_EQ(read_png(dir / "text.png").text, options.text);
}

// With compression level 0 zlib stores the filtered rows verbatim, so the
// file itself shows the byte order: 0x1234 must appear as 0x12 0x34.
TEST(PngTest, Gray16SamplesAreBigEndianInTheFile) {
  const test::ScratchDir dir("png");
  PngWriteOptions options;
  options.compression_level = 0;
  options.adaptive_filter = false;
  GrayImage16 image(2, 1);
  image.pixels = {0x1234, 0xABCD};
  write_png(image, dir / "order.png", options);
  const std::string bytes = read_bytes(dir / "order.png");
  EXPECT_NE(bytes.find(std::string("\x00\x12\x34\xAB\xCD", 5)), std::string::npos);
}

TEST(PngTest, LargeImageIsSplitOverSeveralIdatChunks) {
  const test::ScratchDir dir("png");
  // 600 x 600 random 16-bit samples do not compress: 720 KB of data must be
  // spread over at least three IDAT chunks of at most 256 KiB.
  const auto image = random_image<GrayImage16>(600, 600, 5);
  write_png(image, dir / "big.png");
  const std::string bytes = read_bytes(dir / "big.png");
  int idat_chunks = 0;
  for (std::size_t at = bytes.find("IDAT"); at != std::string::npos;
       at = bytes.find("IDAT", at + 4)) {
    ++idat_chunks;
  }
  EXPECT_GE(idat_chunks, 3);
  EXPECT_EQ(std::get<GrayImage16>(read_png(dir / "big.png").image).pixels, image.pixels);
}

// An RGBA file (the writer makes none) split into one-byte IDAT chunks, with an
// ancillary chunk the reader must skip.
TEST(PngTest, ReadsHandMadeRgbaSplitIntoTinyIdatChunks) {
  const test::ScratchDir dir("png");
  std::string raw;
  const std::vector<std::uint8_t> pixels = {1, 2, 3, 4, 250, 251, 252, 253,
                                            9, 8, 7, 6, 0,   0,   0,   255};
  for (std::size_t y = 0; y < 2; ++y) {
    raw.push_back('\0');  // filter None
    raw.append(reinterpret_cast<const char*>(pixels.data()) + 8 * y, 8);
  }
  const std::string z = zlib_compress(raw);
  std::string file = kSignature + ihdr(2, 2, 8, 6, 0) + chunk("gAMA", std::string(4, '\x01'));
  for (const char byte : z) file += chunk("IDAT", std::string(1, byte));
  file += chunk("IEND", "");
  test::write_file(dir / "rgba.png", file);
  const PngContent read = read_png(dir / "rgba.png");
  ASSERT_TRUE(std::holds_alternative<RgbaImage8>(read.image));
  const auto& rgba = std::get<RgbaImage8>(read.image);
  EXPECT_EQ(rgba.width, 2);
  EXPECT_EQ(rgba.height, 2);
  EXPECT_EQ(rgba.pixels, pixels);
}

TEST(PngTest, ReadGray16WidensGray8AndRejectsColour) {
  const test::ScratchDir dir("png");
  GrayImage8 gray(3, 1);
  gray.pixels = {0, 1, 255};
  write_png(gray, dir / "g8.png");
  EXPECT_EQ(read_png_gray16(dir / "g8.png").pixels, (std::vector<std::uint16_t>{0, 257, 65535}));
  const GrayImage16 gray16 = ramp16(4, 4);
  write_png(gray16, dir / "g16.png");
  EXPECT_EQ(read_png_gray16(dir / "g16.png").pixels, gray16.pixels);
  write_png(RgbImage8(2, 2), dir / "rgb.png");
  EXPECT_THAT([&] { (void)read_png_gray16(dir / "rgb.png"); },
              ::testing::ThrowsMessage<IoError>(
                  AllOf(HasSubstr("rgb.png"), HasSubstr("RGB"), HasSubstr("grayscale"))));
}

// --- damaged and unsupported files ---

TEST(PngTest, CorruptedCrcOrDataIsRejected) {
  const test::ScratchDir dir("png");
  write_png(ramp16(20, 20), dir / "ok.png");
  const std::string good = read_bytes(dir / "ok.png");
  const std::size_t idat = good.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  const std::size_t length =
      (static_cast<std::size_t>(static_cast<unsigned char>(good[idat - 4])) << 24U) |
      (static_cast<std::size_t>(static_cast<unsigned char>(good[idat - 3])) << 16U) |
      (static_cast<std::size_t>(static_cast<unsigned char>(good[idat - 2])) << 8U) |
      static_cast<unsigned char>(good[idat - 1]);
  std::string bad_crc = good;
  bad_crc[idat + 4 + length] = static_cast<char>(bad_crc[idat + 4 + length] ^ 0x01);  // the CRC
  test::write_file(dir / "bad.png", bad_crc);
  EXPECT_THAT(
      [&] { (void)read_png(dir / "bad.png"); },
      ::testing::ThrowsMessage<IoError>(AllOf(HasSubstr("bad.png"), HasSubstr("CRC mismatch"))));
  std::string bad_data = good;
  bad_data[idat + 10] = static_cast<char>(bad_data[idat + 10] ^ 0x40);  // one bit of the data
  test::write_file(dir / "data.png", bad_data);
  EXPECT_THAT(
      [&] { (void)read_png(dir / "data.png"); },
      ::testing::ThrowsMessage<IoError>(AllOf(HasSubstr("data.png"), HasSubstr("corrupt"))));
}

// Every proper prefix of a valid file is rejected with an IoError naming the
// file (never a crash, never a silently smaller image).
TEST(PngTest, EveryTruncationIsRejected) {
  const test::ScratchDir dir("png");
  PngWriteOptions options;
  options.text = {{"k", "v"}};
  write_png(random_image<RgbImage8>(5, 4, 6), dir / "ok.png", options);
  const std::string bytes = read_bytes(dir / "ok.png");
  for (std::size_t size = 1; size < bytes.size(); ++size) {
    test::write_file(dir / "cut.png", bytes.substr(0, size));
    EXPECT_THROW((void)read_png(dir / "cut.png"), IoError) << "cut at " << size;
  }
  test::write_file(dir / "cut.png", bytes.substr(0, bytes.size() - 30));
  EXPECT_THAT(
      [&] { (void)read_png(dir / "cut.png"); },
      ::testing::ThrowsMessage<IoError>(AllOf(HasSubstr("cut.png"), HasSubstr("truncated"))));
}

TEST(PngTest, DamagedImageDataIsRejected) {
  const test::ScratchDir dir("png");
  std::string raw;
  for (int y = 0; y < 4; ++y) raw += std::string(1, '\0') + std::string(4, static_cast<char>(y));
  const std::string z = zlib_compress(raw);
  const std::string head = kSignature + ihdr(4, 4, 8, 0, 0);
  const std::string end = chunk("IEND", "");

  // The zlib stream cut short (chunk CRCs still valid).
  test::write_file(dir / "short.png", head + chunk("IDAT", z.substr(0, z.size() / 2)) + end);
  EXPECT_THAT([&] { (void)read_png(dir / "short.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("truncated image data")));
  // A complete stream with one row too few.
  test::write_file(dir / "rows.png", head + chunk("IDAT", zlib_compress(raw.substr(0, 15))) + end);
  EXPECT_THAT([&] { (void)read_png(dir / "rows.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("rows are missing")));
  // One row too many: the rows the header declares are read, the rest is
  // ignored (as libpng does, with a warning).
  test::write_file(dir / "long.png",
                   head + chunk("IDAT", zlib_compress(raw + raw.substr(0, 5))) + end);
  const PngContent extra = read_png(dir / "long.png");
  ASSERT_TRUE(std::holds_alternative<GrayImage8>(extra.image));
  EXPECT_EQ(std::get<GrayImage8>(extra.image).pixels.size(), 16U);
  // Garbage instead of a zlib stream.
  test::write_file(dir / "garbage.png", head + chunk("IDAT", "this is not zlib") + end);
  EXPECT_THAT([&] { (void)read_png(dir / "garbage.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("corrupt")));
  // A filter byte outside 0..4.
  std::string bad_filter = raw;
  bad_filter[10] = '\x07';
  test::write_file(dir / "filter.png", head + chunk("IDAT", zlib_compress(bad_filter)) + end);
  EXPECT_THAT([&] { (void)read_png(dir / "filter.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("invalid filter type")));
  // No IDAT at all.
  test::write_file(dir / "empty.png", head + end);
  EXPECT_THAT([&] { (void)read_png(dir / "empty.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("no IDAT")));
}

TEST(PngTest, UnsupportedFormatsAreNamed) {
  const test::ScratchDir dir("png");
  const std::string idat = chunk("IDAT", zlib_compress(std::string(2, '\0'))) + chunk("IEND", "");
  test::write_file(dir / "palette.png", kSignature + ihdr(1, 1, 8, 3, 0) + idat);
  EXPECT_THAT([&] { (void)read_png(dir / "palette.png"); },
              ::testing::ThrowsMessage<IoError>(
                  AllOf(HasSubstr("palette.png"), HasSubstr("8-bit palette"))));
  test::write_file(dir / "rgb16.png", kSignature + ihdr(1, 1, 16, 2, 0) + idat);
  EXPECT_THAT([&] { (void)read_png(dir / "rgb16.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("16-bit RGB")));
  test::write_file(dir / "adam7.png", kSignature + ihdr(1, 1, 8, 0, 1) + idat);
  EXPECT_THAT([&] { (void)read_png(dir / "adam7.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("interlac")));
  test::write_file(dir / "critical.png",
                   kSignature + ihdr(1, 1, 8, 0, 0) + chunk("ABCD", "x") + idat);
  EXPECT_THAT([&] { (void)read_png(dir / "critical.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("unknown critical chunk")));
}

// A decompression bomb: a few hundred bytes whose header claims a
// 50,000 x 50,000 image (2.3 GiB of samples). Refused from the header, before
// any image memory is allocated; so is a side above the per-side limit.
TEST(PngTest, HeadersAskingForTooLargeAnImageAreRefusedBeforeDecoding) {
  const test::ScratchDir dir("png");
  const std::string zeros = zlib_compress(std::string(std::size_t{1} << 20U, '\0'));
  const std::string tail = chunk("IDAT", zeros) + chunk("IEND", "");
  test::write_file(dir / "bomb.png", kSignature + ihdr(50'000, 50'000, 8, 0, 0) + tail);
  EXPECT_LT(std::filesystem::file_size(dir / "bomb.png"), 4096U);
  EXPECT_THAT([&] { (void)read_png(dir / "bomb.png"); },
              ::testing::ThrowsMessage<IoError>(
                  AllOf(HasSubstr("bomb.png"), HasSubstr("50000 x 50000"), HasSubstr("512 MiB"),
                        HasSubstr("refused before decoding"))));
  test::write_file(dir / "wide.png", kSignature + ihdr(kPngMaxSide + 1, 1, 8, 0, 0) + tail);
  EXPECT_THAT(
      [&] { (void)read_png(dir / "wide.png"); },
      ::testing::ThrowsMessage<IoError>(AllOf(HasSubstr("wide.png"), HasSubstr("65535 pixels"))));
}

// A file above the size limit is refused from its size, before it is read
// (the test file is sparse: it takes no disk space).
TEST(PngTest, FilesAboveTheSizeLimitAreRefusedBeforeReading) {
  const test::ScratchDir dir("png");
  test::write_file(dir / "huge.png", kSignature);
  std::filesystem::resize_file(dir / "huge.png", kPngMaxFileBytes + 1);
  EXPECT_THAT([&] { (void)read_png(dir / "huge.png"); },
              ::testing::ThrowsMessage<IoError>(
                  AllOf(HasSubstr("huge.png"), HasSubstr("limit of 256 MiB"))));
}

TEST(PngTest, NonPngFilesAreRejected) {
  const test::ScratchDir dir("png");
  EXPECT_THAT([&] { (void)read_png(dir / "missing.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("no such file")));
  test::write_file(dir / "text.png", "hello, I am not an image");
  EXPECT_THAT([&] { (void)read_png(dir / "text.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("not a PNG file")));
  // A PNG signature with its CR LF turned into LF by a text-mode transfer.
  test::write_file(dir / "crlf.png", std::string("\x89PNG\n\x1a\n", 7) + std::string(20, 'x'));
  EXPECT_THAT([&] { (void)read_png(dir / "crlf.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("text mode")));
}

TEST(PngTest, InvalidImagesAndOptionsAreRejectedBeforeWriting) {
  const test::ScratchDir dir("png");
  EXPECT_THROW(write_png(GrayImage8(), dir / "empty.png"), InvalidInputError);
  GrayImage8 short_pixels(4, 4);
  short_pixels.pixels.pop_back();
  EXPECT_THROW(write_png(short_pixels, dir / "short.png"), InvalidInputError);
  PngWriteOptions level;
  level.compression_level = 10;
  EXPECT_THROW(write_png(GrayImage8(1, 1), dir / "level.png", level), InvalidInputError);
  for (const std::string& key : {std::string(), std::string(80, 'k'), std::string(" lead"),
                                 std::string("two  spaces"), std::string("tab\tkey")}) {
    PngWriteOptions text;
    text.text = {{key, "value"}};
    EXPECT_THROW(write_png(GrayImage8(1, 1), dir / "text.png", text), InvalidInputError) << key;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "text.png"));
  EXPECT_THAT([&] { write_png(GrayImage8(1, 1), dir / "no" / "such" / "folder.png"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("does not exist")));
}

}  // namespace
}  // namespace mmm::image
