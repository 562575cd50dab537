#include "core/image/projection.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/file_bytes.h"

namespace mmm::image {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Matrix34d = Eigen::Matrix<double, 3, 4>;

namespace {

// A view sidecar is a few kilobytes; anything past this is not one.
constexpr std::uintmax_t kMaxSidecarBytes = std::uintmax_t{1} << 20U;

constexpr const char* kSidecarFormat = "mmm-radiograph-views";
constexpr int kSidecarVersion = 1;
// Largest image side make_biplanar_views accepts (pixels): 30 m at 0.3 mm.
constexpr double kMaxPixelsPerSide = 100000.0;
// Rays closer to parallel than this (rad) make a triangulation degenerate:
// a pixel error then moves the point by 1e6 pixel sizes along the rays.
constexpr double kMinRayAngle = 1e-6;

std::string view_label(const RadiographView& view) { return "view '" + view.name + "'"; }

std::string format_vector(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

// +1 or -1: the sign that makes P's third row measure depth in front of the
// source positive (Hartley & Zisserman, eq. 6.15).
double depth_sign(const Matrix34d& P) { return P.leftCols<3>().determinant() > 0 ? 1.0 : -1.0; }

// A slot-scanning view's focal spot moves by this per image row:
// M^-1 (0, 1, 0)^T, which changes v by one and u by nothing.
Eigen::Vector3d scan_travel(const RadiographView& view) {
  return view.P.leftCols<3>().partialPivLu().solve(Eigen::Vector3d::UnitY());
}

void check_positive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0) {
    throw InvalidInputError(std::string("BiplanarOptions.") + field +
                            " must be a finite number > 0, got " + std::to_string(value));
  }
}

// --- sidecar reading ---

class SidecarReader {
 public:
  explicit SidecarReader(fs::path path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw IoError(path_, where.empty() ? problem : where + ": " + problem);
  }

  const Json& field(const Json& object, const std::string& where, const char* name) const {
    const auto it = object.find(name);
    if (it == object.end()) fail(where, std::string("field '") + name + "' is missing");
    return *it;
  }

  static std::string describe(const Json& value) {
    std::string text = value.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return std::string(value.type_name()) + " " + text;
  }

  double finite_number(const Json& value, const std::string& where,
                       const std::string& field_name) const {
    if (!value.is_number()) {
      fail(where, "field '" + field_name + "' must be a finite number, got " + describe(value));
    }
    const double number = value.get<double>();
    if (!std::isfinite(number)) {
      fail(where, "field '" + field_name + "' must be a finite number, got " + describe(value));
    }
    return number;
  }

  int positive_int(const Json& object, const std::string& where, const char* name) const {
    const Json& value = field(object, where, name);
    if (!value.is_number_integer() || value.get<std::int64_t>() < 1 ||
        value.get<std::int64_t>() > INT32_MAX) {
      fail(where,
           std::string("field '") + name + "' must be a whole number >= 1, got " + describe(value));
    }
    return static_cast<int>(value.get<std::int64_t>());
  }

  std::string nonempty_string(const Json& object, const std::string& where,
                              const char* name) const {
    const Json& value = field(object, where, name);
    if (!value.is_string() || value.get<std::string>().empty()) {
      fail(where,
           std::string("field '") + name + "' must be a non-empty string, got " + describe(value));
    }
    return value.get<std::string>();
  }

  // A rows x cols nested array of finite numbers (cols == 0: a flat array of
  // `rows` numbers).
  Eigen::MatrixXd matrix(const Json& object, const std::string& where, const char* name, int rows,
                         int cols) const {
    const Json& value = field(object, where, name);
    const std::string shape =
        cols == 0 ? "an array of " + std::to_string(rows) + " finite numbers"
                  : std::to_string(rows) + " rows of " + std::to_string(cols) + " finite numbers";
    const auto wrong = [&](const std::string& detail) {
      fail(where, std::string("field '") + name + "' must be " + shape + ", " + detail);
    };
    if (!value.is_array()) wrong("got " + describe(value));
    if (static_cast<int>(value.size()) != rows) {
      wrong("got " + std::to_string(value.size()) + (cols == 0 ? " entries" : " rows"));
    }
    Eigen::MatrixXd out(rows, cols == 0 ? 1 : cols);
    for (int r = 0; r < rows; ++r) {
      const Json& row = value[static_cast<std::size_t>(r)];
      const std::string row_name = std::string(name) + "[" + std::to_string(r) + "]";
      if (cols == 0) {
        out(r, 0) = finite_number(row, where, row_name);
        continue;
      }
      if (!row.is_array()) wrong("row " + std::to_string(r) + " is " + describe(row));
      if (static_cast<int>(row.size()) != cols) {
        wrong("row " + std::to_string(r) + " has " + std::to_string(row.size()) + " entries");
      }
      for (int c = 0; c < cols; ++c) {
        out(r, c) = finite_number(row[static_cast<std::size_t>(c)], where,
                                  row_name + "[" + std::to_string(c) + "]");
      }
    }
    return out;
  }

  RadiographFile view(const Json& entry, std::size_t index) const {
    std::string where = "views[" + std::to_string(index) + "]";
    if (!entry.is_object()) fail(where, "must be an object, got " + describe(entry));
    RadiographFile file;
    file.view.name = nonempty_string(entry, where, "name");
    where += " ('" + file.view.name + "')";
    file.image = nonempty_string(entry, where, "image");
    file.view.width = positive_int(entry, where, "width");
    file.view.height = positive_int(entry, where, "height");
    const double spacing =
        finite_number(field(entry, where, "pixel_spacing_mm"), where, "pixel_spacing_mm");
    if (spacing <= 0)
      fail(where, "field 'pixel_spacing_mm' must be > 0, got " + std::to_string(spacing));
    file.view.pixel_spacing_mm = spacing;
    const auto model = entry.find("model");
    if (model != entry.end()) {
      const std::optional<ProjectionModel> known =
          model->is_string() ? projection_model_from_name(model->get<std::string>()) : std::nullopt;
      if (!known) {
        fail(where,
             R"(field 'model' must be "pinhole" or "slot-scanning", got )" + describe(*model));
      }
      file.view.model = *known;
    }
    file.view.source_mm = matrix(entry, where, "source_mm", 3, 0).col(0);
    file.view.P = matrix(entry, where, "P", 3, 4);
    try {
      validate_view(file.view);
    } catch (const InvalidInputError& error) {
      fail(where, error.what());
    }
    return file;
  }

  // nlohmann's parse error, plus the field holding a NaN or Infinity when that
  // is the cause (JSON has no such numbers; some writers emit them anyway).
  [[noreturn]] void parse_failure(const std::string& text, const Json::parse_error& error) const {
    // error.byte is 1-based and points at the last character read: the start
    // of the offending literal, or a character inside it.
    const std::size_t at = std::min<std::size_t>(error.byte, text.size());
    std::size_t begin = at == 0 ? 0 : at - 1;
    const auto in_literal = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '+' || c == '.';
    };
    while (begin > 0 && in_literal(text[begin - 1])) --begin;
    std::size_t end = begin;
    while (end < text.size() && in_literal(text[end])) ++end;
    std::string literal = text.substr(begin, end - begin);
    std::transform(literal.begin(), literal.end(), literal.begin(), [](char c) {
      return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    });
    if (!literal.empty() && (literal[0] == '-' || literal[0] == '+')) literal.erase(0, 1);
    if (literal == "nan" || literal == "inf" || literal == "infinity") {
      // The key of the innermost `"key" :` before the error.
      std::string key = "?";
      const std::size_t colon = text.rfind(':', at);
      if (colon != std::string::npos && colon > 0) {
        const std::size_t close = text.find_last_not_of(" \t\r\n", colon - 1);
        if (close != std::string::npos && close > 0 && text[close] == '"') {
          const std::size_t open = text.rfind('"', close - 1);
          if (open != std::string::npos) key = text.substr(open + 1, close - open - 1);
        }
      }
      const auto line =
          1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
      fail("", "field '" + key + "' (line " + std::to_string(line) +
                   ") holds NaN or Infinity, which JSON cannot represent; every value must be a "
                   "finite number");
    }
    fail("", std::string("not valid JSON: ") + error.what());
  }

  std::vector<RadiographFile> read() const {
    return parse(detail::read_file_bytes(path_, "a view sidecar (JSON)", kMaxSidecarBytes));
  }

  std::vector<RadiographFile> parse(const std::string& text) const {
    Json root;
    try {
      root = parse_json(text);
    } catch (const Json::parse_error& error) {
      parse_failure(text, error);
    }
    if (!root.is_object()) fail("", "must hold a JSON object, got " + describe(root));
    const Json& format = field(root, "", "format");
    if (!format.is_string() || format.get<std::string>() != kSidecarFormat) {
      fail("", std::string("field 'format' must be \"") + kSidecarFormat + "\", got " +
                   describe(format));
    }
    const Json& version = field(root, "", "version");
    if (!version.is_number_integer() || version.get<std::int64_t>() != kSidecarVersion) {
      fail("", "field 'version' must be " + std::to_string(kSidecarVersion) + ", got " +
                   describe(version) + " (written by a newer mmm?)");
    }
    const Json& views = field(root, "", "views");
    if (!views.is_array() || views.empty()) {
      fail("", "field 'views' must be a non-empty array, got " + describe(views));
    }
    std::vector<RadiographFile> files;
    std::set<std::string> names;
    for (std::size_t i = 0; i < views.size(); ++i) {
      files.push_back(view(views[i], i));
      if (!names.insert(files.back().view.name).second) {
        fail("views[" + std::to_string(i) + "]",
             "field 'name': view name '" + files.back().view.name + "' is used twice");
      }
    }
    return files;
  }

 private:
  fs::path path_;
};

}  // namespace

RadiographView make_view(const ViewGeometry& g) {
  const double sid = g.source_to_isocentre_mm;
  const double sdd = g.source_to_detector_mm;
  RadiographView view;
  view.name = g.name;
  view.model = g.model;
  view.width = g.width;
  view.height = g.height;
  view.pixel_spacing_mm = g.column_pitch_mm * sid / sdd;
  const Eigen::Vector3d source = g.isocentre_mm - sid * g.beam;
  Eigen::Matrix3d R;
  R.row(0) = g.u_axis.transpose();
  R.row(1) = g.v_axis.transpose();
  R.row(2) = g.beam.transpose();
  // Focal lengths in pixels: the detector distance over the detector pitch
  // (equivalently the isocentre distance over the spacing at the isocentre).
  Eigen::Matrix3d K;
  K << sdd / g.column_pitch_mm, 0, 0.5 * g.width, 0, sdd / g.row_pitch_mm, 0.5 * g.height, 0, 0, 1;
  view.P.leftCols<3>() = K * R;
  view.P.col(3) = -K * R * source;
  if (g.model == ProjectionModel::kSlotScanning) {
    // Row v is the height over the scan step (the rows' spacing at the
    // isocentre), the isocentre on the middle row.
    const double step = g.row_pitch_mm * sid / sdd;
    view.P.block<1, 3>(1, 0) = g.v_axis.transpose() / step;
    view.P(1, 3) = 0.5 * g.height - g.v_axis.dot(g.isocentre_mm) / step;
  }
  view.source_mm = -view.P.leftCols<3>().partialPivLu().solve(view.P.col(3));
  return view;
}

std::array<RadiographView, 2> make_biplanar_views(const BiplanarOptions& options) {
  if (!options.isocentre_mm.allFinite()) {
    throw InvalidInputError("BiplanarOptions.isocentre_mm must be finite, got " +
                            format_vector(options.isocentre_mm));
  }
  check_positive(options.source_to_isocentre_mm, "source_to_isocentre_mm");
  check_positive(options.source_to_detector_mm, "source_to_detector_mm");
  check_positive(options.detector_pixel_pitch_mm, "detector_pixel_pitch_mm");
  check_positive(options.field_width_mm, "field_width_mm");
  check_positive(options.field_height_mm, "field_height_mm");
  if (options.source_to_detector_mm <= options.source_to_isocentre_mm) {
    throw InvalidInputError(
        "BiplanarOptions.source_to_detector_mm (" + std::to_string(options.source_to_detector_mm) +
        ") must exceed source_to_isocentre_mm (" + std::to_string(options.source_to_isocentre_mm) +
        "): the detector lies beyond the subject");
  }
  const double spacing = options.detector_pixel_pitch_mm * options.source_to_isocentre_mm /
                         options.source_to_detector_mm;
  const double width = std::max(1.0, std::round(options.field_width_mm / spacing));
  const double height = std::max(1.0, std::round(options.field_height_mm / spacing));
  if (width > kMaxPixelsPerSide || height > kMaxPixelsPerSide) {
    throw InvalidInputError("BiplanarOptions give images of " + std::to_string(width) + " x " +
                            std::to_string(height) +
                            " pixels (limit 100000 a side): check field_*_mm and the pitch");
  }
  ViewGeometry geometry;
  geometry.isocentre_mm = options.isocentre_mm;
  geometry.v_axis = Eigen::Vector3d(0, 0, -1);
  geometry.source_to_isocentre_mm = options.source_to_isocentre_mm;
  geometry.source_to_detector_mm = options.source_to_detector_mm;
  geometry.column_pitch_mm = options.detector_pixel_pitch_mm;
  geometry.row_pitch_mm = options.detector_pixel_pitch_mm;
  geometry.width = static_cast<int>(width);
  geometry.height = static_cast<int>(height);
  geometry.model = options.model;
  // Frontal: beam -y (AP), u toward the subject's left (-x).
  geometry.name = "frontal";
  geometry.u_axis = Eigen::Vector3d(-1, 0, 0);
  geometry.beam = Eigen::Vector3d(0, -1, 0);
  RadiographView frontal = make_view(geometry);
  // Lateral: beam -x (right to left), u toward anterior (+y).
  geometry.name = "lateral";
  geometry.u_axis = Eigen::Vector3d(0, 1, 0);
  geometry.beam = Eigen::Vector3d(-1, 0, 0);
  RadiographView lateral = make_view(geometry);
  return {std::move(frontal), std::move(lateral)};
}

void validate_view(const RadiographView& view) {
  const std::string label = view_label(view);
  if (!view.P.allFinite()) throw InvalidInputError(label + ": P holds a non-finite entry");
  if (view.width < 1 || view.height < 1) {
    throw InvalidInputError(label + ": width and height must be >= 1, got " +
                            std::to_string(view.width) + " x " + std::to_string(view.height));
  }
  if (!std::isfinite(view.pixel_spacing_mm) || view.pixel_spacing_mm <= 0) {
    throw InvalidInputError(label + ": pixel_spacing_mm must be finite and > 0, got " +
                            std::to_string(view.pixel_spacing_mm));
  }
  if (!view.source_mm.allFinite()) {
    throw InvalidInputError(label + ": source_mm must be finite, got " +
                            format_vector(view.source_mm));
  }
  const Eigen::Matrix3d M = view.P.leftCols<3>();
  // |det M| over the product of its row norms (Hadamard's bound) is 1 for
  // orthogonal rows and 0 for a rank-deficient M (a camera at infinity or no
  // camera at all); 1e-12 is rounding level for any physical pinhole.
  const double volume = std::abs(M.determinant());
  const double bound = M.row(0).norm() * M.row(1).norm() * M.row(2).norm();
  if (!(volume > 1e-12 * bound)) {
    throw InvalidInputError(label + ": the left 3 x 3 block of P is singular (not a pinhole view)");
  }
  const Eigen::Vector3d centre = -M.partialPivLu().solve(view.P.col(3));
  if ((centre - view.source_mm).norm() > 1e-6 * (1.0 + centre.norm())) {
    throw InvalidInputError(label + ": source_mm " + format_vector(view.source_mm) +
                            " is not the centre of projection of P " + format_vector(centre) +
                            " (the two must describe the same focal spot)");
  }
}

std::string projection_model_name(ProjectionModel model) {
  return model == ProjectionModel::kSlotScanning ? "slot-scanning" : "pinhole";
}

std::optional<ProjectionModel> projection_model_from_name(std::string_view name) {
  if (name == "pinhole") return ProjectionModel::kPinhole;
  if (name == "slot-scanning") return ProjectionModel::kSlotScanning;
  return std::nullopt;
}

Eigen::Vector3d source_for(const RadiographView& view, const Eigen::Vector3d& X) {
  if (view.model == ProjectionModel::kPinhole) return view.source_mm;
  const double row = view.P.row(1).dot(X.homogeneous());
  return view.source_mm + row * scan_travel(view);
}

Eigen::Matrix<double, 2, 3> projection_jacobian(const RadiographView& view,
                                                const Eigen::Vector3d& X) {
  const Eigen::Vector3d h = view.P * X.homogeneous();
  Eigen::Matrix<double, 2, 3> J;
  J.row(0) = (view.P.block<1, 3>(0, 0) - h.x() / h.z() * view.P.block<1, 3>(2, 0)) / h.z();
  if (view.model == ProjectionModel::kSlotScanning) {
    J.row(1) = view.P.block<1, 3>(1, 0);
  } else {
    J.row(1) = (view.P.block<1, 3>(1, 0) - h.y() / h.z() * view.P.block<1, 3>(2, 0)) / h.z();
  }
  return J;
}

double depth_mm(const RadiographView& view, const Eigen::Vector3d& X) {
  return depth_sign(view.P) * view.P.row(2).dot(X.homogeneous()) / view.P.block<1, 3>(2, 0).norm();
}

Eigen::Vector2d project(const RadiographView& view, const Eigen::Vector3d& X) {
  if (!X.allFinite()) {
    throw InvalidInputError(view_label(view) + ": cannot project the non-finite point " +
                            format_vector(X));
  }
  const Eigen::Vector3d h = view.P * X.homogeneous();
  if (!(depth_sign(view.P) * h.z() > 0)) {
    throw InvalidInputError(view_label(view) + ": point " + format_vector(X) +
                            " lies on or behind the source plane and casts no image");
  }
  if (view.model == ProjectionModel::kSlotScanning) return {h.x() / h.z(), h.y()};
  return h.hnormalized();
}

Ray backproject(const RadiographView& view, const Eigen::Vector2d& pixel) {
  if (!pixel.allFinite()) {
    throw InvalidInputError(view_label(view) + ": cannot back-project a non-finite pixel");
  }
  const Eigen::Matrix3d M = view.P.leftCols<3>();
  if (view.model == ProjectionModel::kSlotScanning) {
    // In the horizontal plane of row v, from the focal spot lighting it:
    // M d = c (u, 0, 1) keeps v and gives column u.
    const Eigen::Vector3d direction = M.partialPivLu().solve(Eigen::Vector3d(pixel.x(), 0, 1));
    const Eigen::Vector3d origin = view.source_mm + pixel.y() * scan_travel(view);
    if (!direction.allFinite() || direction.squaredNorm() == 0 || !origin.allFinite()) {
      throw InvalidInputError(view_label(view) + ": P is singular; cannot back-project");
    }
    return {origin, depth_sign(view.P) * direction.normalized()};
  }
  const Eigen::Vector3d direction = M.partialPivLu().solve(pixel.homogeneous());
  if (!direction.allFinite() || direction.squaredNorm() == 0) {
    throw InvalidInputError(view_label(view) + ": P is singular; cannot back-project");
  }
  return {view.source_mm, depth_sign(view.P) * direction.normalized()};
}

Eigen::Vector3d triangulate_linear(std::span<const RadiographView> views,
                                   std::span<const Eigen::Vector2d> pixels) {
  if (views.size() != pixels.size()) {
    throw InvalidInputError("triangulate_linear: " + std::to_string(views.size()) + " views but " +
                            std::to_string(pixels.size()) + " pixels");
  }
  if (views.size() < 2) {
    throw InvalidInputError("triangulate_linear needs at least 2 views, got " +
                            std::to_string(views.size()));
  }
  const auto n = static_cast<Eigen::Index>(views.size());
  std::vector<Matrix34d> normalised(views.size());
  std::vector<Eigen::Vector3d> directions(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    validate_view(views[i]);
    if (!pixels[i].allFinite()) {
      throw InvalidInputError("triangulate_linear: pixel " + std::to_string(i) + " of " +
                              view_label(views[i]) + " is not finite");
    }
    // Scaled so that the third row gives the depth in mm in front of the source.
    const Matrix34d& P = views[i].P;
    normalised[i] = P * (depth_sign(P) / P.row(2).head<3>().norm());
    directions[i] = backproject(views[i], pixels[i]).direction;
  }
  double widest = 0;
  double baseline = 0;
  double reach = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    reach = std::max(reach, views[i].source_mm.norm());
    for (std::size_t j = i + 1; j < directions.size(); ++j) {
      widest = std::max(widest, directions[i].cross(directions[j]).norm());
      baseline = std::max(baseline, (views[i].source_mm - views[j].source_mm).norm());
    }
  }
  if (widest < kMinRayAngle) {
    throw InvalidInputError(
        "triangulate_linear: degenerate geometry: the rays are parallel (largest angle between "
        "them " +
        std::to_string(widest) + " rad); the views must look from different directions");
  }
  // Rays from one focal spot meet only there: the depth along them is not
  // observed (1e-9 relative: the sources coincide up to rounding).
  if (baseline <= 1e-9 * (1.0 + reach)) {
    throw InvalidInputError(
        "triangulate_linear: degenerate geometry: all views share one source, so the depth "
        "along the rays is unobservable");
  }
  // Pass 0: unit depths; pass 1: each view's rows divided by the depth found.
  Eigen::Vector3d X = Eigen::Vector3d::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::MatrixX3d A(2 * n, 3);
    Eigen::VectorXd b(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Matrix34d& P = normalised[k];
      double weight = views[k].pixel_spacing_mm;
      if (pass == 1) {
        const double depth = P.row(2).dot(X.homogeneous());
        // A point found behind a source (depth <= 0) keeps the unit weight.
        if (depth > 0) weight /= depth;
      }
      for (int r = 0; r < 2; ++r) {
        Eigen::RowVector4d row = pixels[k](r) * P.row(2) - P.row(r);
        double row_weight = weight;
        if (r == 1 && views[k].model == ProjectionModel::kSlotScanning) {
          // v itself is affine: (v e4 - p2) . [X 1], in rows; over the rows
          // per mm it is mm at every depth.
          const Eigen::RowVector4d& p2 = views[k].P.row(1);
          row = -p2;
          row(3) += pixels[k](1);
          row_weight = 1.0 / p2.head<3>().norm();
        }
        A.row(2 * i + r) = row_weight * row.head<3>();
        b(2 * i + r) = -row_weight * row(3);
      }
    }
    X = A.colPivHouseholderQr().solve(b);
  }
  return X;
}

double reprojection_error_mm(const RadiographView& view, const Eigen::Vector3d& X,
                             const Eigen::Vector2d& pixel) {
  return (project(view, X) - pixel).norm() * view.pixel_spacing_mm;
}

void write_view_sidecar(const fs::path& path, std::span<const RadiographFile> views) {
  write_file_atomically(path, view_sidecar_text(views));
}

std::string view_sidecar_text(std::span<const RadiographFile> views) {
  if (views.empty()) throw InvalidInputError("write_view_sidecar: no view to write");
  std::set<std::string> names;
  for (const RadiographFile& file : views) {
    const RadiographView& view = file.view;
    if (view.name.empty()) throw InvalidInputError("write_view_sidecar: a view has no name");
    if (!names.insert(view.name).second) {
      throw InvalidInputError("write_view_sidecar: view name '" + view.name + "' is used twice");
    }
    if (file.image.empty()) {
      throw InvalidInputError("write_view_sidecar: " + view_label(view) +
                              " has no image file name");
    }
    validate_view(view);
  }
  // Laid out by hand for people reading it (one matrix row per line, fields
  // in a fixed order); every value goes through nlohmann's dump, which
  // escapes strings and prints the shortest round-trip form of a double.
  const auto row = [](const auto& values) {
    std::string out = "[";
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      out += (i == 0 ? "" : ", ") + Json(values(i)).dump();
    }
    return out + "]";
  };
  std::string text = "{\n  \"format\": " + Json(kSidecarFormat).dump() +
                     ",\n  \"version\": " + std::to_string(kSidecarVersion) + ",\n  \"views\": [\n";
  for (std::size_t i = 0; i < views.size(); ++i) {
    const RadiographView& view = views[i].view;
    text += "    {\n";
    text += "      \"name\": " + Json(view.name).dump() + ",\n";
    text += "      \"image\": " + Json(views[i].image).dump() + ",\n";
    text += "      \"width\": " + std::to_string(view.width) + ",\n";
    text += "      \"height\": " + std::to_string(view.height) + ",\n";
    if (view.model != ProjectionModel::kPinhole) {
      text += "      \"model\": " + Json(projection_model_name(view.model)).dump() + ",\n";
    }
    text += "      \"pixel_spacing_mm\": " + Json(view.pixel_spacing_mm).dump() + ",\n";
    text += "      \"source_mm\": " + row(view.source_mm) + ",\n";
    text += "      \"P\": [" + row(view.P.row(0)) + ",\n";
    text += "            " + row(view.P.row(1)) + ",\n";
    text += "            " + row(view.P.row(2)) + "]\n";
    text += i + 1 < views.size() ? "    },\n" : "    }\n";
  }
  text += "  ]\n}\n";
  return text;
}

std::vector<RadiographFile> read_view_sidecar(const fs::path& path) {
  return SidecarReader(path).read();
}

std::vector<RadiographFile> parse_view_sidecar(const std::string& text, const fs::path& path) {
  return SidecarReader(path).parse(text);
}

}  // namespace mmm::image
