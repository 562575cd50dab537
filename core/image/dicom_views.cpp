#include "core/image/dicom_views.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "core/errors.h"

namespace mmm::image {
namespace {

constexpr const char* kHint =
    "; hint: give the pair's calibration sidecar (views.json) as the 'calibration' input, or "
    "calibrate the pair with a calibration object";

[[noreturn]] void fail(const NamedDicom& file, const std::string& problem) {
  throw IoError(file.source, problem + kHint);
}

// mmm's world direction of a DICOM patient direction letter.
std::optional<Eigen::Vector3d> direction_of(const std::string& code) {
  if (code == "R") return Eigen::Vector3d(1, 0, 0);
  if (code == "L") return Eigen::Vector3d(-1, 0, 0);
  if (code == "A") return Eigen::Vector3d(0, 1, 0);
  if (code == "P") return Eigen::Vector3d(0, -1, 0);
  if (code == "H") return Eigen::Vector3d(0, 0, 1);
  if (code == "F") return Eigen::Vector3d(0, 0, -1);
  return std::nullopt;
}

struct Axes {
  Eigen::Vector3d beam;
  std::array<std::string, 2> usual_orientation;
};

Axes axes_of(const NamedDicom& file, bool frontal) {
  const std::string position = file.radiograph->view_position.value_or("");
  if (frontal) {
    if (position == "AP") return {{0, -1, 0}, {"L", "F"}};
    if (position == "PA") return {{0, 1, 0}, {"R", "F"}};
    fail(file, "attribute View Position (0018,5101) is '" + position +
                   "', the frontal view must be AP or PA");
  }
  if (position == "LL" || position == "LATERAL") return {{-1, 0, 0}, {"A", "F"}};
  if (position == "RL") return {{1, 0, 0}, {"P", "F"}};
  fail(file, "attribute View Position (0018,5101) is '" + position +
                 "', the lateral view must be LL, RL or LATERAL");
}

RadiographView view_of(const NamedDicom& file, const std::string& name, bool frontal,
                       ProjectionModel model, bool& mirrored) {
  const DicomRadiograph& dicom = *file.radiograph;
  const Axes axes = axes_of(file, frontal);
  const std::array<std::string, 2> orientation =
      dicom.patient_orientation.value_or(axes.usual_orientation);
  std::array<Eigen::Vector3d, 2> image_axes;
  for (int k = 0; k < 2; ++k) {
    const std::optional<Eigen::Vector3d> axis =
        direction_of(orientation[static_cast<std::size_t>(k)]);
    if (!axis) {
      fail(file, "attribute Patient Orientation (0020,0020) is '" + orientation[0] + "\\" +
                     orientation[1] + "': only one of A, P, R, L, H, F per axis (no oblique view)");
    }
    image_axes[static_cast<std::size_t>(k)] = *axis;
  }
  Eigen::Vector3d u_axis = image_axes[0];
  const Eigen::Vector3d v_axis = image_axes[1];
  if (std::abs(u_axis.dot(v_axis)) > 0.5 || std::abs(u_axis.dot(axes.beam)) > 0.5 ||
      std::abs(v_axis.dot(axes.beam)) > 0.5) {
    fail(file, "attribute Patient Orientation (0020,0020) '" + orientation[0] + "\\" +
                   orientation[1] + "' does not fit View Position '" +
                   dicom.view_position.value_or("") + "' (an image axis along the beam)");
  }
  mirrored = u_axis.cross(v_axis).dot(axes.beam) < 0;
  if (mirrored) u_axis = -u_axis;

  if (!dicom.distance_source_to_detector_mm || !dicom.distance_source_to_patient_mm) {
    fail(file,
         std::string("attribute ") +
             (!dicom.distance_source_to_detector_mm ? "Distance Source to Detector (0018,1110)"
                                                    : "Distance Source to Patient (0018,1111)") +
             " is missing, so the magnification is unknown");
  }
  const double sid = *dicom.distance_source_to_detector_mm;
  const double sod = *dicom.distance_source_to_patient_mm;
  if (!(sod < sid)) {
    fail(file, "Distance Source to Patient (0018,1111) " + std::to_string(sod) +
                   " mm is not below Distance Source to Detector (0018,1110) " +
                   std::to_string(sid) + " mm");
  }
  const RadiographSpacing spacing = radiograph_spacing(dicom);
  std::optional<PixelSpacingMm> detector = spacing.detector_mm;
  if (!detector && spacing.patient_mm) {
    // Calibrated to the patient, with the distances for the magnification.
    detector =
        PixelSpacingMm{(*spacing.patient_mm)[0] * sid / sod, (*spacing.patient_mm)[1] * sid / sod};
  }
  if (!detector || spacing.meaning == SpacingMeaning::kUnknownPlane) {
    fail(file,
         "no pixel spacing whose plane is known (Imager Pixel Spacing (0018,1164), or a "
         "Pixel Spacing (0028,0030) calibrated to the patient): " +
             spacing.explanation);
  }
  ViewGeometry geometry;
  geometry.name = name;
  geometry.u_axis = u_axis;
  geometry.v_axis = v_axis;
  geometry.beam = axes.beam;
  geometry.source_to_isocentre_mm = sod;
  geometry.source_to_detector_mm = sid;
  geometry.column_pitch_mm = (*detector)[1];
  geometry.row_pitch_mm = (*detector)[0];
  geometry.width = dicom.columns;
  geometry.height = dicom.rows;
  geometry.model = model;
  RadiographView view = make_view(geometry);
  validate_view(view);
  return view;
}

}  // namespace

DicomPairGeometry views_from_dicom(const NamedDicom& frontal, const NamedDicom& lateral,
                                   ProjectionModel model) {
  if (frontal.radiograph == nullptr || lateral.radiograph == nullptr) {
    throw InvalidInputError("views_from_dicom: a radiograph is missing");
  }
  if (frontal.radiograph->sop_instance_uid_sha256 == lateral.radiograph->sop_instance_uid_sha256) {
    throw IoError(lateral.source, "is the same image as " + frontal.source.string() +
                                      " (the same SOP Instance UID); hint: give the lateral view");
  }
  DicomPairGeometry pair;
  pair.views[0] = view_of(frontal, "frontal", true, model, pair.mirrored[0]);
  pair.views[1] = view_of(lateral, "lateral", false, model, pair.mirrored[1]);
  if (model == ProjectionModel::kSlotScanning) {
    // One scan lights both views row by row: the same rows at the same step.
    const double step0 = 1.0 / pair.views[0].P.block<1, 3>(1, 0).norm();
    const double step1 = 1.0 / pair.views[1].P.block<1, 3>(1, 0).norm();
    if (pair.views[0].height != pair.views[1].height ||
        std::abs(step0 - step1) > 1e-3 * std::max(step0, step1)) {
      throw IoError(lateral.source,
                    "is inconsistent with " + frontal.source.string() +
                        " for one slot scan: " + std::to_string(pair.views[1].height) +
                        " rows of " + std::to_string(step1) + " mm against " +
                        std::to_string(pair.views[0].height) + " rows of " + std::to_string(step0) +
                        " mm (Rows, Imager Pixel Spacing, the distances); hint: check that both "
                        "files come from the same acquisition, or use model 'pinhole'");
    }
  }
  return pair;
}

GrayImage16 mirror_columns(const GrayImage16& image) {
  GrayImage16 out(image.width, image.height);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) out.at(x, y) = image.at(image.width - 1 - x, y);
  }
  return out;
}

}  // namespace mmm::image
