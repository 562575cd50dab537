#pragma once
// Where a bone lies on a radiograph: the pixels whose centre falls inside the
// projection of one of its surface's faces (each face rasterised by edge
// functions, either orientation), kept within the projection's bounding box.
// Summed over the bones of an atlas, the covers say where bones overlap on
// the image, so that the thickness term (thickness_term.h) can leave out image
// rows that another bone crosses.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/image/projection.h"
#include "core/mesh/mesh.h"

namespace mmm::outlines {

// A rectangle of an image's pixels: columns x0 .. x0 + width - 1, rows
// y0 .. y0 + height - 1.
struct PixelRegion {
  int x0 = 0;
  int y0 = 0;
  int width = 0;
  int height = 0;
};

class BoneCover {
 public:
  BoneCover() = default;
  // Faces with a corner behind the source plane are left out.
  BoneCover(const mesh::IndexedMesh& surface, const image::RadiographView& view);

  [[nodiscard]] bool covered(int x, int y) const;
  // The projection's bounding box within the image (empty when nothing of
  // the bone is in front of the source or in the image).
  [[nodiscard]] PixelRegion region() const { return {x0_, y0_, width_, height_}; }
  // Adds 1 (saturating at 255) to counts[y * width + x] for every covered
  // pixel inside a width x height image.
  void add_to(std::vector<std::uint8_t>& counts, int width, int height) const;

 private:
  int x0_ = 0;
  int y0_ = 0;
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> inside_;
};

// Bones over each pixel of a view (row-major, width x height of the view).
std::vector<std::uint8_t> count_cover(const std::vector<const mesh::IndexedMesh*>& surfaces,
                                      const image::RadiographView& view);

}  // namespace mmm::outlines
