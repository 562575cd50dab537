#pragma once
// How far wrapped muscles run into each other: the muscle-muscle penetration
// metric of muscle wrapping, measured after every muscle has been solved for
// a frame (muscles are wrapped independently; nothing here moves a vertex).
//
// Segmented atlases overlap a little where two muscles meet (the Visible
// Human surfaces were traced one by one), so the metric is the penetration
// the motion adds: a vertex's depth inside another muscle minus its depth
// inside that muscle at rest (0 where it was outside). Inside tests by
// winding number, depths by exact closest point (mesh::SignedDistance); only
// muscles whose boxes meet are compared.

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <vector>

#include "core/mesh/signed_distance.h"

namespace mmm::wrapping {

struct MuscleWrapping;

// Every muscle's surface in one pose (mm), ready for inside queries.
class MuscleSurfaces {
 public:
  // positions[m]: muscle m's vertices; faces[m] its triangles. Built on
  // `threads` threads. Throws InvalidInputError on a size mismatch or an
  // invalid mesh.
  MuscleSurfaces(const std::vector<Eigen::MatrixX3d>& positions,
                 const std::vector<const Eigen::MatrixX3i*>& faces, int threads);

  [[nodiscard]] std::size_t size() const { return surfaces_.size(); }
  [[nodiscard]] const mesh::SignedDistance& surface(std::size_t m) const { return *surfaces_[m]; }
  [[nodiscard]] const Eigen::AlignedBox3d& box(std::size_t m) const { return boxes_[m]; }

 private:
  std::vector<std::unique_ptr<mesh::SignedDistance>> surfaces_;
  std::vector<Eigen::AlignedBox3d> boxes_;
};

// Per other muscle n: the rest depth (mm, >= 0) of each vertex of one muscle
// inside n; only muscles it overlaps at rest are listed.
using RestOverlap = std::map<int, Eigen::VectorXd>;

// The rest overlap of muscle `self` (vertices x) with the others.
RestOverlap rest_overlap(int self, const Eigen::MatrixX3d& x, const MuscleSurfaces& others);

struct MusclePenetration {
  double max_depth_mm = 0.0;  // deepest vertex beyond its rest depth in another muscle
  int vertices_deeper = 0;    // vertices deeper than that by more than the tolerance
  int deepest_muscle = -1;    // index of the muscle where max_depth_mm is reached (-1: none)
};

// Penetration of muscle `self` (vertices x) into the other muscles.
MusclePenetration measure_muscle_penetration(int self, const Eigen::MatrixX3d& x,
                                             const MuscleSurfaces& others, const RestOverlap& rest,
                                             double tolerance_mm);

// Fills muscle_depth_mm, muscle_vertices_deeper and deepest_muscle of every
// muscle-frame of `wrapped` (rest overlaps from the muscles' rest surfaces),
// frames in parallel on `threads` threads.
void measure_muscle_penetration(MuscleWrapping& wrapped, double tolerance_mm, int threads);

}  // namespace mmm::wrapping
