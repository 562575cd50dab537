#pragma once
// What the soft tissue alone shows on a radiograph, predicted from the
// model's own muscles, so that the thickness term (thickness_term.h) can tell
// the bone's brightness from the tissue's around and under it.
//
// Under a bone the limb is thicker than beside it (a limb is convex across):
// a background interpolated linearly between the two sides of a femur's shaft
// misses about 3 mm of tissue under its middle, as much as 2 mm of bone on
// the image. The model predicts that shape:
//   envelope   the limb's outline around the model's bones and muscles
//              (limb_envelope.h, fat_mm of skin and fat outside them)
//   T(u, v)    mm of the ray inside the envelope (bones counted as tissue)
//   M(u, v)    mm of the ray inside the muscles (summed over them)
// both rendered on a coarse grid of each view (pixel_mm at the isocentre).
// The image's soft-tissue law is fitted to the image itself, by least
// squares over the pixels away from every bone (bone_margin_mm) and from the
// skin's edge (skin_margin_mm inside the outline, where the blur and any
// difference between the model's outline and the patient's matter most):
//   I(u, v) = offset + tissue_per_mm T + muscle_per_mm M
// with two rounds of trimming beyond 3 robust standard deviations. The
// prediction S(u, v) is that law at (u, v), read bilinearly from the grid.
// The thickness term uses S only for the shape of the tissue's path under the
// bone: its background is S plus the line through (I - S) on either side of
// the bone, so an error of level or slope in the model is removed there.
//
// Radiographs in mmm are linear in the line integral (drr.h); so are the
// log-converted images of a real system's raw data, which this law assumes.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"
#include "core/mesh/mesh.h"
#include "core/outlines/edge_image.h"

namespace mmm::outlines {

struct SoftTissueModelOptions {
  double pixel_mm = 1.5;         // the grid's pitch at the isocentre
  double fat_mm = 8.0;           // the envelope's skin and fat outside bones and muscles
  double bone_margin_mm = 4.0;   // law fitted on pixels at least this far from any bone
  double skin_margin_mm = 10.0;  // and this far inside the limb's outline
  int min_samples = 50;          // fewer: the law is not fitted, the model is not used
  // Fit the envelope's outline to the limb's in the images, row by row (see
  // above); off: the model's envelope as it is.
  bool fit_outline = true;
  double edge_search_mm = 40.0;  // the limb's edge is searched this far outside the model's
  int threads = 2;
};

// One view's prediction.
class SoftTissueImage {
 public:
  SoftTissueImage() = default;
  // `rows`: per grid row, whether the model holds there (its outline fitted
  // to the image's); empty: every row.
  SoftTissueImage(image::FloatImage tissue_mm, image::FloatImage muscle_mm, int factor,
                  std::vector<std::uint8_t> rows = {});

  // Whether the law was fitted: enough samples, and the tissue's median
  // contrast over them at least 5 times the law's residual (no tissue on a
  // radiograph of bones in air).
  [[nodiscard]] bool usable() const { return usable_; }
  // Predicted image value at a pixel of the view (fine pixels), bones counted
  // as tissue. Positions outside the grid are clamped.
  [[nodiscard]] double at(const Eigen::Vector2d& pixel) const;
  // Whether the model holds on image row v (fine pixels): the law was fitted
  // and the grid rows around v had their outline fitted.
  [[nodiscard]] bool holds(double v) const;
  // 1 on a row where the model holds, falling linearly to 0 over
  // `blend_rows` grid rows beyond.
  [[nodiscard]] double share(double v, int blend_rows) const;

  // Fits the law to `image` (see the file comment); `covered` marks the grid's
  // pixels near a bone (grid size, row-major).
  void fit_law(const EdgeImage& image, const std::vector<std::uint8_t>& covered,
               const SoftTissueModelOptions& options);

  double offset = 0.0;              // image units
  double tissue_per_mm = 0.0;       // image units per mm of tissue
  double muscle_per_mm = 0.0;       // image units per mm of muscle, above the tissue
  int samples = 0;                  // pixels the law was fitted on (after trimming)
  int rows_matched = 0;             // grid rows whose outline was fitted to the image's
  double median_width_ratio = 1.0;  // the image's limb width over the model's, median over them
  double residual_rms = 0.0;        // their residual (image units)

 private:
  image::FloatImage tissue_mm_;
  image::FloatImage muscle_mm_;
  int factor_ = 1;  // fine pixels per grid pixel
  std::vector<std::uint8_t> rows_;
  bool usable_ = false;
};

// The radiograph with the predicted soft tissue taken out (its air level
// kept) where the model holds, blended out over `blend_rows` grid rows
// beyond: about what the bones alone would show.
image::GrayImage16 without_soft_tissue(const image::GrayImage16& radiograph,
                                       const SoftTissueImage& model, int blend_rows = 8);

// Per view (same order as `views` and `images`). Throws InvalidInputError for
// no bones, a view that fails validate_view, views and images of different
// counts or an image of another size than its view, options out of range
// (pixel_mm, fat_mm or a margin not positive and finite, threads < 1).
std::vector<SoftTissueImage> model_soft_tissue(const std::vector<const mesh::IndexedMesh*>& bones,
                                               const std::vector<const mesh::IndexedMesh*>& muscles,
                                               const std::vector<image::RadiographView>& views,
                                               const std::vector<const EdgeImage*>& images,
                                               const SoftTissueModelOptions& options = {});

}  // namespace mmm::outlines
