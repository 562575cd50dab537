#pragma once
// Digitally reconstructed radiographs (DRR) of closed surface meshes, and
// their conversion to a 16-bit "radiograph" with a simple detector model.
//
// Each mesh k bounds a homogeneous material with linear attenuation mu_k
// (1/mm). For each pixel, the ray from the view's source through the pixel
// centre accumulates the line integral
//   L = sum_k mu_k * (length of the ray inside mesh k)         (dimensionless)
// and Beer-Lambert gives the transmitted fraction exp(-L). Per mesh:
//   if the ray misses the mesh's bounding box: 0 (slab test, no tree walk)
//   hits = AabbTree::all_hits(ray), sorted by t
//   depth = 0
//   for each hit: entering if the face normal opposes the ray direction
//     entering: depth += 1 (an interval opens when depth becomes 1)
//     exiting:  if depth > 0: depth -= 1 (it closes when depth becomes 0)
//   length = sum of the closed intervals
// The depth count is the winding number along the ray, so a cavity modelled
// by an inward-facing inner shell (the marrow canal of a bone) is excluded,
// and overlapping components of one mesh count once. An exit with nothing
// open (a grazing hit at a silhouette edge) is ignored, and an interval still
// open after the last hit (a hole in the mesh, a grazing entry) is dropped,
// never extended to infinity.
//
// Meshes add: a bone inside a soft-tissue envelope is crossed by both, so
// give the bone mu_bone - mu_soft to model bone replacing tissue.

#include <Eigen/Core>
#include <cstdint>
#include <span>

#include "core/image/image.h"
#include "core/image/projection.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::image {

// Linear attenuation coefficients (1/mm) at an effective energy of ~60 keV,
// typical of the filtered beam of a radiography tube at 80-120 kV. Callers
// choose their own; these are the documented defaults of mmm.
//   soft tissue: water, mu/rho = 0.206 cm^2/g (NIST XCOM) -> 0.0206 /mm.
//   bone: cortical bone (ICRU-44, 1.92 g/cm^3) has ~0.060 /mm; a whole-bone
//         surface also encloses trabecular bone and marrow, so 0.05 /mm is
//         used as its mean.
constexpr double kSoftTissueMuPerMm = 0.02;
constexpr double kBoneMuPerMm = 0.05;

// One closed, outward-oriented surface (faces counter-clockwise seen from
// outside, the IndexedMesh convention) and the attenuation of what it encloses.
struct AttenuatingMesh {
  const mesh::AabbTree* tree = nullptr;  // not owned; must outlive the call
  double mu_per_mm = 0;                  // 1/mm; negative values subtract (air in tissue)
};

// Line integral sum_k mu_k * length_k along one ray (origin + t direction,
// t >= 0; any non-zero direction, lengths are in mm whatever its norm).
// Face orientation is trusted as given (see render_drr for the checks).
// Throws InvalidInputError for a null tree, a non-finite mu, or a non-finite
// or zero ray.
double line_integral(const Ray& ray, std::span<const AttenuatingMesh> meshes);

struct DrrOptions {
  // Worker threads, each taking whole rows (>= 1). 2 matches the build
  // machines; rows are handed out one at a time, so uneven rows balance.
  int threads = 2;
};

// width x height image of the line integral through each pixel centre
// (u = i + 0.5, v = j + 0.5) of `view`, from its source. Pixels whose ray
// meets no mesh are exactly 0. Throws InvalidInputError when the view fails
// validate_view, a tree is null, a mu is not finite, threads < 1, or a mesh
// encloses a negative volume (inside out: its faces need reversing).
// Cost: one bounding-box test per pixel and mesh, plus an all_hits query per
// pixel whose ray meets the box: the five VHF shank and foot bones (114K
// faces) take 0.5 s for 436 x 1090 pixels on 2 threads, so a full default
// view (1962 x 4795) of them about 10 s.
FloatImage render_drr(const RadiographView& view, std::span<const AttenuatingMesh> meshes,
                      const DrrOptions& options = {});

// Detector model turning line integrals L into 16-bit pixels, displayed as
// attenuation (bone bright, air dark) like a clinical radiograph:
//   N  = photons_per_pixel * exp(-L)               expected photon count
//   N' = N + sqrt(N) * z, z ~ N(0, 1)              quantum noise (Gaussian
//                                                  approximation of Poisson,
//                                                  good for N >~ 20), if on
//   A  = -ln(max(N', 1) / photons_per_pixel)       measured attenuation
//   I  = offset_counts + counts_per_attenuation * A + readout_noise * z'
//   pixel = I rounded and clamped to [0, 65535]
// Without noise A = L exactly. The normal deviates come from a
// std::mt19937_64 seeded with `seed` (Box-Muller on its raw 64-bit output, so
// the image is the same on every platform), one pixel after the other in
// row-major order.
struct RadiographOptions {
  // Unattenuated photons per pixel. 1e5 gives 0.3 % noise in air and ~3 %
  // behind L = 4.6 (about 15 cm of tissue and 3 cm of bone).
  double photons_per_pixel = 1e5;
  // Display gain (counts per unit of attenuation). With the offset below,
  // 6000 keeps L up to 10.7 (more than ln 1e5 = 11.5 would saturate) in range.
  double counts_per_attenuation = 6000.0;
  // Detector dark level added to every pixel (counts), so that noise in air
  // is not clipped at 0.
  double offset_counts = 1000.0;
  bool quantum_noise = true;
  // Standard deviation of additive electronic noise (counts); 0 = none.
  double readout_noise_counts = 0.0;
  std::uint64_t seed = 1;
};

// The 16-bit radiograph of an image of line integrals (see RadiographOptions).
// Throws InvalidInputError for a non-finite sample, photons_per_pixel <= 1,
// a non-finite or negative gain/offset/readout noise, or an image whose pixel
// count does not match its size.
GrayImage16 to_radiograph(const FloatImage& line_integrals, const RadiographOptions& options = {});

}  // namespace mmm::image
