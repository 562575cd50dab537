#pragma once
// Plain raster images: a width, a height and the samples in one row-major
// std::vector, channels interleaved. No views, strides or padding: the
// containers the PNG codec, the DRR and the mesh renderer exchange.
//
// Pixel (x, y) is column x (0 at the left, growing to the right) of row y (0
// at the top, growing downwards); channel c of it is
//   pixels[(y * width + x) * kChannels + c].

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::image {

template <typename T, int Channels>
struct Image {
  static_assert(Channels >= 1 && Channels <= 4, "1 to 4 interleaved channels");
  using Sample = T;
  static constexpr int kChannels = Channels;

  int width = 0;
  int height = 0;
  std::vector<T> pixels;  // width * height * kChannels samples, row-major

  Image() = default;
  // A width x height image with every sample set to `fill`. Throws
  // InvalidInputError for a negative size.
  Image(int width_px, int height_px, T fill = T{}) : width(width_px), height(height_px) {
    if (width_px < 0 || height_px < 0) {
      throw InvalidInputError("image size must not be negative, got " + std::to_string(width_px) +
                              " x " + std::to_string(height_px));
    }
    pixels.assign(sample_count(), fill);
  }

  // width * height * kChannels (what pixels.size() must be).
  [[nodiscard]] std::size_t sample_count() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * kChannels;
  }
  [[nodiscard]] bool empty() const { return width == 0 || height == 0; }
  [[nodiscard]] std::size_t index(int x, int y, int c = 0) const {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
            static_cast<std::size_t>(x)) *
               kChannels +
           static_cast<std::size_t>(c);
  }
  // Sample access without bounds checks (x in [0, width), y in [0, height)).
  [[nodiscard]] T& at(int x, int y, int c = 0) { return pixels[index(x, y, c)]; }
  [[nodiscard]] const T& at(int x, int y, int c = 0) const { return pixels[index(x, y, c)]; }

  // Same size and samples.
  friend bool operator==(const Image&, const Image&) = default;
};

using GrayImage8 = Image<std::uint8_t, 1>;
using GrayImage16 = Image<std::uint16_t, 1>;
using RgbImage8 = Image<std::uint8_t, 3>;
using RgbaImage8 = Image<std::uint8_t, 4>;
// Single-channel float samples (DRR line integrals, depth buffers).
using FloatImage = Image<float, 1>;

// An 8-bit sRGB colour.
struct Rgb8 {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
  friend bool operator==(const Rgb8&, const Rgb8&) = default;
};

// Colour of pixel (x, y) of an RGB image, and setting it.
inline Rgb8 get_rgb(const RgbImage8& image, int x, int y) {
  return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
}
inline void set_rgb(RgbImage8& image, int x, int y, Rgb8 colour) {
  image.at(x, y, 0) = colour.r;
  image.at(x, y, 1) = colour.g;
  image.at(x, y, 2) = colour.b;
}

}  // namespace mmm::image
