#include "core/image/outline_overlay.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/image/mesh_render.h"
#include "core/image/silhouette.h"

namespace mmm::image {

namespace {

constexpr double kMaxLineWidth = 20.0;      // pixels
constexpr double kMaxMarkerRadius = 200.0;  // pixels
constexpr int kMinMaxWidth = 64;            // pixels
// Legend swatches: side, pitch between swatches and distance from the corner
// (pixels).
constexpr int kSwatch = 14;
constexpr int kSwatchPitch = 18;
constexpr int kLegendMargin = 8;
constexpr Rgb8 kSwatchBorder{0, 0, 0};

std::string format_point(const Eigen::Vector3d& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

std::string item_label(std::span<const OutlineItem> items, std::size_t k) {
  return "item " + std::to_string(k) + " ('" + items[k].name + "')";
}

void check_options(const OverlayOptions& options) {
  if (!(options.low_percentile >= 0 && options.low_percentile < options.high_percentile &&
        options.high_percentile <= 100)) {
    throw InvalidInputError(
        "OverlayOptions: need 0 <= low_percentile < high_percentile <= 100, got " +
        std::to_string(options.low_percentile) + " and " + std::to_string(options.high_percentile));
  }
  for (const auto& [bound, field] : {std::pair{options.window_low, "window_low"},
                                     std::pair{options.window_high, "window_high"}}) {
    if (bound && !std::isfinite(*bound)) {
      throw InvalidInputError(std::string("OverlayOptions.") + field + " must be finite");
    }
  }
  if (options.window_low && options.window_high && !(*options.window_low < *options.window_high)) {
    throw InvalidInputError("OverlayOptions: window_low (" + std::to_string(*options.window_low) +
                            ") must be below window_high (" + std::to_string(*options.window_high) +
                            ")");
  }
  if (!(options.line_width_px > 0 && options.line_width_px <= kMaxLineWidth)) {
    throw InvalidInputError("OverlayOptions.line_width_px must be in (0, 20], got " +
                            std::to_string(options.line_width_px));
  }
  if (!(options.marker_radius_px > 0 && options.marker_radius_px <= kMaxMarkerRadius)) {
    throw InvalidInputError("OverlayOptions.marker_radius_px must be in (0, 200], got " +
                            std::to_string(options.marker_radius_px));
  }
  if (options.max_width < kMinMaxWidth) {
    throw InvalidInputError("OverlayOptions.max_width must be >= 64, got " +
                            std::to_string(options.max_width));
  }
  if (options.min_contour_edges < 1) {
    throw InvalidInputError("OverlayOptions.min_contour_edges must be >= 1, got " +
                            std::to_string(options.min_contour_edges));
  }
  if (options.gap_px < 0) {
    throw InvalidInputError("OverlayOptions.gap_px must be >= 0, got " +
                            std::to_string(options.gap_px));
  }
  for (std::size_t k = 0; k < options.points.size(); ++k) {
    if (!options.points[k].position_mm.allFinite()) {
      throw InvalidInputError("OverlayOptions.points[" + std::to_string(k) +
                              "]: position_mm is not finite " +
                              format_point(options.points[k].position_mm));
    }
  }
}

void check_items(std::span<const OutlineItem> items) {
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (items[k].mesh == nullptr) {
      throw InvalidInputError("outline_overlay: " + item_label(items, k) + " has no mesh (null)");
    }
    try {
      mesh::validate_indices_and_coordinates(*items[k].mesh);
    } catch (const InvalidInputError& e) {
      throw InvalidInputError("outline_overlay: " + item_label(items, k) + ": " + e.what());
    }
  }
}

void check_radiograph(const RadiographView& view, const GrayImage16& radiograph) {
  validate_view(view);
  if (radiograph.width != view.width || radiograph.height != view.height) {
    throw InvalidInputError("outline_overlay: view '" + view.name + "' is " +
                            std::to_string(view.width) + " x " + std::to_string(view.height) +
                            " pixels, the radiograph " + std::to_string(radiograph.width) + " x " +
                            std::to_string(radiograph.height));
  }
  if (radiograph.pixels.size() != radiograph.sample_count()) {
    throw InvalidInputError("outline_overlay: the radiograph of view '" + view.name + "' holds " +
                            std::to_string(radiograph.pixels.size()) + " samples, its size needs " +
                            std::to_string(radiograph.sample_count()));
  }
}

// The smallest sample value v with at least max(1, ceil(percent / 100 * N))
// samples <= v.
double percentile(const std::vector<std::size_t>& histogram, std::size_t count, double percent) {
  const auto rank = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(percent / 100.0 * static_cast<double>(count))));
  std::size_t cumulative = 0;
  for (std::size_t v = 0; v < histogram.size(); ++v) {
    cumulative += histogram[v];
    if (cumulative >= rank) return static_cast<double>(v);
  }
  return static_cast<double>(histogram.size() - 1);
}

// The grey level (0-255) of every 16-bit sample value: the window of the
// header, from the radiograph's histogram unless both bounds are given.
std::vector<std::uint8_t> window_table(const GrayImage16& radiograph,
                                       const OverlayOptions& options) {
  double low = options.window_low.value_or(0);
  double high = options.window_high.value_or(0);
  if (!options.window_low || !options.window_high) {
    std::vector<std::size_t> histogram(65536, 0);
    for (const std::uint16_t v : radiograph.pixels) ++histogram[v];
    const std::size_t count = radiograph.pixels.size();
    if (!options.window_low) low = percentile(histogram, count, options.low_percentile);
    if (!options.window_high) high = percentile(histogram, count, options.high_percentile);
  }
  if (!(high > low)) high = low + 1;  // a flat image, or one bound above the other's percentile
  std::vector<std::uint8_t> table(65536);
  for (std::size_t v = 0; v < table.size(); ++v) {
    const double t = std::clamp((static_cast<double>(v) - low) / (high - low), 0.0, 1.0);
    table[v] = static_cast<std::uint8_t>(std::lround(t * 255.0));
  }
  return table;
}

GrayImage8 window(const GrayImage16& radiograph, const OverlayOptions& options) {
  const std::vector<std::uint8_t> table = window_table(radiograph, options);
  GrayImage8 grey(radiograph.width, radiograph.height);
  for (std::size_t i = 0; i < grey.pixels.size(); ++i) grey.pixels[i] = table[radiograph.pixels[i]];
  return grey;
}

// The windowed radiograph as RGB grey, in one pass.
RgbImage8 window_rgb(const GrayImage16& radiograph, const OverlayOptions& options) {
  const std::vector<std::uint8_t> table = window_table(radiograph, options);
  RgbImage8 rgb(radiograph.width, radiograph.height);
  std::uint8_t* out = rgb.pixels.data();
  for (const std::uint16_t v : radiograph.pixels) {
    const std::uint8_t g = table[v];
    *out++ = g;
    *out++ = g;
    *out++ = g;
  }
  return rgb;
}

// Area-averaging weights of a 1-D resampling from `from` to `to` <= `from`
// samples: output sample i covers input [i r, (i + 1) r), r = from / to.
struct Tap {
  int source = 0;
  double weight = 0;
};
std::vector<std::vector<Tap>> area_taps(int from, int to) {
  std::vector<std::vector<Tap>> taps(static_cast<std::size_t>(to));
  const double ratio = static_cast<double>(from) / to;
  for (int i = 0; i < to; ++i) {
    const double begin = i * ratio;
    const double end = (i + 1) * ratio;
    for (int s = static_cast<int>(std::floor(begin));
         s < std::min(from, static_cast<int>(std::ceil(end))); ++s) {
      const double overlap = std::min(end, s + 1.0) - std::max(begin, static_cast<double>(s));
      if (overlap > 0) taps[static_cast<std::size_t>(i)].push_back({s, overlap / ratio});
    }
  }
  return taps;
}

GrayImage8 resample_area(const GrayImage8& grey, int width, int height) {
  const auto columns = area_taps(grey.width, width);
  const auto rows = area_taps(grey.height, height);
  std::vector<double> horizontal(static_cast<std::size_t>(width) *
                                 static_cast<std::size_t>(grey.height));
  for (int y = 0; y < grey.height; ++y) {
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      for (const Tap& tap : columns[static_cast<std::size_t>(x)]) {
        sum += tap.weight * grey.at(tap.source, y);
      }
      horizontal[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(x)] = sum;
    }
  }
  GrayImage8 out(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      for (const Tap& tap : rows[static_cast<std::size_t>(y)]) {
        sum += tap.weight *
               horizontal[static_cast<std::size_t>(tap.source) * static_cast<std::size_t>(width) +
                          static_cast<std::size_t>(x)];
      }
      out.at(x, y) = static_cast<std::uint8_t>(std::lround(std::clamp(sum, 0.0, 255.0)));
    }
  }
  return out;
}

RgbImage8 to_rgb(const GrayImage8& grey) {
  RgbImage8 rgb(grey.width, grey.height);
  for (std::size_t i = 0; i < grey.pixels.size(); ++i) {
    std::fill_n(&rgb.pixels[3 * i], 3, grey.pixels[i]);
  }
  return rgb;
}

// Anti-aliased strokes: coverage accumulates (maximum) over the strokes of
// one colour, then is blended into the image once.
class Painter {
 public:
  Painter(RgbImage8& image, double line_width)
      : image_(image),
        reach_(line_width / 2 + 0.5),
        coverage_(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height),
                  0) {}

  void segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d ab = b - a;
    const double length2 = ab.squaredNorm();
    stamp(a.cwiseMin(b), a.cwiseMax(b), [&](const Eigen::Vector2d& p) {
      const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
      return (p - (a + t * ab)).norm();
    });
  }

  void ring(const Eigen::Vector2d& centre, double radius) {
    const Eigen::Vector2d extent(radius, radius);
    stamp(centre - extent, centre + extent,
          [&](const Eigen::Vector2d& p) { return std::abs((p - centre).norm() - radius); });
  }

  // Blends the accumulated coverage in `colour` and clears it.
  void flush(Rgb8 colour) {
    const std::array<double, 3> target = {static_cast<double>(colour.r),
                                          static_cast<double>(colour.g),
                                          static_cast<double>(colour.b)};
    for (const std::size_t i : touched_) {
      const double a = coverage_[i] / 255.0;
      for (std::size_t c = 0; c < 3; ++c) {
        std::uint8_t& sample = image_.pixels[3 * i + c];
        sample = static_cast<std::uint8_t>(std::lround((1 - a) * sample + a * target[c]));
      }
      coverage_[i] = 0;
    }
    touched_.clear();
  }

 private:
  // Visits the pixel centres within reach_ of the box [low, high] (clipped
  // to the image) and raises their coverage by the distance `distance`.
  template <typename Distance>
  void stamp(const Eigen::Vector2d& low, const Eigen::Vector2d& high, Distance distance) {
    // Bounds in double first: a point near the source plane projects far away.
    const auto first = [&](double v, int size) {
      return static_cast<int>(
          std::clamp(std::ceil(v - reach_ - 0.5), 0.0, static_cast<double>(size)));
    };
    const auto last = [&](double v, int size) {
      return static_cast<int>(std::clamp(std::floor(v + reach_ - 0.5), -1.0, size - 1.0));
    };
    const int x0 = first(low.x(), image_.width);
    const int x1 = last(high.x(), image_.width);
    const int y0 = first(low.y(), image_.height);
    const int y1 = last(high.y(), image_.height);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double cover = std::min(1.0, reach_ - distance(Eigen::Vector2d(x + 0.5, y + 0.5)));
        if (!(cover > 0.5 / 255)) continue;
        const std::size_t i = image_.index(x, y) / 3;  // pixel, not sample
        if (coverage_[i] == 0) touched_.push_back(i);
        coverage_[i] = std::max(coverage_[i], static_cast<std::uint8_t>(std::lround(cover * 255)));
      }
    }
  }

  RgbImage8& image_;
  double reach_;
  std::vector<std::uint8_t> coverage_;  // 0-255 for 0-1
  std::vector<std::size_t> touched_;
};

void draw_legend(RgbImage8& image, std::span<const OutlineItem> items) {
  int left = kLegendMargin;
  int top = kLegendMargin;
  for (const OutlineItem& item : items) {
    if (top + kSwatch > image.height - kLegendMargin && top > kLegendMargin) {
      top = kLegendMargin;  // next column
      left += kSwatchPitch;
    }
    for (int y = top; y < std::min(top + kSwatch, image.height); ++y) {
      for (int x = left; x < std::min(left + kSwatch, image.width); ++x) {
        const bool border =
            x == left || y == top || x == left + kSwatch - 1 || y == top + kSwatch - 1;
        set_rgb(image, x, y, border ? kSwatchBorder : item.colour);
      }
    }
    top += kSwatchPitch;
  }
}

// Outlines and markers of one view onto `canvas` (the view's size).
void draw_view(const RadiographView& view, RgbImage8& canvas, std::span<const OutlineItem> items,
               const OverlayOptions& options) {
  Painter painter(canvas, options.line_width_px);
  for (std::size_t k = 0; k < items.size(); ++k) {
    const mesh::IndexedMesh& surface = *items[k].mesh;
    if (surface.empty()) continue;
    const std::vector<Eigen::Vector2d> pixels =
        project_face_vertices(view, surface, "outline_overlay: " + item_label(items, k));
    const std::vector<std::array<int, 2>> edges =
        keep_contour_pieces(silhouette_edges(surface, view), options.min_contour_edges);
    for (const auto& [a, b] : edges) {
      painter.segment(pixels[static_cast<std::size_t>(a)], pixels[static_cast<std::size_t>(b)]);
    }
    painter.flush(items[k].colour);
  }
  for (const OverlayPoint& point : options.points) {
    const Eigen::Vector2d centre = project(view, point.position_mm);
    const double r = options.marker_radius_px;
    if (point.marker == PointMarker::kCircle) {
      painter.ring(centre, r);
    } else {
      painter.segment(centre - Eigen::Vector2d(r, 0), centre + Eigen::Vector2d(r, 0));
      painter.segment(centre - Eigen::Vector2d(0, r), centre + Eigen::Vector2d(0, r));
    }
    painter.flush(point.colour);
  }
}

// HSV (h in degrees, s and v in [0, 1]) to 8-bit RGB.
Rgb8 hsv(double h, double s, double v) {
  const double c = v * s;
  const double x = c * (1 - std::abs(std::fmod(h / 60.0, 2.0) - 1));
  const double m = v - c;
  std::array<double, 3> rgb{};
  const int sector = static_cast<int>(h / 60.0) % 6;
  switch (sector) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  const auto channel = [&](double value) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(value + m, 0.0, 1.0) * 255.0));
  };
  return {channel(rgb[0]), channel(rgb[1]), channel(rgb[2])};
}

}  // namespace

RgbImage8 outline_overlay(const RadiographView& view, const GrayImage16& radiograph,
                          std::span<const OutlineItem> items, const OverlayOptions& options) {
  check_options(options);
  check_radiograph(view, radiograph);
  check_items(items);
  RgbImage8 canvas = window_rgb(radiograph, options);
  draw_view(view, canvas, items, options);
  if (options.legend) draw_legend(canvas, items);
  return canvas;
}

RgbImage8 outline_overlay_pair(const RadiographPair& pair, std::span<const OutlineItem> items,
                               const OverlayOptions& options) {
  check_options(options);
  check_items(items);
  if (pair.views.empty()) throw InvalidInputError("outline_overlay_pair: the pair has no view");
  int total = options.gap_px * static_cast<int>(pair.views.size() - 1);
  for (const RadiographFile& file : pair.views) total += file.view.width;
  // Scale of every view: the views' widths share what max_width leaves after the gaps.
  const int gaps = options.gap_px * static_cast<int>(pair.views.size() - 1);
  const double scale = total <= options.max_width ? 1.0
                                                  : std::max(1, options.max_width - gaps) /
                                                        static_cast<double>(total - gaps);
  std::vector<RgbImage8> pictures;
  for (const RadiographFile& file : pair.views) {
    const GrayImage16 radiograph = pair.image(file.view.name);
    check_radiograph(file.view, radiograph);
    GrayImage8 grey = window(radiograph, options);
    RadiographView view = file.view;
    if (scale < 1.0) {
      const int width = std::max(1, static_cast<int>(std::floor(view.width * scale)));
      const int height = std::max(1, static_cast<int>(std::lround(view.height * scale)));
      grey = resample_area(grey, width, height);
      // Pixel coordinates scale with the image: [0, W] -> [0, width].
      const Eigen::Vector3d rows(static_cast<double>(width) / view.width,
                                 static_cast<double>(height) / view.height, 1.0);
      view.P = rows.asDiagonal() * view.P;
      view.pixel_spacing_mm *= static_cast<double>(view.width) / width;
      view.width = width;
      view.height = height;
    }
    RgbImage8 canvas = to_rgb(grey);
    draw_view(view, canvas, items, options);
    pictures.push_back(std::move(canvas));
  }
  SideBySideOptions layout;
  layout.gap_px = options.gap_px;
  RgbImage8 picture = side_by_side(pictures, layout);
  if (options.legend) draw_legend(picture, items);
  return picture;
}

std::vector<Rgb8> distinct_colours(int count) {
  std::vector<Rgb8> colours;
  colours.reserve(static_cast<std::size_t>(std::max(0, count)));
  for (int k = 0; k < count; ++k) {
    // Golden-angle hue steps keep consecutive items far apart on the wheel;
    // alternating value keeps neighbours of similar hue distinguishable.
    colours.push_back(hsv(std::fmod(k * 137.50776405, 360.0), 0.85, k % 2 == 0 ? 1.0 : 0.8));
  }
  return colours;
}

}  // namespace mmm::image
