#pragma once
// Fibre templates in the unit cube (after Blemker & Delp 2005): each fibre a
// quadratic Bezier curve from the origin face (s = 0) to the insertion face
// (s = 1) of the cube, whose control points sit at s = 0, 1/2 and 1, so a
// fibre's cross-section position (u, v) is a quadratic function of s. The
// fibres' labels (a, b) form a regular grid of the cross-section; the
// architecture decides how a fibre wanders from its label:
//
//   parallel  straight along s at (a, b)
//   fanned    broad at one end, converging in u to the middle third at the
//             other ("narrow" end: the end with the smaller attachment area)
//   pennate   straight but oblique: u runs from 0.6 a to 0.6 a + 0.4, the
//             same tilt for every fibre (unipennate)
//   curved    bowed toward u = 1 by 0.3 (1 - a) at mid-length

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/atlas/atlas.h"

namespace mmm::fibres {

struct TemplateFibre {
  Eigen::Vector2d label;                   // (a, b): grid position in the cross-section
  std::array<Eigen::Vector2d, 3> control;  // (u, v) at s = 0, 1/2, 1
  // (u, v) at s in [0, 1].
  [[nodiscard]] Eigen::Vector2d at(double s) const;
};

// `count` (>= 1) labels on a near-square grid of cell centres: columns
// ceil(sqrt(count)), rows as needed, the last row centred when short; 81 is
// the 9 by 9 grid at (i + 1/2) / 9.
std::vector<Eigen::Vector2d> fibre_labels(int count);

// The template of `count` fibres. `narrow_at_insertion` orients the fanned
// template (ignored by the others). Throws InvalidInputError for count < 1.
std::vector<TemplateFibre> fibre_template(atlas::FibreArchitecture architecture, int count,
                                          bool narrow_at_insertion = true);

}  // namespace mmm::fibres
