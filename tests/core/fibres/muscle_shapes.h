#pragma once
// Analytic muscles for the decomposition tests: a closed circular cylinder
// along z with rings along its length, and points on its end discs standing
// for the attachment areas.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/fibres/decomposition.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres::testing {

// Side: `segments` around by `rings` + 1 rings from z = 0 to z = length;
// caps: fans around a centre vertex. Outward oriented.
inline mesh::IndexedMesh ringed_cylinder(double radius, double length, int segments, int rings) {
  const int side = segments * (rings + 1);
  mesh::IndexedMesh m;
  m.V.resize(side + 2, 3);
  for (int r = 0; r <= rings; ++r) {
    for (int i = 0; i < segments; ++i) {
      const double a = 2.0 * std::numbers::pi * i / segments;
      m.V.row(r * segments + i) << radius * std::cos(a), radius * std::sin(a), length * r / rings;
    }
  }
  m.V.row(side) << 0, 0, 0;
  m.V.row(side + 1) << 0, 0, length;
  std::vector<Eigen::Vector3i> faces;
  for (int r = 0; r < rings; ++r) {
    for (int i = 0; i < segments; ++i) {
      const int a = r * segments + i;
      const int b = r * segments + (i + 1) % segments;
      faces.emplace_back(a, b, b + segments);
      faces.emplace_back(a, b + segments, a + segments);
    }
  }
  for (int i = 0; i < segments; ++i) {
    faces.emplace_back(side, (i + 1) % segments, i);
    faces.emplace_back(side + 1, rings * segments + i, rings * segments + (i + 1) % segments);
  }
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    m.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  }
  return m;
}

// Points of a disc of `radius` at height z on a polar grid (centre included).
inline Eigen::MatrixX3d disc_points(double radius, double z) {
  std::vector<Eigen::Vector3d> points{{0, 0, z}};
  for (int ring = 1; ring <= 4; ++ring) {
    const int count = 8 * ring;
    for (int i = 0; i < count; ++i) {
      const double a = 2.0 * std::numbers::pi * i / count;
      const double r = radius * ring / 4.0;
      points.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
  }
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    out.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  }
  return out;
}

// The cylinder's attachments: its end discs, slightly inside the rim.
inline Attachments cylinder_attachments(double radius, double length) {
  return {disc_points(0.95 * radius, 0.0), disc_points(0.95 * radius, length), 0.0, 0.0};
}

}  // namespace mmm::fibres::testing
