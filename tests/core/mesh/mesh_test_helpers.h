#pragma once
// Test-only meshes and topology/geometry measurements computed directly from
// (V, F), independent of the kernels under test: jittered planar grids,
// boundary-edge counts, closedness, volume and area.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <utility>

#include "core/mesh/mesh.h"

namespace mmm::test {

// A uniform random number in [-0.5, 0.5) from the raw mt19937 stream (the
// standard distributions are implementation-defined; this is portable).
inline double centred_unit(std::mt19937& rng) {
  return static_cast<double>(rng()) / 4294967296.0 - 0.5;
}

// n by n vertices on [0, (n-1) h]^2 in the plane z = 0. Each grid square is
// split along a diagonal chosen at random; interior vertices move by up to
// jitter * h / 2 in x and y. Faces are counter-clockwise seen from +z.
inline mesh::IndexedMesh make_jittered_grid(int n, double h, double jitter, std::uint32_t seed) {
  std::mt19937 rng(seed);
  mesh::IndexedMesh grid;
  grid.V.resize(static_cast<Eigen::Index>(n) * n, 3);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      double x = c * h;
      double y = r * h;
      if (r > 0 && r < n - 1 && c > 0 && c < n - 1) {
        x += jitter * h * centred_unit(rng);
        y += jitter * h * centred_unit(rng);
      }
      grid.V.row(r * n + c) << x, y, 0.0;
    }
  }
  grid.F.resize(2 * static_cast<Eigen::Index>(n - 1) * (n - 1), 3);
  Eigen::Index f = 0;
  for (int r = 0; r + 1 < n; ++r) {
    for (int c = 0; c + 1 < n; ++c) {
      const int a = r * n + c;  // (c, r)
      const int b = a + 1;      // (c+1, r)
      const int d = a + n;      // (c, r+1)
      const int e = d + 1;      // (c+1, r+1)
      if ((rng() & 1U) != 0U) {
        grid.F.row(f++) << a, b, e;
        grid.F.row(f++) << a, e, d;
      } else {
        grid.F.row(f++) << a, b, d;
        grid.F.row(f++) << b, e, d;
      }
    }
  }
  return grid;
}

// Number of faces using each undirected edge (min, max).
inline std::map<std::pair<int, int>, int> edge_face_counts(const Eigen::MatrixX3i& F) {
  std::map<std::pair<int, int>, int> counts;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) ++counts[std::minmax(F(f, k), F(f, (k + 1) % 3))];
  }
  return counts;
}

// Edges used by exactly one face.
inline int count_boundary_edges(const Eigen::MatrixX3i& F) {
  int boundary = 0;
  for (const auto& [edge, count] : edge_face_counts(F)) boundary += count == 1 ? 1 : 0;
  return boundary;
}

// Every undirected edge in exactly two faces, and every directed edge in
// exactly one (consistently oriented closed two-manifold along edges).
inline bool is_closed_edge_manifold(const Eigen::MatrixX3i& F) {
  std::map<std::pair<int, int>, int> directed;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
  }
  for (const auto& [edge, count] : directed) {
    if (count != 1 || directed.count({edge.second, edge.first}) != 1) return false;
  }
  return !directed.empty();
}

// V - E + F over the referenced edges (2 for a sphere, 0 for a torus).
inline Eigen::Index euler_characteristic(const mesh::IndexedMesh& mesh) {
  return mesh.num_vertices() - static_cast<Eigen::Index>(edge_face_counts(mesh.F).size()) +
         mesh.num_faces();
}

// Enclosed volume by the divergence theorem: sum of v0 . (v1 x v2) / 6.
inline double signed_volume(const mesh::IndexedMesh& mesh) {
  double volume = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2)).transpose();
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

// A point uniform in `box`.
inline Eigen::Vector3d uniform_in(const Eigen::AlignedBox3d& box, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d s(unit(rng), unit(rng), unit(rng));
  return box.min() + s.cwiseProduct(box.sizes());
}

inline double triangle_area(const mesh::IndexedMesh& mesh, Eigen::Index f) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose();
  const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1)).transpose();
  const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2)).transpose();
  return 0.5 * (b - a).cross(c - a).norm();
}

inline double surface_area(const mesh::IndexedMesh& mesh) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) area += triangle_area(mesh, f);
  return area;
}

// Mean edge length over the undirected edges.
inline double mean_edge_length(const mesh::IndexedMesh& mesh) {
  const auto counts = edge_face_counts(mesh.F);
  double sum = 0.0;
  for (const auto& [edge, count] : counts) {
    sum += (mesh.V.row(edge.first) - mesh.V.row(edge.second)).norm();
  }
  return counts.empty() ? 0.0 : sum / static_cast<double>(counts.size());
}

// Largest gap between the sphere of radius `radius` around `center` and an
// inscribed icosphere: radius minus the smallest distance from the centre to a
// face plane. All vertices lie on the sphere, so the foot of the perpendicular
// from the centre to a face plane is the face's circumcentre, which is inside
// the (acute) icosphere faces: the nearest point of the polyhedron to the centre
// is such a foot. For an equilateral face of edge e this gap is about
// e^2 / (6 radius).
inline double icosphere_gap(const mesh::IndexedMesh& sphere, double radius,
                            const Eigen::Vector3d& center) {
  double nearest_plane = radius;
  for (Eigen::Index f = 0; f < sphere.num_faces(); ++f) {
    const Eigen::Vector3d a = sphere.V.row(sphere.F(f, 0)).transpose();
    const Eigen::Vector3d b = sphere.V.row(sphere.F(f, 1)).transpose();
    const Eigen::Vector3d c = sphere.V.row(sphere.F(f, 2)).transpose();
    nearest_plane = std::min(nearest_plane, (b - a).cross(c - a).normalized().dot(a - center));
  }
  return radius - nearest_plane;
}

}  // namespace mmm::test
