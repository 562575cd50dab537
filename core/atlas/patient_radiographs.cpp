#include "core/atlas/patient_radiographs.h"

#include <algorithm>
#include <memory>
#include <vector>

#include "core/atlas/limb_envelope.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/dicom_write.h"
#include "core/image/mesh_render.h"
#include "core/image/png.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"

namespace mmm::atlas {
namespace {

// 8-bit picture of a 16-bit radiograph: the 0.5th-99.5th percentile window.
image::GrayImage8 preview(const image::GrayImage16& radiograph) {
  std::vector<std::uint16_t> sorted = radiograph.pixels;
  std::ranges::sort(sorted);
  const double low = sorted[sorted.size() / 200];
  const double high = std::max(low + 1.0, static_cast<double>(sorted[sorted.size() * 199 / 200]));
  image::GrayImage8 picture(radiograph.width, radiograph.height);
  for (std::size_t i = 0; i < radiograph.pixels.size(); ++i) {
    const double t = (radiograph.pixels[i] - low) / (high - low);
    picture.pixels[i] = static_cast<std::uint8_t>(std::lround(std::clamp(t, 0.0, 1.0) * 255.0));
  }
  return picture;
}

// A 2x2 box-filtered copy as RGB, for the side-by-side picture of the pair.
image::RgbImage8 half_size_rgb(const image::GrayImage8& picture) {
  image::RgbImage8 half(picture.width / 2, picture.height / 2);
  for (int y = 0; y < half.height; ++y) {
    for (int x = 0; x < half.width; ++x) {
      const int sum = picture.at(2 * x, 2 * y) + picture.at(2 * x + 1, 2 * y) +
                      picture.at(2 * x, 2 * y + 1) + picture.at(2 * x + 1, 2 * y + 1);
      const auto grey = static_cast<std::uint8_t>((sum + 2) / 4);
      for (int c = 0; c < 3; ++c) half.at(x, y, c) = grey;
    }
  }
  return half;
}

// <view>.dcm beside the PNG: the same samples, the system's geometry, and an
// invented identity (a study given it must drop that).
void write_dicom(const image::GrayImage16& picture, const image::RadiographView& view,
                 std::size_t k, const PatientRadiographOptions& options,
                 const std::filesystem::path& dir) {
  image::DicomExport dicom;
  const bool frontal = view.name == "frontal";
  dicom.view_position = frontal ? "AP" : "LL";
  dicom.patient_orientation =
      frontal ? std::array<std::string, 2>{"L", "F"} : std::array<std::string, 2>{"A", "F"};
  dicom.row_pitch_mm = options.detector_pixel_pitch_mm;
  dicom.column_pitch_mm = options.detector_pixel_pitch_mm;
  dicom.source_to_detector_mm = options.source_to_detector_mm;
  dicom.source_to_patient_mm = options.source_to_isocentre_mm;
  std::vector<std::uint16_t> sorted = picture.pixels;
  std::ranges::sort(sorted);
  const double low = sorted[sorted.size() / 200];
  const double high = std::max(low + 1.0, static_cast<double>(sorted[sorted.size() * 199 / 200]));
  dicom.window_centre = 0.5 * (low + high);
  dicom.window_width = high - low;
  const std::string seed = std::to_string(options.seed);
  dicom.patient_name = "SYNTHETIC^PATIENT^" + seed;
  dicom.patient_id = "SYN-" + seed;
  dicom.patient_birth_date = "19700101";
  dicom.study_date = "20260101";
  // A UUID-derived OID (2.25.<integer>, PS3.5 B.2) made from the seed.
  dicom.sop_instance_uid = "2.25." + std::to_string(options.seed * 10 + k + 1);
  write_file_atomically(dir / (view.name + ".dcm"), image::dicom_radiograph_bytes(picture, dicom));
}

}  // namespace

std::array<image::RadiographView, 2> write_patient_radiographs(
    const std::map<std::string, mesh::IndexedMesh>& bones,
    const std::map<std::string, mesh::IndexedMesh>& soft_tissue, const std::filesystem::path& dir,
    const PatientRadiographOptions& options) {
  if (!(options.detector_pixel_pitch_mm > 0) || !(options.field_margin_mm >= 0) ||
      !(options.mu_bone_per_mm >= 0) || !(options.mu_soft_per_mm >= 0)) {
    throw InvalidInputError(
        "patient radiographs: pixel pitch must be > 0, margin and attenuations >= 0");
  }
  if (bones.empty()) throw InvalidInputError("patient radiographs: no bones to render");
  // Views centred on the bones, the field covering them with a margin.
  Eigen::AlignedBox3d box;
  for (const auto& [name, surface] : bones) box.extend(mesh::bounding_box(surface));
  image::BiplanarOptions geometry;
  geometry.isocentre_mm = box.center();
  geometry.source_to_isocentre_mm = options.source_to_isocentre_mm;
  geometry.source_to_detector_mm = options.source_to_detector_mm;
  geometry.detector_pixel_pitch_mm = options.detector_pixel_pitch_mm;
  geometry.model = options.model;
  const Eigen::Vector3d size = box.sizes();
  geometry.field_width_mm = std::max(size.x(), size.y()) + 2 * options.field_margin_mm;
  geometry.field_height_mm = size.z() + 2 * options.field_margin_mm;
  std::array<image::RadiographView, 2> views = image::make_biplanar_views(geometry);

  std::vector<std::unique_ptr<mesh::AabbTree>> trees;
  std::vector<image::AttenuatingMesh> materials;
  const bool envelope = options.soft_tissue_envelope;
  for (const auto& [name, surface] : bones) {
    trees.push_back(std::make_unique<mesh::AabbTree>(surface));
    materials.push_back({trees.back().get(), envelope
                                                 ? options.mu_bone_per_mm - options.mu_soft_per_mm
                                                 : options.mu_bone_per_mm});
  }
  for (const auto& [name, surface] : soft_tissue) {
    trees.push_back(std::make_unique<mesh::AabbTree>(surface));
    materials.push_back(
        {trees.back().get(), envelope ? options.muscle_contrast_per_mm : options.mu_soft_per_mm});
  }
  if (envelope) {
    std::vector<const mesh::IndexedMesh*> inside;
    inside.reserve(bones.size() + soft_tissue.size());
    for (const auto& [name, surface] : bones) inside.push_back(&surface);
    for (const auto& [name, surface] : soft_tissue) inside.push_back(&surface);
    LimbEnvelopeOptions shape;
    shape.fat_mm = options.envelope_fat_mm;
    trees.push_back(std::make_unique<mesh::AabbTree>(limb_envelope(inside, shape)));
    materials.push_back({trees.back().get(), options.mu_soft_per_mm});
  }
  std::filesystem::create_directories(dir);
  std::vector<image::RadiographFile> files;
  std::vector<image::RgbImage8> halves;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const image::FloatImage integrals =
        image::render_drr(views[k], materials, image::DrrOptions{options.threads});
    image::RadiographOptions radiograph = options.radiograph;
    radiograph.seed = options.radiograph.seed * 1000003U + options.seed * 2U + k;
    const image::GrayImage16 picture = image::to_radiograph(integrals, radiograph);
    const std::string file = views[k].name + ".png";
    image::write_png(picture, dir / file);
    if (options.write_dicom) write_dicom(picture, views[k], k, options, dir);
    const image::GrayImage8 windowed = preview(picture);
    image::write_png(windowed, dir / (views[k].name + "_preview.png"));
    halves.push_back(half_size_rgb(windowed));
    files.push_back({views[k], file});
  }
  image::write_view_sidecar(dir / "views.json", files);
  image::write_png(image::side_by_side(halves, {10, {0, 0, 0}}), dir / "pair_preview.png");
  return views;
}

}  // namespace mmm::atlas
