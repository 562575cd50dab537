#include "core/image/mesh_render.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::image {

namespace {

constexpr double kMaxSide = 20000.0;  // pixels

// Orthographic camera: right/up/depth coordinates to pixels.
struct Camera {
  Eigen::Vector3d right;
  Eigen::Vector3d up;
  Eigen::Vector3d forward;  // unit view direction; depth grows along it
  double scale = 1;         // pixels per mm
  double right_min = 0;     // mm, maps to the left margin
  double up_max = 0;        // mm, maps to the top margin
  double margin = 0;        // pixels

  [[nodiscard]] Eigen::Vector3d to_screen(const Eigen::Vector3d& p) const {
    return {(p.dot(right) - right_min) * scale + margin, (up_max - p.dot(up)) * scale + margin,
            p.dot(forward)};
  }
};

void check_options(const RenderOptions& options) {
  const double length = options.view_direction.norm();
  if (!options.view_direction.allFinite() || !(length > 0)) {
    throw InvalidInputError("RenderOptions.view_direction must be finite and non-zero");
  }
  if (!options.up.allFinite()) throw InvalidInputError("RenderOptions.up must be finite");
  const Eigen::Vector3d d = options.view_direction / length;
  const Eigen::Vector3d up = options.up - options.up.dot(d) * d;
  if (!(up.norm() > 1e-9 * options.up.norm())) {
    throw InvalidInputError("RenderOptions.up is zero or parallel to view_direction");
  }
  if (!std::isfinite(options.pixels_per_mm) || options.pixels_per_mm < 0) {
    throw InvalidInputError(
        "RenderOptions.pixels_per_mm must be finite and >= 0 (0: fit "
        "image_width), got " +
        std::to_string(options.pixels_per_mm));
  }
  if (options.margin_px < 0) {
    throw InvalidInputError("RenderOptions.margin_px must be >= 0, got " +
                            std::to_string(options.margin_px));
  }
  if (options.pixels_per_mm == 0 && options.image_width <= 2 * options.margin_px) {
    throw InvalidInputError("RenderOptions.image_width (" + std::to_string(options.image_width) +
                            ") must exceed twice margin_px (" + std::to_string(options.margin_px) +
                            ")");
  }
  if (!(options.ambient >= 0 && options.ambient <= 1)) {
    throw InvalidInputError("RenderOptions.ambient must be in [0, 1], got " +
                            std::to_string(options.ambient));
  }
  if (!(options.outline_depth_jump_mm > 0)) {
    throw InvalidInputError("RenderOptions.outline_depth_jump_mm must be > 0, got " +
                            std::to_string(options.outline_depth_jump_mm));
  }
}

// Area-weighted vertex normals (unit; zero for unused vertices).
Eigen::MatrixX3d vertex_normals(const mesh::IndexedMesh& surface) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(surface.V.rows(), 3);
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose();
    const Eigen::Vector3d b = surface.V.row(surface.F(f, 1)).transpose();
    const Eigen::Vector3d c = surface.V.row(surface.F(f, 2)).transpose();
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();  // length = 2 area
    for (int k = 0; k < 3; ++k) normals.row(surface.F(f, k)) += n;
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const double length = normals.row(v).norm();
    if (length > 0) normals.row(v) /= length;
  }
  return normals;
}

std::uint8_t shade(std::uint8_t channel, double intensity) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(channel * intensity), 0L, 255L));
}

struct Buffers {
  int width = 0;
  int height = 0;
  std::vector<double> depth;  // +infinity where nothing is drawn
  std::vector<int> item;      // index of the item drawn, -1 for background
  RgbImage8 colour;

  Buffers(int w, int h, Rgb8 background)
      : width(w),
        height(h),
        depth(static_cast<std::size_t>(w) * static_cast<std::size_t>(h),
              std::numeric_limits<double>::infinity()),
        item(depth.size(), -1),
        colour(w, h) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) set_rgb(colour, x, y, background);
    }
  }
  [[nodiscard]] std::size_t at(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }
};

void rasterize(const mesh::IndexedMesh& surface, int index, Rgb8 colour, const Camera& camera,
               const RenderOptions& options, Buffers& buffers) {
  const Eigen::MatrixX3d normals =
      options.smooth_shading ? vertex_normals(surface) : Eigen::MatrixX3d();
  Eigen::MatrixX3d screen(surface.V.rows(), 3);
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v) {
    screen.row(v) = camera.to_screen(surface.V.row(v).transpose()).transpose();
  }
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    const std::array<int, 3> corner = {surface.F(f, 0), surface.F(f, 1), surface.F(f, 2)};
    const Eigen::Vector3d p0 = screen.row(corner[0]).transpose();
    const Eigen::Vector3d p1 = screen.row(corner[1]).transpose();
    const Eigen::Vector3d p2 = screen.row(corner[2]).transpose();
    // Twice the signed screen area; edge-on triangles cover no pixel centre.
    const double area =
        (p1.x() - p0.x()) * (p2.y() - p0.y()) - (p1.y() - p0.y()) * (p2.x() - p0.x());
    if (std::abs(area) < 1e-12) continue;
    Eigen::Vector3d face_normal = Eigen::Vector3d::Zero();
    if (!options.smooth_shading) {
      const Eigen::Vector3d a = surface.V.row(corner[0]).transpose();
      const Eigen::Vector3d b = surface.V.row(corner[1]).transpose();
      const Eigen::Vector3d c = surface.V.row(corner[2]).transpose();
      face_normal = (b - a).cross(c - a).normalized();
    }
    const int x_begin =
        std::max(0, static_cast<int>(std::ceil(std::min({p0.x(), p1.x(), p2.x()}) - 0.5)));
    const int x_end = std::min(
        buffers.width - 1, static_cast<int>(std::floor(std::max({p0.x(), p1.x(), p2.x()}) - 0.5)));
    const int y_begin =
        std::max(0, static_cast<int>(std::ceil(std::min({p0.y(), p1.y(), p2.y()}) - 0.5)));
    const int y_end = std::min(
        buffers.height - 1, static_cast<int>(std::floor(std::max({p0.y(), p1.y(), p2.y()}) - 0.5)));
    for (int y = y_begin; y <= y_end; ++y) {
      const double py = y + 0.5;
      for (int x = x_begin; x <= x_end; ++x) {
        const double px = x + 0.5;
        // Barycentric weights from the edge functions, sign-normalised by the
        // area so that either winding works; a centre on an edge belongs to
        // both triangles (no cracks; the z-buffer settles the tie).
        const double w0 = ((p1.x() - px) * (p2.y() - py) - (p1.y() - py) * (p2.x() - px)) / area;
        const double w1 = ((p2.x() - px) * (p0.y() - py) - (p2.y() - py) * (p0.x() - px)) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double depth = w0 * p0.z() + w1 * p1.z() + w2 * p2.z();
        const std::size_t at = buffers.at(x, y);
        if (!(depth < buffers.depth[at])) continue;
        buffers.depth[at] = depth;
        buffers.item[at] = index;
        Eigen::Vector3d normal = face_normal;
        if (options.smooth_shading) {
          normal = w0 * normals.row(corner[0]).transpose() +
                   w1 * normals.row(corner[1]).transpose() +
                   w2 * normals.row(corner[2]).transpose();
          const double length = normal.norm();
          normal = length > 0 ? Eigen::Vector3d(normal / length) : Eigen::Vector3d::Zero();
        }
        const double intensity =
            options.ambient + (1.0 - options.ambient) * std::abs(normal.dot(camera.forward));
        set_rgb(
            buffers.colour, x, y,
            {shade(colour.r, intensity), shade(colour.g, intensity), shade(colour.b, intensity)});
      }
    }
  }
}

void draw_outlines(const RenderOptions& options, Buffers& buffers) {
  std::vector<bool> edge(buffers.depth.size(), false);
  constexpr std::array<std::array<int, 2>, 4> kNeighbours = {{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  for (int y = 0; y < buffers.height; ++y) {
    for (int x = 0; x < buffers.width; ++x) {
      const std::size_t at = buffers.at(x, y);
      if (buffers.item[at] < 0) continue;
      for (const auto& [dx, dy] : kNeighbours) {
        const int nx = x + dx;
        const int ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= buffers.width || ny >= buffers.height) {
          edge[at] = true;  // a mesh touching the image border
          break;
        }
        const std::size_t other = buffers.at(nx, ny);
        const bool background = buffers.item[other] < 0;
        const double step = buffers.depth[other] - buffers.depth[at];
        const bool other_mesh_behind = buffers.item[other] != buffers.item[at] && step > 0;
        if (background || other_mesh_behind || step > options.outline_depth_jump_mm) {
          edge[at] = true;
          break;
        }
      }
    }
  }
  for (int y = 0; y < buffers.height; ++y) {
    for (int x = 0; x < buffers.width; ++x) {
      if (edge[buffers.at(x, y)]) set_rgb(buffers.colour, x, y, options.outline_colour);
    }
  }
}

}  // namespace

RgbImage8 render_meshes(std::span<const RenderItem> items, const RenderOptions& options) {
  check_options(options);
  Camera camera;
  camera.forward = options.view_direction.normalized();
  camera.up = (options.up - options.up.dot(camera.forward) * camera.forward).normalized();
  camera.right = camera.forward.cross(camera.up);
  camera.margin = options.margin_px;

  double right_max = -std::numeric_limits<double>::infinity();
  double up_min = std::numeric_limits<double>::infinity();
  camera.right_min = std::numeric_limits<double>::infinity();
  camera.up_max = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < items.size(); ++k) {
    const mesh::IndexedMesh* surface = items[k].mesh;
    if (surface == nullptr) {
      throw InvalidInputError("render_meshes: item " + std::to_string(k) + " has no mesh (null)");
    }
    mesh::validate_indices_and_coordinates(*surface);
    // Only vertices used by a face count toward the framing.
    for (Eigen::Index f = 0; f < surface->F.rows(); ++f) {
      for (int c = 0; c < 3; ++c) {
        const Eigen::Vector3d p = surface->V.row(surface->F(f, c)).transpose();
        camera.right_min = std::min(camera.right_min, p.dot(camera.right));
        right_max = std::max(right_max, p.dot(camera.right));
        up_min = std::min(up_min, p.dot(camera.up));
        camera.up_max = std::max(camera.up_max, p.dot(camera.up));
      }
    }
  }
  if (!std::isfinite(right_max)) throw InvalidInputError("render_meshes: no face to draw");
  const double extent_right = right_max - camera.right_min;
  const double extent_up = camera.up_max - up_min;
  if (options.pixels_per_mm > 0) {
    camera.scale = options.pixels_per_mm;
  } else {
    // A mesh seen edge-on has no width: fit its height to the width instead.
    const double extent = extent_right > 0 ? extent_right : extent_up;
    camera.scale = extent > 0 ? (options.image_width - 2.0 * options.margin_px) / extent : 1.0;
  }
  const double width = options.pixels_per_mm > 0
                           ? std::ceil(extent_right * camera.scale) + 2.0 * options.margin_px
                           : options.image_width;
  const double height = std::ceil(extent_up * camera.scale) + 2.0 * options.margin_px;
  if (width > kMaxSide || height > kMaxSide) {
    throw InvalidInputError("render_meshes: the image would be " + std::to_string(width) + " x " +
                            std::to_string(height) +
                            " pixels (limit 20000 a side): lower pixels_per_mm or image_width");
  }
  Buffers buffers(std::max(1, static_cast<int>(width)), std::max(1, static_cast<int>(height)),
                  options.background);
  for (std::size_t k = 0; k < items.size(); ++k) {
    rasterize(*items[k].mesh, static_cast<int>(k), items[k].colour, camera, options, buffers);
  }
  if (options.outline) draw_outlines(options, buffers);
  return std::move(buffers.colour);
}

RgbImage8 side_by_side(std::span<const RgbImage8> images, const SideBySideOptions& options) {
  if (images.empty()) throw InvalidInputError("side_by_side: no image");
  if (options.gap_px < 0) {
    throw InvalidInputError("SideBySideOptions.gap_px must be >= 0, got " +
                            std::to_string(options.gap_px));
  }
  int width = 0;
  int height = 0;
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (images[k].pixels.size() != images[k].sample_count()) {
      throw InvalidInputError("side_by_side: image " + std::to_string(k) +
                              " holds the wrong number of samples for its size");
    }
    width += images[k].width + (k > 0 ? options.gap_px : 0);
    height = std::max(height, images[k].height);
  }
  RgbImage8 out(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) set_rgb(out, x, y, options.background);
  }
  int left = 0;
  for (const RgbImage8& image : images) {
    for (int y = 0; y < image.height && image.width > 0; ++y) {
      std::copy_n(&image.at(0, y), 3 * static_cast<std::size_t>(image.width), &out.at(left, y));
    }
    left += image.width + options.gap_px;
  }
  return out;
}

}  // namespace mmm::image
