// mmm overlay: the bones of an atlas outlined over a calibrated radiograph
// pair (core/image/outline_overlay.h), for the operator's check of a scaling.

#include <array>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "core/atlas/atlas_io.h"
#include "core/image/outline_overlay.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"

namespace mmm::app {
namespace {

struct OverlayArgs {
  std::string atlas;
  std::string radiographs;
  std::string out;
  std::string level = "lod1";
  int max_width = 2400;
};

std::string hex(image::Rgb8 colour) {
  std::array<char, 8> text{};
  std::snprintf(text.data(), text.size(), "#%02x%02x%02x", colour.r, colour.g, colour.b);
  return text.data();
}

void run_overlay(const OverlayArgs& args) {
  const auto started = std::chrono::steady_clock::now();
  const atlas::Atlas atlas = atlas::read_atlas(args.atlas);
  const image::RadiographPair pair = image::load_radiograph_pair(args.radiographs);
  std::vector<mesh::IndexedMesh> meshes;
  meshes.reserve(atlas.bones.size());
  for (const atlas::Bone& bone : atlas.bones) {
    meshes.push_back(atlas::load_mesh(args.atlas, bone.meshes, args.level));
  }
  const std::vector<image::Rgb8> colours =
      image::distinct_colours(static_cast<int>(atlas.bones.size()));
  std::vector<image::OutlineItem> items;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    items.push_back({atlas.bones[k].name, &meshes[k], colours[k]});
  }
  image::OverlayOptions options;
  options.max_width = args.max_width;
  const image::RgbImage8 picture = image::outline_overlay_pair(pair, items, options);
  image::write_png(picture, args.out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cout << args.out << ": " << picture.width << " x " << picture.height << " px, "
            << items.size() << " bones (" << args.level << ") in " << std::fixed
            << std::setprecision(2) << seconds << " s\n"
            << "legend (swatches top-left, top to bottom):\n";
  for (const image::OutlineItem& item : items) {
    std::cout << "  " << hex(item.colour) << "  " << item.name << '\n';
  }
}

}  // namespace

void register_overlay_commands(CLI::App& app) {
  auto args = std::make_shared<OverlayArgs>();
  auto* overlay = app.add_subcommand(
      "overlay",
      "Draw the projected outlines of an atlas's bones over a calibrated radiograph pair (PNG)");
  overlay->add_option("--atlas", args->atlas, "Atlas folder (e.g. a scaled or ground-truth atlas)")
      ->required();
  overlay
      ->add_option("--radiographs", args->radiographs,
                   "Calibration sidecar of the pair (views.json beside its images)")
      ->required();
  overlay->add_option("-o,--out", args->out, "PNG to write")->required();
  overlay->add_option("--level", args->level, "Mesh level of the bones (full, lod1, ...)")
      ->capture_default_str();
  overlay
      ->add_option("--max-width", args->max_width,
                   "Scale the side-by-side picture down to at most this width (pixels)")
      ->capture_default_str()
      ->check(CLI::Range(64, 100000));
  overlay->callback([args] { run_overlay(*args); });
}

}  // namespace mmm::app
