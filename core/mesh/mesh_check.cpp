#include "core/mesh/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/mesh/mass_properties.h"

namespace mmm::mesh {
namespace {

class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  size_t find(size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void unite(size_t a, size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<size_t> parent_;
};

uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<uint64_t>(std::min(a, b));
  const auto hi = static_cast<uint64_t>(std::max(a, b));
  return (lo << 32U) | hi;
}

// One face's use of an undirected edge: the face, its corner where the edge
// starts, and whether it runs lo -> hi.
struct EdgeUse {
  Eigen::Index face;
  int corner;
  bool forward;
};

using EdgeMap = std::unordered_map<uint64_t, std::vector<EdgeUse>>;

EdgeMap collect_edges(const IndexedMesh& mesh) {
  EdgeMap edges;
  edges.reserve(static_cast<size_t>(mesh.F.rows()) * 2);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k);
      const int b = mesh.F(f, (k + 1) % 3);
      if (a == b) continue;
      edges[edge_key(a, b)].push_back({f, k, a < b});
    }
  }
  return edges;
}

Eigen::Index count_duplicates(const IndexedMesh& mesh, double distance) {
  // Hash grid with cells of the tolerance size; a duplicate lies in one of
  // the 27 cells around a vertex.
  const double cell = std::max(distance, 1e-300);
  struct Key {
    int64_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      return static_cast<size_t>(k.x * 73856093 ^ k.y * 19349663 ^ k.z * 83492791);
    }
  };
  std::unordered_map<Key, std::vector<Eigen::Index>, KeyHash> grid;
  grid.reserve(static_cast<size_t>(mesh.V.rows()));
  Eigen::Index duplicates = 0;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Eigen::Vector3d p = mesh.V.row(v);
    const Key key{static_cast<int64_t>(std::floor(p.x() / cell)),
                  static_cast<int64_t>(std::floor(p.y() / cell)),
                  static_cast<int64_t>(std::floor(p.z() / cell))};
    bool duplicate = false;
    for (int64_t dx = -1; dx <= 1 && !duplicate; ++dx) {
      for (int64_t dy = -1; dy <= 1 && !duplicate; ++dy) {
        for (int64_t dz = -1; dz <= 1 && !duplicate; ++dz) {
          const auto it = grid.find({key.x + dx, key.y + dy, key.z + dz});
          if (it == grid.end()) continue;
          for (const Eigen::Index other : it->second) {
            if ((mesh.V.row(other) - mesh.V.row(v)).norm() <= distance) {
              duplicate = true;
              break;
            }
          }
        }
      }
    }
    if (duplicate) ++duplicates;
    grid[key].push_back(v);
  }
  return duplicates;
}

}  // namespace

MeshCheckReport check_mesh(const IndexedMesh& mesh, const MeshCheckOptions& options) {
  validate_indices_and_coordinates(mesh);
  MeshCheckReport report;
  report.vertices = mesh.V.rows();
  report.faces = mesh.F.rows();
  const auto num_vertices = static_cast<size_t>(mesh.V.rows());

  // Degenerate faces: repeated vertex or (near) zero area.
  const double diagonal = mesh.V.rows() > 0 ? bounding_box(mesh).diagonal().norm() : 0.0;
  const double min_area = options.degenerate_area_fraction * diagonal * diagonal;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    const bool repeated = mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) ||
                          mesh.F(f, 0) == mesh.F(f, 2);
    if (repeated || 0.5 * (b - a).cross(c - a).norm() <= min_area) ++report.degenerate_faces;
  }

  // Edges: boundary, non-manifold, orientation; corner fans for vertices.
  const EdgeMap edges = collect_edges(mesh);
  report.edges = static_cast<Eigen::Index>(edges.size());
  UnionFind corner_fans(static_cast<size_t>(mesh.F.rows()) * 3);
  UnionFind boundary_graph(num_vertices);
  std::vector<bool> on_boundary(num_vertices, false);
  auto corner_of = [&](Eigen::Index f, int vertex) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.F(f, k) == vertex) return static_cast<size_t>(f) * 3 + static_cast<size_t>(k);
    }
    return static_cast<size_t>(f) * 3;  // unreachable: the edge belongs to f
  };
  for (const auto& [key, uses] : edges) {
    const auto lo = static_cast<int>(key >> 32U);
    const auto hi = static_cast<int>(key & 0xffffffffU);
    if (uses.size() == 1) {
      ++report.boundary_edges;
      boundary_graph.unite(static_cast<size_t>(lo), static_cast<size_t>(hi));
      on_boundary[static_cast<size_t>(lo)] = on_boundary[static_cast<size_t>(hi)] = true;
    } else if (uses.size() > 2) {
      ++report.non_manifold_edges;
    } else {
      if (uses[0].forward == uses[1].forward) ++report.inconsistently_oriented_edges;
      for (const int vertex : {lo, hi}) {
        corner_fans.unite(corner_of(uses[0].face, vertex), corner_of(uses[1].face, vertex));
      }
    }
  }

  // Vertices: fans around each, referenced or not.
  std::vector<std::vector<size_t>> fan_roots(num_vertices);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      fan_roots[static_cast<size_t>(mesh.F(f, k))].push_back(
          corner_fans.find(static_cast<size_t>(f) * 3 + static_cast<size_t>(k)));
    }
  }
  Eigen::Index referenced = 0;
  for (auto& roots : fan_roots) {
    if (roots.empty()) {
      ++report.unreferenced_vertices;
      continue;
    }
    ++referenced;
    std::sort(roots.begin(), roots.end());
    if (std::unique(roots.begin(), roots.end()) - roots.begin() > 1) {
      ++report.non_manifold_vertices;
    }
  }

  // Boundary loops and connected components.
  std::vector<bool> seen_loop(num_vertices, false);
  for (size_t v = 0; v < num_vertices; ++v) {
    if (!on_boundary[v]) continue;
    const size_t root = boundary_graph.find(v);
    if (!seen_loop[root]) {
      seen_loop[root] = true;
      ++report.boundary_loops;
    }
  }
  UnionFind components(num_vertices);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    components.unite(static_cast<size_t>(mesh.F(f, 0)), static_cast<size_t>(mesh.F(f, 1)));
    components.unite(static_cast<size_t>(mesh.F(f, 1)), static_cast<size_t>(mesh.F(f, 2)));
  }
  std::vector<bool> seen_component(num_vertices, false);
  for (size_t v = 0; v < num_vertices; ++v) {
    if (fan_roots[v].empty()) continue;
    const size_t root = components.find(v);
    if (!seen_component[root]) {
      seen_component[root] = true;
      ++report.connected_components;
    }
  }

  report.duplicate_vertices = count_duplicates(mesh, options.duplicate_vertex_distance);
  report.euler_characteristic = referenced - report.edges + report.faces;
  return report;
}

std::vector<std::string> MeshCheckReport::problems() const {
  std::vector<std::string> out;
  auto add = [&out](Eigen::Index count, const std::string& what) {
    if (count > 0) out.push_back(std::to_string(count) + " " + what);
  };
  if (faces == 0) out.emplace_back("no faces");
  add(boundary_edges, "boundary edges in " + std::to_string(boundary_loops) +
                          " loop(s): the surface is open (holes)");
  add(non_manifold_edges, "non-manifold edges (shared by more than two faces)");
  add(non_manifold_vertices, "non-manifold vertices (faces around them form several fans)");
  add(inconsistently_oriented_edges,
      "edges whose two faces are oriented inconsistently (flipped faces)");
  add(degenerate_faces, "degenerate faces (zero area or repeated vertex)");
  add(duplicate_vertices, "duplicate vertices (distinct indices, same position)");
  add(unreferenced_vertices, "vertices used by no face");
  return out;
}

}  // namespace mmm::mesh
