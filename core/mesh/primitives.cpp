#include "core/mesh/primitives.h"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace mmm::mesh {
namespace {

IndexedMesh from_lists(const std::vector<Eigen::Vector3d>& vertices,
                       const std::vector<Eigen::Vector3i>& faces) {
  IndexedMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t i = 0; i < vertices.size(); ++i) {
    mesh.V.row(static_cast<Eigen::Index>(i)) = vertices[i].transpose();
  }
  for (size_t i = 0; i < faces.size(); ++i) {
    mesh.F.row(static_cast<Eigen::Index>(i)) = faces[i].transpose();
  }
  return mesh;
}

}  // namespace

IndexedMesh make_icosphere(int subdivisions, double radius, const Eigen::Vector3d& center) {
  if (subdivisions < 0 || subdivisions > 8) {
    throw InvalidInputError("icosphere subdivisions must be in [0, 8], got " +
                            std::to_string(subdivisions));
  }
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                           {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                           {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : vertices) v.normalize();
  std::vector<Eigen::Vector3i> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint_of;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint_of.find(key);
      if (it != midpoint_of.end()) return it->second;
      vertices.push_back(
          (vertices[static_cast<size_t>(a)] + vertices[static_cast<size_t>(b)]).normalized());
      const int index = static_cast<int>(vertices.size()) - 1;
      midpoint_of.emplace(key, index);
      return index;
    };
    std::vector<Eigen::Vector3i> refined;
    refined.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const int ab = midpoint(f[0], f[1]);
      const int bc = midpoint(f[1], f[2]);
      const int ca = midpoint(f[2], f[0]);
      refined.emplace_back(f[0], ab, ca);
      refined.emplace_back(f[1], bc, ab);
      refined.emplace_back(f[2], ca, bc);
      refined.emplace_back(ab, bc, ca);
    }
    faces = std::move(refined);
  }
  for (auto& v : vertices) v = center + radius * v;
  return from_lists(vertices, faces);
}

IndexedMesh make_box(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner) {
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(8);
  for (int i = 0; i < 8; ++i) {
    vertices.emplace_back((i & 1) ? max_corner.x() : min_corner.x(),
                          (i & 2) ? max_corner.y() : min_corner.y(),
                          (i & 4) ? max_corner.z() : min_corner.z());
  }
  // Two outward triangles per side; vertex i has bits (x, y, z).
  const std::vector<Eigen::Vector3i> faces = {{0, 2, 3}, {0, 3, 1},   // z = lo
                                              {4, 5, 7}, {4, 7, 6},   // z = hi
                                              {0, 1, 5}, {0, 5, 4},   // y = lo
                                              {2, 6, 7}, {2, 7, 3},   // y = hi
                                              {0, 4, 6}, {0, 6, 2},   // x = lo
                                              {1, 3, 7}, {1, 7, 5}};  // x = hi
  return from_lists(vertices, faces);
}

IndexedMesh make_torus(double major_radius, double minor_radius, int major_segments,
                       int minor_segments) {
  if (major_segments < 3 || minor_segments < 3 || minor_radius <= 0 ||
      major_radius <= minor_radius) {
    throw InvalidInputError(
        "torus needs major_radius > minor_radius > 0 and at least 3 segments each way");
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  vertices.reserve(static_cast<size_t>(major_segments) * static_cast<size_t>(minor_segments));
  faces.reserve(2 * vertices.capacity());
  const double two_pi = 2.0 * std::numbers::pi;
  for (int i = 0; i < major_segments; ++i) {
    const double u = two_pi * i / major_segments;
    for (int j = 0; j < minor_segments; ++j) {
      const double v = two_pi * j / minor_segments;
      const double ring = major_radius + minor_radius * std::cos(v);
      vertices.emplace_back(ring * std::cos(u), ring * std::sin(u), minor_radius * std::sin(v));
    }
  }
  auto index = [&](int i, int j) {
    return (i % major_segments) * minor_segments + (j % minor_segments);
  };
  for (int i = 0; i < major_segments; ++i) {
    for (int j = 0; j < minor_segments; ++j) {
      const int a = index(i, j);
      const int b = index(i + 1, j);
      const int c = index(i + 1, j + 1);
      const int d = index(i, j + 1);
      faces.emplace_back(a, b, c);
      faces.emplace_back(a, c, d);
    }
  }
  return from_lists(vertices, faces);
}

IndexedMesh make_cylinder(double radius, double height, int segments) {
  if (segments < 3 || radius <= 0 || height <= 0) {
    throw InvalidInputError("cylinder needs radius > 0, height > 0 and at least 3 segments");
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  vertices.reserve(2 * static_cast<size_t>(segments) + 2);
  faces.reserve(4 * static_cast<size_t>(segments));
  for (int ring = 0; ring < 2; ++ring) {
    for (int i = 0; i < segments; ++i) {
      const double a = 2.0 * std::numbers::pi * i / segments;
      vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), ring * height);
    }
  }
  const int bottom_center = static_cast<int>(vertices.size());
  vertices.emplace_back(0, 0, 0);
  const int top_center = static_cast<int>(vertices.size());
  vertices.emplace_back(0, 0, height);
  for (int i = 0; i < segments; ++i) {
    const int next = (i + 1) % segments;
    faces.emplace_back(i, next, segments + next);
    faces.emplace_back(i, segments + next, segments + i);
    faces.emplace_back(bottom_center, next, i);
    faces.emplace_back(top_center, segments + i, segments + next);
  }
  return from_lists(vertices, faces);
}

}  // namespace mmm::mesh
