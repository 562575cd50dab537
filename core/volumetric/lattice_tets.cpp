#include "core/volumetric/lattice_tets.h"

#include <algorithm>
#include <array>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>

#include "core/errors.h"

namespace mmm::volumetric {
namespace {

using Eigen::Vector3d;

// The six tetrahedra of a cube around its diagonal from corner 0 to corner 7
// (corner bits: x = 1, y = 2, z = 4): one per order in which the path from 0
// to 7 steps along the axes.
constexpr std::array<std::array<int, 4>, 6> kKuhn = {{
    {0, 1, 3, 7},
    {0, 1, 5, 7},
    {0, 2, 3, 7},
    {0, 2, 6, 7},
    {0, 4, 5, 7},
    {0, 4, 6, 7},
}};

double volume_of(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

Vector3d corner_offset(int corner) {
  return {static_cast<double>(corner & 1), static_cast<double>((corner >> 1) & 1),
          static_cast<double>((corner >> 2) & 1)};
}

// The Kuhn tetrahedra with their corners ordered for a positive volume.
std::array<std::array<int, 4>, 6> oriented_kuhn() {
  std::array<std::array<int, 4>, 6> out = kKuhn;
  for (std::array<int, 4>& t : out) {
    if (volume_of(corner_offset(t[0]), corner_offset(t[1]), corner_offset(t[2]),
                  corner_offset(t[3])) < 0) {
      std::swap(t[2], t[3]);
    }
  }
  return out;
}

// Faces of a positively oriented tetrahedron (a, b, c, d), each oriented
// outwards (the opposite corner behind it).
constexpr std::array<std::array<int, 3>, 4> kFaces = {{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

std::uint64_t face_key(std::array<int, 3> f) {
  std::ranges::sort(f);
  return (static_cast<std::uint64_t>(f[0]) << 42) | (static_cast<std::uint64_t>(f[1]) << 21) |
         static_cast<std::uint64_t>(f[2]);
}

}  // namespace

TetMesh lattice_tets(const LabelledLattice& lattice) {
  const Eigen::Array3i nodes_per_axis = lattice.cells + 1;
  const auto grid_node = [&](int i, int j, int k) {
    return (static_cast<std::int64_t>(k) * nodes_per_axis.y() + j) * nodes_per_axis.x() + i;
  };
  std::unordered_map<std::int64_t, int> node_of;
  std::vector<Vector3d> positions;
  std::vector<std::array<int, 4>> tets;
  std::vector<std::uint16_t> labels;
  const std::array<std::array<int, 4>, 6> kuhn = oriented_kuhn();
  for (int k = 0; k < lattice.cells.z(); ++k) {
    for (int j = 0; j < lattice.cells.y(); ++j) {
      for (int i = 0; i < lattice.cells.x(); ++i) {
        const std::uint16_t label = lattice.at(i, j, k);
        if (label == 0) continue;
        std::array<int, 8> corner{};
        for (int c = 0; c < 8; ++c) {
          const int ci = i + (c & 1);
          const int cj = j + ((c >> 1) & 1);
          const int ck = k + ((c >> 2) & 1);
          const auto [it, added] =
              node_of.try_emplace(grid_node(ci, cj, ck), static_cast<int>(positions.size()));
          if (added) {
            positions.emplace_back(lattice.origin + lattice.spacing_mm * Vector3d(ci, cj, ck));
          }
          corner[static_cast<std::size_t>(c)] = it->second;
        }
        for (const std::array<int, 4>& t : kuhn) {
          tets.push_back(
              {corner[static_cast<std::size_t>(t[0])], corner[static_cast<std::size_t>(t[1])],
               corner[static_cast<std::size_t>(t[2])], corner[static_cast<std::size_t>(t[3])]});
          labels.push_back(label);
        }
      }
    }
  }
  TetMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    mesh.V.row(static_cast<Eigen::Index>(v)) = positions[v].transpose();
  }
  mesh.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (int c = 0; c < 4; ++c) mesh.T(static_cast<Eigen::Index>(t), c) = tets[t][c];
  }
  mesh.label = std::move(labels);
  return mesh;
}

Eigen::VectorXd tet_volumes(const TetMesh& mesh) {
  Eigen::VectorXd out(mesh.T.rows());
  for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
    out[t] = volume_of(mesh.V.row(mesh.T(t, 0)).transpose(), mesh.V.row(mesh.T(t, 1)).transpose(),
                       mesh.V.row(mesh.T(t, 2)).transpose(), mesh.V.row(mesh.T(t, 3)).transpose());
  }
  return out;
}

mesh::IndexedMesh label_boundary(const TetMesh& mesh, std::uint16_t label) {
  // Each face of the label's tetrahedra, by its sorted corners: a face seen
  // twice lies between two of them and is inside.
  std::unordered_map<std::uint64_t, std::pair<std::array<int, 3>, int>> faces;
  for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.label[static_cast<std::size_t>(t)] != label) continue;
    for (const std::array<int, 3>& f : kFaces) {
      const std::array<int, 3> face = {mesh.T(t, f[0]), mesh.T(t, f[1]), mesh.T(t, f[2])};
      auto [it, added] = faces.try_emplace(face_key(face), face, 0);
      ++it->second.second;
    }
  }
  if (faces.empty()) {
    throw InvalidInputError("tet mesh: no tetrahedron has label " + std::to_string(label));
  }
  std::vector<std::array<int, 3>> boundary;
  for (const auto& [key, face] : faces) {
    if (face.second == 1) boundary.push_back(face.first);
  }
  std::ranges::sort(boundary);  // the same surface whatever the hash order
  mesh::IndexedMesh out;
  out.V = mesh.V;
  out.F.resize(static_cast<Eigen::Index>(boundary.size()), 3);
  for (std::size_t f = 0; f < boundary.size(); ++f) {
    for (int c = 0; c < 3; ++c) out.F(static_cast<Eigen::Index>(f), c) = boundary[f][c];
  }
  return out;
}

}  // namespace mmm::volumetric
