#pragma once
// All muscles at rest as one labelled lattice: every cubic cell of a regular
// grid belongs to at most one muscle, so that touching muscles share their
// interface and none overlaps another by construction. The first step of the
// volumetric pathway (lattice_tets.h turns the cells into tetrahedra).
//
//   cell c (centre x_c) is inside a surface when a ray along +z through x_c
//     has entered it more often than it has left it below x_c (the crossings'
//     orientation, so nested or inward-facing pieces count as they should)
//   inside a bone                  -> empty (bone wins: muscles wrap bones)
//   inside exactly one muscle      -> that muscle
//   inside several muscles         -> the one it lies deepest in (largest
//                                     distance to that muscle's surface); a
//                                     tie to the muscle listed first
// The segmentations overlap at rest (by millimetres between neighbours, and
// by a fifth of a muscle where one comes from another body, as the default
// atlas's mirrored long head of biceps femoris). Where two muscles overlap
// equally deep the rule splits the overlap along its middle; a muscle mostly
// inside another gives up most of the overlap.
//
// Then each muscle that has fewer cells than its segmentation's volume grows
// them back, as a muscle displaced by its neighbour bulges elsewhere: in
// rounds, the empty cells next to its cells (not bone, not another muscle's),
// nearest its own surface first, until its volume is back or it has grown
// max_regrowth_mm beyond its cells. Muscles grow in input order within a
// round. Deterministic: the same input gives the same labels, whatever the
// number of threads.
//
// Per muscle the report separates what the grid itself changes (the cells
// whose centre lies inside the muscle against the surface's volume, an
// O(spacing x area) staircase error that mostly cancels), what resolving the
// overlaps and the bones takes away, and what the regrowth gives back.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mmm::volumetric {

struct LatticeOptions {
  double spacing_mm = 3.0;  // cell edge, > 0
  int padding_cells = 1;    // empty cells around the muscles' bounding box, >= 1
  int threads = 1;
  // Volume given to other muscles or bones is grown back (see above) up to
  // this far beyond the muscle's cells; 0: not grown back.
  double max_regrowth_mm = 6.0;
  // Refused above this many cells (choose a larger spacing).
  std::int64_t max_cells = 200'000'000;
};

struct NamedSurface {
  std::string name;
  const mesh::IndexedMesh* surface = nullptr;  // closed, outward oriented, mm
};

// What the lattice did to one muscle's volume (mm^3).
struct MuscleCells {
  std::string name;
  double segmented_mm3 = 0.0;      // enclosed by its surface
  double inside_mm3 = 0.0;         // cells whose centre is inside it (the grid's own error)
  double to_bones_mm3 = 0.0;       // of those, inside a bone
  double to_muscles_mm3 = 0.0;     // of those, given to a muscle it is less deep in
  double regrown_mm3 = 0.0;        // grown back into free cells next to it
  double regrowth_depth_mm = 0.0;  // farthest regrown cell from its surface
  double kept_mm3 = 0.0;           // its cells in the lattice
  // kept / segmented - 1: everything the lattice changed
  [[nodiscard]] double change() const { return kept_mm3 / segmented_mm3 - 1.0; }
};

struct LabelledLattice {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner of cell (0, 0, 0), mm
  double spacing_mm = 0.0;
  Eigen::Array3i cells = Eigen::Array3i::Zero();  // per axis
  // Per cell, x fastest then y then z: 0 empty, k + 1 the k-th muscle.
  std::vector<std::uint16_t> label;
  std::vector<MuscleCells> muscles;  // in input order

  [[nodiscard]] std::int64_t index(int i, int j, int k) const {
    return (static_cast<std::int64_t>(k) * cells.y() + j) * cells.x() + i;
  }
  [[nodiscard]] std::uint16_t at(int i, int j, int k) const {
    return label[static_cast<std::size_t>(index(i, j, k))];
  }
  [[nodiscard]] Eigen::Vector3d centre(int i, int j, int k) const {
    return origin + spacing_mm * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
};

// Throws InvalidInputError (naming the muscle or bone, or the option) for no
// muscles, more than 65534 of them, a null, empty, invalid or non-finite
// surface, a surface enclosing no volume (open or inward facing), a
// non-positive or non-finite spacing, padding_cells < 1, a negative or
// non-finite max_regrowth_mm, or more cells than max_cells.
LabelledLattice build_labelled_lattice(const std::vector<NamedSurface>& muscles,
                                       const std::vector<NamedSurface>& bones,
                                       const LatticeOptions& options = {});

}  // namespace mmm::volumetric
