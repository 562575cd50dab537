// mmm calibrate: a radiograph pair's calibration (views.json) from a
// calibration object of known geometry seen in both views
// (core/image/bead_calibration.h), with each bead's residual.

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

#include "app/commands/commands.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/bead_calibration.h"
#include "core/image/calibration_object.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/png.h"
#include "core/image/projection.h"

namespace mmm::app {
namespace {

namespace fs = std::filesystem;

struct CalibrateArgs {
  std::string object;
  std::string clicks;
  std::string frontal;
  std::string lateral;
  std::string model = "slot-scanning";
  double refine_radius_px = 0.0;
  std::string out;
};

std::string read_small(const fs::path& path, std::uintmax_t limit, const char* what) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) throw IoError(path, std::string("cannot read ") + what + ": " + error.message());
  if (size > limit) {
    throw IoError(path, "is " + std::to_string(size) + " bytes, too large for " + what);
  }
  return read_file_bytes(path, size);
}

// A radiograph as 16-bit samples, from a PNG or a DICOM file.
image::GrayImage16 read_radiograph(const fs::path& path) {
  const std::string bytes = read_small(path, image::kDicomMaxFileBytes, "a radiograph");
  if (image::looks_like_dicom(bytes)) return image::read_dicom_radiograph(bytes, path).image;
  image::PngContent content = image::decode_png(path, bytes);
  if (auto* wide = std::get_if<image::GrayImage16>(&content.image)) return std::move(*wide);
  if (const auto* narrow = std::get_if<image::GrayImage8>(&content.image)) {
    image::GrayImage16 out(narrow->width, narrow->height);
    for (std::size_t i = 0; i < out.pixels.size(); ++i) {
      out.pixels[i] = static_cast<std::uint16_t>(narrow->pixels[i] * 257U);
    }
    return out;
  }
  throw IoError(path, "holds colour; a radiograph must be grayscale");
}

void run_calibrate(const CalibrateArgs& args) {
  const image::CalibrationObject object = image::parse_calibration_object(
      read_small(args.object, std::uintmax_t{1} << 20U, "a calibration object"), args.object);
  const image::BeadClicks clicks = image::parse_bead_clicks(
      read_small(args.clicks, std::uintmax_t{1} << 20U, "bead clicks"), args.clicks, object);
  const image::ProjectionModel model = *image::projection_model_from_name(args.model);
  std::vector<image::RadiographFile> files;
  nlohmann::json report = {{"object", object.name}, {"model", args.model}};
  std::cout << "calibration object '" << object.name << "': " << object.beads.size()
            << " beads; model " << args.model << "\n";
  for (const auto& [name, path] :
       {std::pair<std::string, std::string>{"frontal", args.frontal}, {"lateral", args.lateral}}) {
    const auto seen = clicks.find(name);
    if (seen == clicks.end()) {
      throw IoError(args.clicks, "field 'views' has no view '" + name + "'");
    }
    const image::GrayImage16 radiograph = read_radiograph(path);
    std::vector<image::BeadPixel> beads;
    for (const auto& [bead, pixel] : seen->second) {
      const Eigen::Vector2d at =
          args.refine_radius_px > 0
              ? image::refine_bead_pixel(radiograph, pixel, args.refine_radius_px)
              : pixel;
      beads.push_back({bead, object.beads.at(bead), at});
    }
    const image::BeadCalibration calibration =
        image::calibrate_view_from_beads(name, radiograph.width, radiograph.height, model, beads);
    std::cout << std::fixed << std::setprecision(3) << "view '" << name << "': " << beads.size()
              << " beads, residual RMS " << calibration.rms_mm << " mm, max " << calibration.max_mm
              << " mm" << (calibration.converged ? "" : " (the solver did not report convergence)")
              << "\n";
    nlohmann::json rows = nlohmann::json::array();
    for (const image::BeadResidual& residual : calibration.residuals) {
      std::cout << "  " << std::left << std::setw(10) << residual.bead << std::right << std::setw(8)
                << residual.error_mm << " mm\n";
      rows.push_back({{"bead", residual.bead},
                      {"pixel", {residual.pixel.x(), residual.pixel.y()}},
                      {"projected", {residual.projected.x(), residual.projected.y()}},
                      {"error_mm", residual.error_mm}});
    }
    report["views"][name] = {{"rms_mm", calibration.rms_mm},
                             {"max_mm", calibration.max_mm},
                             {"converged", calibration.converged},
                             {"beads", rows}};
    files.push_back({calibration.view, fs::path(path).filename().string()});
  }
  fs::create_directories(args.out);
  image::write_view_sidecar(fs::path(args.out) / "views.json", files);
  write_file_atomically(fs::path(args.out) / "calibration_report.json", report.dump(2) + "\n");
  std::cout << "written: " << (fs::path(args.out) / "views.json").string()
            << " and calibration_report.json\n";
}

}  // namespace

void register_calibrate_commands(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* calibrate = app.add_subcommand(
      "calibrate",
      "Calibrate a radiograph pair from a calibration object of known geometry (beads) seen in "
      "both views: writes views.json and each bead's residual");
  calibrate->add_option("--object", args->object, "Calibration object (JSON: bead centres, mm)")
      ->required();
  calibrate->add_option("--clicks", args->clicks, "Bead pixels per view (JSON)")->required();
  calibrate->add_option("--frontal", args->frontal, "Frontal radiograph (PNG or DICOM)")
      ->required();
  calibrate->add_option("--lateral", args->lateral, "Lateral radiograph (PNG or DICOM)")
      ->required();
  calibrate->add_option("--model", args->model, "Projection model")
      ->check(CLI::IsMember({"pinhole", "slot-scanning"}));
  calibrate
      ->add_option("--refine-radius", args->refine_radius_px,
                   "Move each click to its bead's centre within this many pixels (0: as clicked)")
      ->check(CLI::Range(0.0, 100.0));
  calibrate->add_option("-o,--out", args->out, "Folder to write views.json into")->required();
  calibrate->callback([args] { run_calibrate(*args); });
}

}  // namespace mmm::app
