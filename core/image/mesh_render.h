#pragma once
// A small software rasterizer for pictures of meshes (atlas reports, review
// pages): orthographic projection, z-buffer, Lambert + ambient shading under a
// headlight, one colour per mesh, optional outlines.
//
//   basis: d = view direction, up' = up made perpendicular to d, right = d x up'
//   scale: pixels_per_mm, or fitted so that the meshes' extent along `right`
//          fills image_width minus the margins
//   per triangle: screen positions of its corners; for every pixel centre
//     (x + 0.5, y + 0.5) inside it (edge functions, barycentric weights w):
//       depth = w . corner depths; if nearer than the z-buffer: keep it, and
//       colour = mesh colour * (ambient + (1 - ambient) |n . d|), n the face
//       normal or the interpolated vertex normal (two-sided, so meshes of
//       either orientation look the same)
//   outline: a covered pixel next to background, or next to a farther pixel
//     of another mesh or one more than outline_depth_jump_mm farther, is
//     painted outline_colour (silhouettes and occluding contours).
//
// Views of the patient frame (x subject's right, y anterior, z superior):
//   front (the default): view_direction (0, -1, 0), up (0, 0, 1): seen from
//     in front, the subject's right on the image left, like the frontal
//     radiograph of projection.h;
//   side: view_direction (-1, 0, 0), up (0, 0, 1): seen from the subject's
//     right, anterior on the image right, like the lateral radiograph.

#include <Eigen/Core>
#include <span>

#include "core/image/image.h"
#include "core/mesh/mesh.h"

namespace mmm::image {

// One mesh to draw and its colour.
struct RenderItem {
  const mesh::IndexedMesh* mesh = nullptr;  // not owned; V in mm
  Rgb8 colour{200, 200, 200};
};

struct RenderOptions {
  // Direction the camera looks along (world, any non-zero length). Default:
  // the front view (see above).
  Eigen::Vector3d view_direction{0, -1, 0};
  // World direction shown upward; its part along view_direction is ignored.
  Eigen::Vector3d up{0, 0, 1};
  // Pixels per mm. 0 (default): fit the width instead (image_width).
  double pixels_per_mm = 0;
  // Total image width (pixels, margins included) when pixels_per_mm is 0; the
  // height follows from the meshes' extent along `up`.
  int image_width = 800;
  // Empty border around the meshes on every side (pixels).
  int margin_px = 10;
  Rgb8 background{255, 255, 255};
  // Share of the colour a surface keeps when turned edge-on to the light
  // (in [0, 1]); surfaces facing the camera get the full colour.
  double ambient = 0.3;
  // Interpolate area-weighted vertex normals (smooth look) rather than use
  // each face's normal (faceted look).
  bool smooth_shading = true;
  bool outline = true;
  Rgb8 outline_colour{40, 40, 40};
  // Depth step within one mesh that counts as a contour (mm): large enough to
  // ignore the curvature between neighbouring pixels, small enough to show a
  // bone in front of itself.
  double outline_depth_jump_mm = 5.0;
};

// Renders the meshes into a new image. Items whose mesh has no face are
// skipped. Throws InvalidInputError for a null mesh, a mesh with a non-finite
// coordinate or a face index out of range, no face at all to draw, a zero or
// non-finite view direction, an up vector parallel to it, pixels_per_mm < 0,
// image_width <= 2 margin_px when fitting, margin_px < 0, ambient outside
// [0, 1], outline_depth_jump_mm <= 0, or an image above 20000 pixels a side.
RgbImage8 render_meshes(std::span<const RenderItem> items, const RenderOptions& options = {});

struct SideBySideOptions {
  int gap_px = 10;                 // background columns between images
  Rgb8 background{255, 255, 255};  // fills the gaps and below shorter images
};

// Images placed left to right, top-aligned, in one image as tall as the
// tallest. Throws InvalidInputError when there is no image, an image's pixel
// count does not match its size, or gap_px < 0.
RgbImage8 side_by_side(std::span<const RgbImage8> images, const SideBySideOptions& options = {});

}  // namespace mmm::image
