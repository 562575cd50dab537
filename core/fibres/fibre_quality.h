#pragma once
// Quality figures of a muscle's fibre decomposition (any method of
// core/fibres/): do the fibres stay inside the muscle, start and end on the
// attachment areas and cover them, fill the muscle evenly, and are they smooth
// enough for a t-polynomial (Audenaert et al. 2010, equation (3))?
//
//   tree = AabbTree(surface); w = WindingNumber(tree)
//   vertex inside      <=> w(q) > 1/2  or  |q - closest_point(q)| <= tolerance
//   end distance       =   min over attachment points a of |end - a|
//   point covered      <=> min over fibre ends e of |a - e| <= coverage radius
//   spacing at (i, k)  =   min over fibres j != i of |p_i,k - p_j,k|, 0 < k < S
//   fit error          =   mean_resultant_error of fit_t_polynomial(fibre, n)
//
// Nearest-point searches between ends and attachment points are brute force:
// #fibres x #points distances per end (3e5 for 300 fibres and 1000 points).

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "core/fibres/fibre_set.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

struct FibreQualityOptions {
  // A vertex outside the surface by at most this much (mm, >= 0) still counts
  // as inside: fibre ends sit on the attachment areas, on the surface.
  double surface_tolerance_mm = 0.5;
  // An attachment point counts as covered when a fibre end lies within this
  // distance of it (mm, > 0; "within" includes equality).
  double coverage_radius_mm = 5.0;
  // Degree n of the t-polynomial fitted to each fibre (0..kMaxTPolynomialDegree
  // of t_polynomial.h). A fibre with fewer than n + 1 points at distinct
  // arc-length parameters is fitted with the highest degree it supports
  // (which interpolates it: error 0).
  int polynomial_degree = 5;
};

// Every median is of the values sorted, the middle one or the mean of the two
// middle ones; every coefficient of variation (cv) is the population standard
// deviation (divided by the count, not count - 1) over the mean.
struct FibreQuality {
  int fibres = 0;    // number of fibres
  int vertices = 0;  // total number of fibre points
  // Fraction of all fibre points (over `vertices`) that are inside the surface
  // (generalized winding number > 1/2) or within surface_tolerance_mm of it.
  double inside_fraction = 0;
  // Per fibre, the distance from its first point (origin end) to the nearest
  // origin attachment point (mm); median and largest over the fibres.
  double origin_end_distance_median_mm = 0;
  double origin_end_distance_max_mm = 0;
  // The same for the last point (insertion end) and the insertion points.
  double insertion_end_distance_median_mm = 0;
  double insertion_end_distance_max_mm = 0;
  // Fraction of the origin (insertion) attachment points that have the first
  // (last) point of some fibre within coverage_radius_mm.
  double origin_coverage = 0;
  double insertion_coverage = 0;
  // Spacing: for every interior sample index k = 1 .. S - 1 and every fibre i,
  // the distance from fibre i's point k to the nearest point k of any other
  // fibre (mm). The samples are the fibres' own points when all fibres have
  // the same count S + 1 (the convention of fibre_set.h: point k at level
  // t = k / S); otherwise every fibre is first resampled at equal arc length
  // to the largest count. Mean (mm) and cv of those #fibres x (S - 1)
  // distances; both 0 when there is none (a single fibre, or S < 2) and the cv
  // is 0 when the mean is 0 (coinciding fibres).
  double spacing_mean_mm = 0;
  double spacing_cv = 0;
  // Polyline length of each fibre (sum of its segment lengths, mm): median,
  // smallest, largest, and cv.
  double length_median_mm = 0;
  double length_min_mm = 0;
  double length_max_mm = 0;
  double length_cv = 0;
  // Per fibre, the mean resultant error (equation (3), mm) of its
  // least-squares t-polynomial of degree polynomial_degree with t by arc
  // length: the mean over the fibres and the largest.
  double fit_error_mean_mm = 0;
  double fit_error_max_mm = 0;
};

// Measures a decomposition.
//   surface    closed, outward-oriented muscle surface (V #V by 3 mm, F #F by 3)
//   fibres     >= 1 fibres of >= 2 finite points each, not all equal (mm)
//   origin     #O by 3 points sampled on the origin attachment area, #O >= 1 (mm)
//   insertion  #I by 3 points sampled on the insertion attachment area, #I >= 1 (mm)
// Throws InvalidInputError naming what is wrong for no fibres, a fibre with
// fewer than two points, non-finite or all-equal points, an empty or
// non-finite attachment point set, options out of range, or an empty or
// invalid surface.
FibreQuality measure_fibre_quality(const mesh::IndexedMesh& surface,
                                   const std::vector<Fibre>& fibres, const Eigen::MatrixX3d& origin,
                                   const Eigen::MatrixX3d& insertion,
                                   const FibreQualityOptions& options = {});

// The inside_fraction of FibreQuality alone (1 for no points): for checks
// repeated per frame, where the other figures are not needed. Throws
// InvalidInputError for an invalid surface.
double inside_fraction(const mesh::IndexedMesh& surface, const std::vector<Fibre>& fibres,
                       double surface_tolerance_mm = FibreQualityOptions{}.surface_tolerance_mm);

// A flat JSON object whose keys are the field names above, e.g.
// {"fibres": 81, "inside_fraction": 1.0, "spacing_cv": 0.12, ...}. The
// second form is nlohmann's hook (`nlohmann::json j = quality;`). Include
// <nlohmann/json.hpp> to use them.
nlohmann::json to_json(const FibreQuality& quality);
void to_json(nlohmann::json& json, const FibreQuality& quality);

}  // namespace mmm::fibres
