#include "core/fibres/fibre_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/fibres/t_polynomial.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/winding_number.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector3d;

constexpr const char* kWhat = "fibre quality: ";

void check_options(const FibreQualityOptions& options) {
  if (!std::isfinite(options.surface_tolerance_mm) || options.surface_tolerance_mm < 0.0) {
    throw InvalidInputError(std::string(kWhat) +
                            "surface_tolerance_mm must be finite and >= 0, got " +
                            std::to_string(options.surface_tolerance_mm));
  }
  if (!std::isfinite(options.coverage_radius_mm) || options.coverage_radius_mm <= 0.0) {
    throw InvalidInputError(std::string(kWhat) + "coverage_radius_mm must be finite and > 0, got " +
                            std::to_string(options.coverage_radius_mm) +
                            "; hint: about the spacing of the fibre ends, e.g. 5 mm");
  }
  if (options.polynomial_degree < 0 || options.polynomial_degree > kMaxTPolynomialDegree) {
    throw InvalidInputError(std::string(kWhat) + "polynomial_degree " +
                            std::to_string(options.polynomial_degree) + " is out of range 0.." +
                            std::to_string(kMaxTPolynomialDegree) +
                            "; hint: 3 to 5 suffice for muscle fibres");
  }
}

void check_attachment_points(const Eigen::MatrixX3d& points, const std::string& name) {
  if (points.rows() == 0) {
    throw InvalidInputError(std::string(kWhat) + "no " + name +
                            " points; hint: sample at least one point on the " + name +
                            " attachment area");
  }
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) {
      throw InvalidInputError(std::string(kWhat) + name + " point " + std::to_string(i) +
                              " is not finite (NaN or infinite)");
    }
  }
}

// Checks fibre `index` and returns its polyline length (mm).
double checked_length(const Fibre& fibre, std::size_t index) {
  const std::string name = "fibre " + std::to_string(index);
  if (fibre.rows() < 2) {
    throw InvalidInputError(
        std::string(kWhat) + name + " has " + std::to_string(fibre.rows()) +
        " point(s); hint: a fibre needs at least its origin and insertion ends");
  }
  for (Eigen::Index i = 0; i < fibre.rows(); ++i) {
    if (!fibre.row(i).allFinite()) {
      throw InvalidInputError(std::string(kWhat) + name + " point " + std::to_string(i) +
                              " is not finite (NaN or infinite)");
    }
  }
  const double length =
      (fibre.bottomRows(fibre.rows() - 1) - fibre.topRows(fibre.rows() - 1)).rowwise().norm().sum();
  if (!(length > 0.0))
    throw InvalidInputError(std::string(kWhat) + name + " has zero length (all points equal)");
  return length;
}

double median(std::vector<double> values) {
  const std::size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(half),
                   values.end());
  const double upper = values[half];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(),
                                          values.begin() + static_cast<std::ptrdiff_t>(half)));
}

// Population mean and coefficient of variation (0 when the mean is 0).
std::pair<double, double> mean_and_cv(const std::vector<double>& values) {
  if (values.empty()) return {0.0, 0.0};
  const auto n = static_cast<double>(values.size());
  double sum = 0.0;
  for (const double v : values) sum += v;
  const double mean = sum / n;
  double squares = 0.0;
  for (const double v : values) squares += (v - mean) * (v - mean);
  return {mean, mean > 0.0 ? std::sqrt(squares / n) / mean : 0.0};
}

// The polyline resampled at `count` points of equal arc length (ends kept).
Fibre resample(const Fibre& fibre, Eigen::Index count) {
  const Eigen::VectorXd t = arc_length_parameters(fibre);
  Fibre result(count, 3);
  Eigen::Index segment = 0;
  for (Eigen::Index j = 0; j < count; ++j) {
    const double u = static_cast<double>(j) / static_cast<double>(count - 1);
    while (segment < t.size() - 2 && t[segment + 1] < u) ++segment;
    const double span = t[segment + 1] - t[segment];
    const double w = span > 0.0 ? std::clamp((u - t[segment]) / span, 0.0, 1.0) : 0.0;
    result.row(j) = (1.0 - w) * fibre.row(segment) + w * fibre.row(segment + 1);
  }
  return result;
}

// Distances to the nearest other fibre at every interior sample index.
std::vector<double> spacings(const std::vector<Fibre>& fibres) {
  Eigen::Index count = 0;
  bool same = true;
  for (const Fibre& fibre : fibres) {
    same = same && (count == 0 || fibre.rows() == count);
    count = std::max(count, fibre.rows());
  }
  std::vector<Fibre> resampled;
  if (!same) {
    resampled.reserve(fibres.size());
    for (const Fibre& fibre : fibres) resampled.push_back(resample(fibre, count));
  }
  const std::vector<Fibre>& samples = same ? fibres : resampled;
  std::vector<double> result;
  if (samples.size() < 2) return result;
  result.reserve(samples.size() * static_cast<std::size_t>(std::max<Eigen::Index>(count - 2, 0)));
  for (Eigen::Index k = 1; k + 1 < count; ++k) {
    for (std::size_t i = 0; i < samples.size(); ++i) {
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < samples.size(); ++j) {
        if (j != i)
          nearest = std::min(nearest, (samples[i].row(k) - samples[j].row(k)).squaredNorm());
      }
      result.push_back(std::sqrt(nearest));
    }
  }
  return result;
}

struct EndFigures {
  double distance_median = 0;
  double distance_max = 0;
  double coverage = 0;
};

// Fibre ends (#fibres by 3) against attachment points, brute force.
EndFigures measure_ends(const Eigen::MatrixX3d& ends, const Eigen::MatrixX3d& points,
                        double coverage_radius) {
  std::vector<double> nearest(static_cast<std::size_t>(ends.rows()),
                              std::numeric_limits<double>::infinity());
  const double radius_squared = coverage_radius * coverage_radius;
  Eigen::Index covered = 0;
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    double closest = std::numeric_limits<double>::infinity();
    for (Eigen::Index e = 0; e < ends.rows(); ++e) {
      const double d = (points.row(p) - ends.row(e)).squaredNorm();
      closest = std::min(closest, d);
      auto& best = nearest[static_cast<std::size_t>(e)];
      best = std::min(best, d);
    }
    if (closest <= radius_squared) ++covered;
  }
  for (double& d : nearest) d = std::sqrt(d);
  return {median(nearest), *std::max_element(nearest.begin(), nearest.end()),
          static_cast<double>(covered) / static_cast<double>(points.rows())};
}

double fit_error(const Fibre& fibre, int degree) {
  const Eigen::MatrixXd points = fibre;
  const Eigen::VectorXd t = arc_length_parameters(points);
  int distinct = 1;
  for (Eigen::Index i = 1; i < t.size(); ++i) distinct += t[i] > t[i - 1] ? 1 : 0;
  return fit_t_polynomial(t, points, std::min(degree, distinct - 1)).mean_resultant_error;
}

}  // namespace

double inside_fraction(const mesh::IndexedMesh& surface, const std::vector<Fibre>& fibres,
                       double surface_tolerance_mm) {
  const mesh::AabbTree tree(surface);
  const mesh::WindingNumber winding(tree);
  const double tolerance_squared = surface_tolerance_mm * surface_tolerance_mm;
  int inside = 0;
  int vertices = 0;
  for (const Fibre& fibre : fibres) {
    for (Eigen::Index i = 0; i < fibre.rows(); ++i) {
      const Vector3d q = fibre.row(i).transpose();
      if (winding.is_inside(q) || tree.closest_point_within(q, tolerance_squared)) ++inside;
    }
    vertices += static_cast<int>(fibre.rows());
  }
  return vertices > 0 ? static_cast<double>(inside) / vertices : 1.0;
}

FibreQuality measure_fibre_quality(const mesh::IndexedMesh& surface,
                                   const std::vector<Fibre>& fibres, const Eigen::MatrixX3d& origin,
                                   const Eigen::MatrixX3d& insertion,
                                   const FibreQualityOptions& options) {
  check_options(options);
  if (fibres.empty())
    throw InvalidInputError(std::string(kWhat) + "no fibres; hint: decompose the muscle first");
  std::vector<double> lengths;
  lengths.reserve(fibres.size());
  for (std::size_t i = 0; i < fibres.size(); ++i) lengths.push_back(checked_length(fibres[i], i));
  check_attachment_points(origin, "origin");
  check_attachment_points(insertion, "insertion");
  if (surface.empty())
    throw InvalidInputError(std::string(kWhat) + "the muscle surface has no face");

  FibreQuality quality;
  quality.fibres = static_cast<int>(fibres.size());
  for (const Fibre& fibre : fibres) quality.vertices += static_cast<int>(fibre.rows());
  try {
    quality.inside_fraction = inside_fraction(surface, fibres, options.surface_tolerance_mm);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(std::string(kWhat) + "muscle surface: " + error.what());
  }

  Eigen::MatrixX3d first(static_cast<Eigen::Index>(fibres.size()), 3);
  Eigen::MatrixX3d last(first.rows(), 3);
  for (std::size_t i = 0; i < fibres.size(); ++i) {
    first.row(static_cast<Eigen::Index>(i)) = fibres[i].row(0);
    last.row(static_cast<Eigen::Index>(i)) = fibres[i].row(fibres[i].rows() - 1);
  }
  const EndFigures origin_ends = measure_ends(first, origin, options.coverage_radius_mm);
  const EndFigures insertion_ends = measure_ends(last, insertion, options.coverage_radius_mm);
  quality.origin_end_distance_median_mm = origin_ends.distance_median;
  quality.origin_end_distance_max_mm = origin_ends.distance_max;
  quality.origin_coverage = origin_ends.coverage;
  quality.insertion_end_distance_median_mm = insertion_ends.distance_median;
  quality.insertion_end_distance_max_mm = insertion_ends.distance_max;
  quality.insertion_coverage = insertion_ends.coverage;

  std::tie(quality.spacing_mean_mm, quality.spacing_cv) = mean_and_cv(spacings(fibres));

  quality.length_median_mm = median(lengths);
  const auto [shortest, longest] = std::minmax_element(lengths.begin(), lengths.end());
  quality.length_min_mm = *shortest;
  quality.length_max_mm = *longest;
  quality.length_cv = mean_and_cv(lengths).second;

  double error_sum = 0.0;
  for (const Fibre& fibre : fibres) {
    const double error = fit_error(fibre, options.polynomial_degree);
    error_sum += error;
    quality.fit_error_max_mm = std::max(quality.fit_error_max_mm, error);
  }
  quality.fit_error_mean_mm = error_sum / static_cast<double>(fibres.size());
  return quality;
}

nlohmann::json to_json(const FibreQuality& quality) {
  nlohmann::json json;
  to_json(json, quality);
  return json;
}

void to_json(nlohmann::json& json, const FibreQuality& quality) {
  json = nlohmann::json{
      {"fibres", quality.fibres},
      {"vertices", quality.vertices},
      {"inside_fraction", quality.inside_fraction},
      {"origin_end_distance_median_mm", quality.origin_end_distance_median_mm},
      {"origin_end_distance_max_mm", quality.origin_end_distance_max_mm},
      {"insertion_end_distance_median_mm", quality.insertion_end_distance_median_mm},
      {"insertion_end_distance_max_mm", quality.insertion_end_distance_max_mm},
      {"origin_coverage", quality.origin_coverage},
      {"insertion_coverage", quality.insertion_coverage},
      {"spacing_mean_mm", quality.spacing_mean_mm},
      {"spacing_cv", quality.spacing_cv},
      {"length_median_mm", quality.length_median_mm},
      {"length_min_mm", quality.length_min_mm},
      {"length_max_mm", quality.length_max_mm},
      {"length_cv", quality.length_cv},
      {"fit_error_mean_mm", quality.fit_error_mean_mm},
      {"fit_error_max_mm", quality.fit_error_max_mm},
  };
}

}  // namespace mmm::fibres
