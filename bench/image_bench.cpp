// Suite `image`: the operator's overlay picture (core/image/outline_overlay.h)
// on one full-size EOS-like view (make_biplanar_views defaults: 1962 x 4795
// pixels of 0.229 mm) with 10 bone-sized tori of 4000 faces each, the size of
// an atlas's lod1 bones. Run with `bench/run image`.
//
//   BM_OverlayWindowOnly    the radiograph windowed to grey (percentiles), no item
//   BM_OverlayTenBones      the same plus the 10 silhouettes: the operator's case
//   BM_OverlayTenBonesLines the 10 silhouettes on a fixed window (no histogram)

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "core/image/outline_overlay.h"
#include "core/image/projection.h"
#include "core/mesh/primitives.h"

namespace {

using mmm::image::GrayImage16;
using mmm::image::OutlineItem;
using mmm::image::OverlayOptions;
using mmm::image::RadiographView;

const RadiographView& view() {
  static const RadiographView frontal = mmm::image::make_biplanar_views()[0];
  return frontal;
}

// A ramp with a little structure, so that the histogram has many bins.
const GrayImage16& radiograph() {
  static const GrayImage16 image = [] {
    GrayImage16 r(view().width, view().height);
    for (int y = 0; y < r.height; ++y) {
      for (int x = 0; x < r.width; ++x) {
        r.at(x, y) = static_cast<std::uint16_t>((7 * x + 11 * y + (x * y) % 97) % 60000);
      }
    }
    return r;
  }();
  return image;
}

// 10 tori (major radius 40 mm, tube 15 mm; 50 x 40 quads = 4000 faces) from
// z = -450 to +450 mm, tilted so that their silhouettes have both the outer
// and the inner contour.
const std::vector<mmm::mesh::IndexedMesh>& bones() {
  static const std::vector<mmm::mesh::IndexedMesh> meshes = [] {
    std::vector<mmm::mesh::IndexedMesh> out;
    for (int k = 0; k < 10; ++k) {
      mmm::mesh::IndexedMesh torus = mmm::mesh::make_torus(40.0, 15.0, 50, 40);
      for (Eigen::Index v = 0; v < torus.V.rows(); ++v) {
        const double y = torus.V(v, 1);
        const double z = torus.V(v, 2);
        torus.V(v, 1) = 0.8 * y - 0.6 * z;
        torus.V(v, 2) = 0.6 * y + 0.8 * z - 450.0 + 100.0 * k;
      }
      out.push_back(std::move(torus));
    }
    return out;
  }();
  return meshes;
}

std::vector<OutlineItem> items() {
  std::vector<OutlineItem> list;
  const std::vector<mmm::image::Rgb8> colours = mmm::image::distinct_colours(10);
  for (std::size_t k = 0; k < bones().size(); ++k) {
    list.push_back({"bone", &bones()[k], colours[k]});
  }
  return list;
}

void BM_OverlayWindowOnly(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(mmm::image::outline_overlay(view(), radiograph(), {}));
  }
}
BENCHMARK(BM_OverlayWindowOnly)->Unit(benchmark::kMillisecond);

void BM_OverlayTenBones(benchmark::State& state) {
  const std::vector<OutlineItem> list = items();
  for (auto _ : state) {
    benchmark::DoNotOptimize(mmm::image::outline_overlay(view(), radiograph(), list));
  }
}
BENCHMARK(BM_OverlayTenBones)->Unit(benchmark::kMillisecond);

void BM_OverlayTenBonesLines(benchmark::State& state) {
  const std::vector<OutlineItem> list = items();
  OverlayOptions options;
  options.window_low = 0;
  options.window_high = 60000;
  for (auto _ : state) {
    benchmark::DoNotOptimize(mmm::image::outline_overlay(view(), radiograph(), list, options));
  }
}
BENCHMARK(BM_OverlayTenBonesLines)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
