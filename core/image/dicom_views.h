#pragma once
// A calibrated frontal + lateral pair from the geometry in the radiographs'
// own DICOM attributes (dicom_radiograph.h), when they are complete: the
// calibration without a calibration object.
//
// Per view:
//   beam       from View Position (0018,5101): AP -> posterior (-y), PA ->
//              anterior (+y), LL (left side on the detector) -> toward the
//              left (-x), RL -> toward the right (+x); "LATERAL" is taken as
//              LL (mmm's lateral view).
//   axes       from Patient Orientation (0020,0020): the patient direction
//              of increasing column (u) and of increasing row (v), A/P/R/L/
//              H/F in mmm's frame (+x right, +y anterior, +z superior); when
//              absent, the usual display for the view position (AP: L, F;
//              PA: R, F; LL: A, F; RL: P, F). An image whose axes show it
//              from the detector side (u x v = -beam) is mirrored into the
//              view from the source, as mmm's image code expects.
//   distances  Distance Source to Detector (0018,1110) and Distance Source to
//              Patient (0018,1111), taken as the source-to-isocentre
//              distance; both are required.
//   spacing    the detector plane's spacing (radiograph_spacing): Imager Pixel
//              Spacing, or a calibrated Pixel Spacing times the
//              magnification. A Pixel Spacing whose plane cannot be told is
//              refused (no calibration is better than a wrong one).
//   centre     the isocentre projects to the image centre (the central ray
//              hits the detector's centre), and both views share it: the
//              world origin. The two views are vertically aligned (the same
//              scan or the same table height).
//   model      pinhole (a conventional radiograph) or slot-scanning (EOS-
//              type: the row spacing at the patient plane is the scan step,
//              the vertical is not magnified).

#include <array>
#include <filesystem>

#include "core/image/dicom_radiograph.h"
#include "core/image/projection.h"

namespace mmm::image {

// One radiograph with the file it came from (for messages).
struct NamedDicom {
  const DicomRadiograph* radiograph = nullptr;
  std::filesystem::path source;
};

// The views "frontal" and "lateral" (see the file comment). Throws IoError
// naming the file and the attribute (with a hint: give a calibration sidecar
// or calibrate with beads) when an attribute needed is missing or
// inconsistent: no SID or SOD, SOD >= SID, no usable spacing, a view position
// that is not frontal (AP/PA) for the first or lateral (LL/RL/LATERAL) for
// the second, axes that are not perpendicular to the beam and each other.
// The same image twice (one SOP Instance UID) and, for a slot scan, views
// whose rows differ in number or step (one scan lights both) are refused.
// `mirrored[k]` says whether view k's image must be flipped left-right to be
// seen from the source (mirror_columns does it).
struct DicomPairGeometry {
  std::array<RadiographView, 2> views;
  std::array<bool, 2> mirrored = {false, false};
};
DicomPairGeometry views_from_dicom(const NamedDicom& frontal, const NamedDicom& lateral,
                                   ProjectionModel model);

// The image flipped left-right.
GrayImage16 mirror_columns(const GrayImage16& image);

}  // namespace mmm::image
