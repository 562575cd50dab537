#pragma once
// Calibrated X-ray views of a biplanar (EOS-like) radiography system: the
// pinhole model of each view, projection of 3-D points, linear triangulation
// of a point seen in two or more views, and the JSON sidecar that stores a
// calibrated pair beside its images.
//
// Two projection models, both held in one 3 x 4 matrix P (h = P [X 1]^T):
//   pinhole        [u v 1]^T ~ h: u = h0 / h2, v = h1 / h2 (Hartley &
//                  Zisserman, "Multiple View Geometry", 2nd ed., ch. 6); the
//                  X-ray focal spot is the centre of projection
//                  (P [source 1]^T = 0). A conventional radiograph.
//   slot scanning  u = h0 / h2, v = h1: conic across the image, parallel along
//                  it. The source and a line detector move together along the
//                  scan (vertically, on an EOS-type system), so a point is
//                  seen from the focal spot at its own height: its row v is
//                  its height over the scan step, whatever its depth, while
//                  its column is a pinhole's within that horizontal plane.
//                  P is not defined up to scale here (row 1 gives v itself).
//                  The focal spot at row v is source_mm + v t, where
//                  source_mm is the one at row 0 (still -M^-1 p4 for P =
//                  [M | p4]) and t = M^-1 (0, 1, 0)^T is the scan's travel per
//                  row.
// A pinhole matrix fitted to a slot-scanning view is exact only at one height
// and one depth: over a full-leg scan it is off by millimetres at the ends of
// the image (see tests/core/image/slot_scanning_test.cpp and the benchmarks).
//
// Triangulation (linear, "DLT"): each view gives two equations linear in X,
//   (u p3 - p1) . [X 1] = 0,   (v p3 - p2) . [X 1] = 0   (p_i = row i of P),
// the second being (v e4 - p2) . [X 1] = 0 for a slot-scanning view,
// solved in least squares for the 3 coordinates. The residual of such a row
// is depth * (pixel error); a second solve divides each view's rows by the
// depth found by the first and multiplies them by the view's pixel spacing,
// so that every equation measures an error in mm at the isocentre and views
// of different resolution weigh what they are worth (the iterative linear
// method of Hartley & Sturm 1997, "Triangulation", one step).
//
// Conventions (all of mmm's image code):
//   world   the patient frame in mm: +x toward the subject's right, +y
//           anterior, +z superior (right-handed; "RAS").
//   pixels  (u, v): u to the right along a row, v down along a column. Pixel
//           (i, j) (column i, row j) covers [i, i+1) x [j, j+1), so its centre
//           is (i + 0.5, j + 0.5) and the image spans [0, width] x [0, height].
//   frontal beam anterior -> posterior (AP: source in front of the subject,
//           detector behind); the image is seen from the source, as
//           radiologists display a frontal film: the subject's right on the
//           image left, u increasing toward the subject's left (-x), v down
//           (-z).
//   lateral beam right -> left (-x: source on the subject's right, detector on
//           the left); seen from the source: anterior on the image right, u
//           increasing toward anterior (+y), v down (-z).

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::image {

// How a view maps the world to its pixels (see the file comment).
enum class ProjectionModel { kPinhole, kSlotScanning };

// "pinhole" or "slot-scanning" (as in the sidecar), and back (std::nullopt
// for another text).
std::string projection_model_name(ProjectionModel model);
std::optional<ProjectionModel> projection_model_from_name(std::string_view name);

struct RadiographView {
  std::string name;  // "frontal", "lateral", ...
  ProjectionModel model = ProjectionModel::kPinhole;
  // Maps homogeneous world points (mm) to pixels (u, v) as `model` says;
  // pixel centres at integer + 0.5 (see above).
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 0;   // pixels (u in [0, width])
  int height = 0;  // pixels (v in [0, height])
  // Size of a pixel projected onto the plane through the isocentre parallel
  // to the detector (mm): the detector pitch divided by the magnification
  // source_to_detector / source_to_isocentre. An object at the isocentre
  // measures this many mm per pixel.
  double pixel_spacing_mm = 0;
  // X-ray focal spot (mm, world): the centre of projection of P (for a
  // slot-scanning view, the focal spot when it lights row v = 0).
  Eigen::Vector3d source_mm = Eigen::Vector3d::Zero();
};

// A ray in world coordinates: origin + t * direction, t >= 0.
struct Ray {
  Eigen::Vector3d origin;     // mm
  Eigen::Vector3d direction;  // unit length
};

struct BiplanarOptions {
  // World point on both central rays (mm): the centre of the field, where the
  // two beams cross. Default: the world origin.
  Eigen::Vector3d isocentre_mm = Eigen::Vector3d::Zero();
  // Focal spot to isocentre (mm). 1300 mm is a round figure of the order of
  // EOS-type systems (not a vendor specification).
  double source_to_isocentre_mm = 1300.0;
  // Focal spot to detector (mm), > source_to_isocentre_mm; with the default
  // 1700 mm the magnification at the isocentre is 1700 / 1300 = 1.31.
  double source_to_detector_mm = 1700.0;
  // Detector pixel pitch (mm), in the plane of the detector. 0.3 mm (the
  // views' spacing at the isocentre is then 0.3 / 1.31 = 0.229 mm).
  double detector_pixel_pitch_mm = 0.3;
  // Field of view at the isocentre (mm): horizontal (x for the frontal view,
  // y for the lateral one) and vertical (z). 450 x 1100 mm covers the pelvis
  // to the feet of an adult. The image size is this over the pixel spacing at
  // the isocentre, rounded to the nearest pixel.
  double field_width_mm = 450.0;
  double field_height_mm = 1100.0;
  // Pinhole views (a conventional pair) or slot-scanning ones (an EOS-type
  // scan: square pixels of the same spacing at the isocentre, every row seen
  // from the focal spot at its own height).
  ProjectionModel model = ProjectionModel::kPinhole;
};

// One view of a radiography system in the world frame: its isocentre, its
// image axes (u right, v down) and beam (unit, u x v = beam: the image seen
// from the source), distances and detector pitch per axis.
struct ViewGeometry {
  std::string name;
  Eigen::Vector3d isocentre_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v_axis = -Eigen::Vector3d::UnitZ();
  Eigen::Vector3d beam = -Eigen::Vector3d::UnitY();
  double source_to_isocentre_mm = 1300.0;
  double source_to_detector_mm = 1700.0;
  double column_pitch_mm = 0.3;  // detector plane
  double row_pitch_mm = 0.3;
  int width = 1;
  int height = 1;
  ProjectionModel model = ProjectionModel::kPinhole;
};

// The view of `geometry`: the isocentre at the image centre; for a
// slot-scanning view the rows' spacing at the isocentre is the scan step.
// The caller checks the values (make_biplanar_views, views_from_dicom).
RadiographView make_view(const ViewGeometry& geometry);

// The calibrated pair {frontal, lateral} described by `options` (names
// "frontal" and "lateral"). The isocentre projects to the image centre
// (width / 2, height / 2) of both. Throws InvalidInputError naming the field
// for a non-finite or non-positive value, source_to_detector_mm <=
// source_to_isocentre_mm, or an image larger than 100000 pixels a side.
std::array<RadiographView, 2> make_biplanar_views(const BiplanarOptions& options = {});

// Throws InvalidInputError naming the view and field unless: P is finite and
// its left 3 x 3 block invertible, width and height are >= 1, the spacing is
// finite and > 0, source_mm is finite and is the centre of projection of P
// (-M^-1 p4 for P = [M | p4]) within 1e-6 * (1 mm + its distance from the
// origin): rounding, not a second focal spot.
void validate_view(const RadiographView& view);

// The focal spot from which X is seen: source_mm for a pinhole view; for a
// slot-scanning view the spot at X's row (see the file comment).
Eigen::Vector3d source_for(const RadiographView& view, const Eigen::Vector3d& X);

// d(u, v) / dX at the world point X (pixels per mm), for either model.
Eigen::Matrix<double, 2, 3> projection_jacobian(const RadiographView& view,
                                                const Eigen::Vector3d& X);

// Depth of X in front of the source along the beam, in mm (> 0 in front):
// the distance, along the view's axis, from the plane through the source
// parallel to the detector.
double depth_mm(const RadiographView& view, const Eigen::Vector3d& X);

// Pixel (u, v) of the world point X (mm). Throws InvalidInputError when X is
// not finite or lies on or behind the plane through the source parallel to
// the detector (it casts no shadow on the detector).
Eigen::Vector2d project(const RadiographView& view, const Eigen::Vector3d& X);

// The ray from the source (for a slot-scanning view: from the focal spot at
// row v) through pixel position (u, v), pointing toward the detector. Throws InvalidInputError for
// a non-finite pixel or a view whose P is singular.
Ray backproject(const RadiographView& view, const Eigen::Vector2d& pixel);

// Least-squares linear triangulation of one point seen at pixels[i] in
// views[i] (see the file comment). Returns X (mm). Throws InvalidInputError
// when fewer than 2 views are given, the counts differ, a pixel is not finite,
// a view fails validate_view, or the geometry is degenerate: every pair of
// rays within 1e-6 rad of parallel (e.g. the same view twice), where a pixel
// of error would move the point by a million pixel sizes along the rays, or
// all views sharing one source (the rays meet only at the focal spot).
Eigen::Vector3d triangulate_linear(std::span<const RadiographView> views,
                                   std::span<const Eigen::Vector2d> pixels);

// Distance between the projection of X and `pixel`, in pixels times the
// view's pixel_spacing_mm: mm at the isocentre plane.
double reprojection_error_mm(const RadiographView& view, const Eigen::Vector3d& X,
                             const Eigen::Vector2d& pixel);

// One view as stored in a sidecar, with the file name of its radiograph
// (relative to the sidecar's folder, e.g. "frontal.png").
struct RadiographFile {
  RadiographView view;
  std::string image;
};

// Writes the views as JSON:
//   {"format": "mmm-radiograph-views", "version": 1,
//    "views": [{"name": "frontal", "image": "frontal.png", "width": 1962,
//               ["model": "slot-scanning",] (absent: "pinhole")
//               "height": 4795, "pixel_spacing_mm": 0.229,
//               "source_mm": [x, y, z], "P": [[4 numbers], [..], [..]]}, ...]}
// Numbers are written as the shortest text that reads back to the same
// double, so a round trip is exact. Throws InvalidInputError when no view is given, a view fails
// validate_view, names are empty or repeated, or an image name is empty;
// IoError naming the path when the file cannot be written.
void write_view_sidecar(const std::filesystem::path& path, std::span<const RadiographFile> views);

// Reads a sidecar written by write_view_sidecar. Every field is checked; an
// error is an IoError naming the path and the field, e.g.
// "views[1] ('lateral'): field 'P' must be 3 rows of 4 finite numbers, row 2
// has 3 entries", "views[0] ('frontal'): field 'pixel_spacing_mm' is missing".
// Unknown extra fields are ignored (room for later versions); a version other
// than 1 is rejected.
std::vector<RadiographFile> read_view_sidecar(const std::filesystem::path& path);

// The text write_view_sidecar writes, and the reading of such a text already
// in memory (errors name `path`, where the text came from).
std::string view_sidecar_text(std::span<const RadiographFile> views);
std::vector<RadiographFile> parse_view_sidecar(const std::string& text,
                                               const std::filesystem::path& path);

}  // namespace mmm::image
