// Suite `image`: the operator's overlay picture (core/image/outline_overlay.h)
// on one full-size EOS-like view (make_biplanar_views defaults: 1962 x 4795
// pixels of 0.229 mm) with 10 bone-sized tori of 4000 faces each, the size of
// an atlas's lod1 bones. Run with `bench/run image`.
//
//   BM_OverlayWindowOnly    the radiograph windowed to grey (percentiles), no item
//   BM_OverlayTenBones      the same plus the 10 silhouettes: the operator's case
//   BM_OverlayTenBonesLines the 10 silhouettes on a fixed window (no histogram)
//
// Accuracy table first (image.accuracy.txt): how far a pinhole fitted (DLT)
// to an EOS-type slot scan of the whole leg (1700 mm tall, 0.38 mm pixels at
// the isocentre) is from it, over the volume a leg fills (200 mm deep and
// across, 1600 mm tall), per height band, in mm at the isocentre.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "bench/bench_main.h"
#include "core/image/outline_overlay.h"
#include "core/image/projection.h"
#include "core/image/view_fit.h"
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

// The pinhole-versus-slot table (see the file comment).
void write_accuracy_table() {
  mmm::image::BiplanarOptions options;
  options.model = mmm::image::ProjectionModel::kSlotScanning;
  options.isocentre_mm = {0, 0, 900};
  options.field_height_mm = 1700.0;
  options.detector_pixel_pitch_mm = 0.5;
  const auto views = mmm::image::make_biplanar_views(options);
  std::vector<Eigen::Vector3d> points;
  for (int i = -4; i <= 4; ++i) {
    for (int j = -4; j <= 4; ++j) {
      for (int k = -16; k <= 16; ++k) {
        points.emplace_back(options.isocentre_mm + Eigen::Vector3d(25 * i, 25 * j, 50 * k));
      }
    }
  }
  // Height bands from the centre of the scan (mm).
  const std::vector<std::pair<double, double>> bands = {
      {0, 200}, {200, 500}, {500, 700}, {700, 801}};
  std::ostringstream text;
  nlohmann::json rows = nlohmann::json::array();
  text << "pinhole fitted to a slot-scanning full-leg scan (1700 mm tall), error in mm at the "
          "isocentre, points 200 mm deep and across\n"
       << "view      | height from centre (mm) | mean  | max\n";
  for (const mmm::image::RadiographView& view : views) {
    std::vector<Eigen::Vector2d> pixels;
    pixels.reserve(points.size());
    for (const Eigen::Vector3d& X : points) pixels.push_back(mmm::image::project(view, X));
    const mmm::image::RadiographView pinhole = mmm::image::fit_pinhole_view(
        points, pixels, view.name, view.width, view.height, view.pixel_spacing_mm);
    for (const auto& [low, high] : bands) {
      double sum = 0;
      double worst = 0;
      int count = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        const double height = std::abs(points[i].z() - options.isocentre_mm.z());
        if (height < low || height >= high) continue;
        const double error =
            (mmm::image::project(pinhole, points[i]) - pixels[i]).norm() * view.pixel_spacing_mm;
        sum += error;
        worst = std::max(worst, error);
        ++count;
      }
      const std::string range = std::to_string(static_cast<int>(low)) + "-" +
                                std::to_string(static_cast<int>(std::min(high, 800.0)));
      text << std::left << std::setw(9) << view.name << " | " << std::setw(23) << range << " | "
           << std::fixed << std::setprecision(2) << std::setw(5) << sum / count << " | " << worst
           << "\n";
      rows.push_back({{"view", view.name},
                      {"height_from_mm", low},
                      {"height_to_mm", std::min(high, 800.0)},
                      {"mean_mm", sum / count},
                      {"max_mm", worst}});
    }
  }
  std::cout << text.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "image.accuracy.json")
      << nlohmann::json{{"pinhole_vs_slot", rows}}.dump(2) << "\n";
  std::ofstream(folder / "image.accuracy.txt") << text.str();
}

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_image", write_accuracy_table);
}
