#pragma once
// What every decomposition method of a muscle into fibres takes: the muscle
// surface (closed, outward oriented, mm), points sampled on its attachment
// areas, and the fibre count and resolution. See fibre_set.h for the
// conventions of fibres and contours.

#include <Eigen/Core>

#include <vector>

#include "core/atlas/atlas.h"
#include "core/fibres/fibre_set.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// Points on the muscle's origin and insertion attachment areas (each #P by
// 3, at least one point; e.g. the centroids of the areas' bone faces).
// The areas (mm^2, 0 when unknown) decide which end of a fanned muscle is
// narrow; unknown, the point counts stand in for them.
struct Attachments {
  Eigen::MatrixX3d origin;
  Eigen::MatrixX3d insertion;
  double origin_area_mm2 = 0.0;
  double insertion_area_mm2 = 0.0;
  [[nodiscard]] bool narrow_at_insertion() const {
    return origin_area_mm2 > 0.0 && insertion_area_mm2 > 0.0 ? insertion_area_mm2 <= origin_area_mm2
                                                             : insertion.rows() <= origin.rows();
  }
};

struct DecompositionOptions {
  int fibres = 81;    // >= 1
  int segments = 20;  // per fibre, >= 2
  atlas::FibreArchitecture architecture = atlas::FibreArchitecture::kParallel;
  int contour_points = 64;   // per slice contour, a multiple of 8
  int smoothing_passes = 2;  // of the fibres after their ends are extended (>= 0)
};

// The muscle's frame: `axis` (unit) from the centroid of the origin points
// toward that of the insertion points; `reference` (unit, across the axis)
// the direction of the muscle's widest spread across it (principal axis of
// its vertices projected across the axis), the side where contours start.
struct MuscleAxes {
  Eigen::Vector3d origin_centre;
  Eigen::Vector3d insertion_centre;
  Eigen::Vector3d axis;
  Eigen::Vector3d reference;
};

// What the contour methods (slicing, harmonic, mass-spring) return: the
// fibres, the contours they went through, levels without a closed contour
// (interpolated from their neighbours), fibre points moved into the muscle
// (keep_inside.h) and the muscle's axes.
struct ContourFibres {
  std::vector<Fibre> fibres;
  std::vector<Contour> contours;
  int interpolated_contours = 0;
  int moved_inside = 0;
  MuscleAxes axes;
};

// Throws InvalidInputError when a point set is empty or not finite, or the
// two centroids coincide.
MuscleAxes muscle_axes(const mesh::IndexedMesh& surface, const Attachments& attachments);

// Throws InvalidInputError naming the bad option.
void validate(const DecompositionOptions& options);

}  // namespace mmm::fibres
