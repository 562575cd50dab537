#include "core/image/silhouette.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::image {
namespace {

// The edges chained into vertex paths: first the open chains, each from a
// vertex of degree != 2 (in edge order), then the closed loops (first vertex
// repeated at the end).
std::vector<std::vector<int>> chain_edges(const std::vector<std::array<int, 2>>& edges) {
  std::vector<int> vertices;
  for (const auto& [a, b] : edges) vertices.insert(vertices.end(), {a, b});
  std::ranges::sort(vertices);
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  const auto slot = [&](int v) {
    return static_cast<std::size_t>(std::ranges::lower_bound(vertices, v) - vertices.begin());
  };
  std::vector<std::vector<std::size_t>> incident(vertices.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    incident[slot(edges[e][0])].push_back(e);
    incident[slot(edges[e][1])].push_back(e);
  }
  std::vector<bool> used(edges.size(), false);
  std::vector<std::vector<int>> chains;
  const auto walk = [&](int start, std::size_t first_edge) {
    std::vector<int> chain = {start};
    int at = start;
    std::size_t edge = first_edge;
    while (true) {
      used[edge] = true;
      at = edges[edge][0] == at ? edges[edge][1] : edges[edge][0];
      chain.push_back(at);
      const std::vector<std::size_t>& next = incident[slot(at)];
      if (next.size() != 2) break;  // an end, or a junction: the chain stops
      const std::size_t other = next[0] == edge ? next[1] : next[0];
      if (used[other]) break;  // the loop closed
      edge = other;
    }
    chains.push_back(std::move(chain));
  };
  for (const bool open : {true, false}) {
    for (std::size_t e = 0; e < edges.size(); ++e) {
      if (used[e]) continue;
      for (const int end : edges[e]) {
        if (used[e]) break;
        if (!open || incident[slot(end)].size() != 2) walk(end, e);
      }
    }
  }
  return chains;
}

}  // namespace

std::vector<Eigen::Vector2d> project_face_vertices(const RadiographView& view,
                                                   const mesh::IndexedMesh& surface,
                                                   const std::string& what) {
  const double sign = view.P.leftCols<3>().determinant() > 0 ? 1.0 : -1.0;
  std::vector<bool> used(static_cast<std::size_t>(surface.V.rows()), false);
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(surface.F(f, k))] = true;
  }
  std::vector<Eigen::Vector2d> pixels(used.size(), Eigen::Vector2d::Zero());
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v) {
    if (!used[static_cast<std::size_t>(v)]) continue;
    const Eigen::Vector3d p = surface.V.row(v).transpose();
    const Eigen::Vector3d h = view.P * p.homogeneous();
    if (!(sign * h.z() > 0)) {
      throw InvalidInputError(what + ": view '" + view.name + "': vertex " + std::to_string(v) +
                              " (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                              std::to_string(p.z()) +
                              ") lies on or behind the source plane (wrong frame or units?)");
    }
    pixels[static_cast<std::size_t>(v)] = project(view, p);
  }
  return pixels;
}

namespace {

std::vector<std::array<int, 2>> silhouette_edges_from(
    const mesh::IndexedMesh& surface,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& source_of) {
  const Eigen::Index faces = surface.F.rows();
  std::vector<int> side(static_cast<std::size_t>(faces));
  for (Eigen::Index f = 0; f < faces; ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose();
    const Eigen::Vector3d b = surface.V.row(surface.F(f, 1)).transpose();
    const Eigen::Vector3d c = surface.V.row(surface.F(f, 2)).transpose();
    const Eigen::Vector3d centroid = (a + b + c) / 3.0;
    const double facing = (b - a).cross(c - a).dot(centroid - source_of(centroid));
    side[static_cast<std::size_t>(f)] = (facing > 0) - (facing < 0);
  }
  struct Corner {
    int low = 0;
    int high = 0;
    int face = 0;
  };
  std::vector<Corner> corners;
  corners.reserve(static_cast<std::size_t>(3 * faces));
  for (Eigen::Index f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int u = surface.F(f, k);
      const int v = surface.F(f, (k + 1) % 3);
      corners.push_back({std::min(u, v), std::max(u, v), static_cast<int>(f)});
    }
  }
  std::ranges::sort(corners, [](const Corner& p, const Corner& q) {
    return p.low != q.low ? p.low < q.low : p.high < q.high;
  });
  std::vector<std::array<int, 2>> edges;
  for (std::size_t begin = 0; begin < corners.size();) {
    std::size_t end = begin;
    bool front = false;
    bool back = false;
    while (end < corners.size() && corners[end].low == corners[begin].low &&
           corners[end].high == corners[begin].high) {
      const int s = side[static_cast<std::size_t>(corners[end].face)];
      front = front || s < 0;
      back = back || s > 0;
      ++end;
    }
    if (end - begin == 1 || (front && back)) {
      edges.push_back({corners[begin].low, corners[begin].high});
    }
    begin = end;
  }
  return edges;
}

}  // namespace

std::vector<std::array<int, 2>> silhouette_edges(const mesh::IndexedMesh& surface,
                                                 const Eigen::Vector3d& source) {
  return silhouette_edges_from(surface, [&](const Eigen::Vector3d&) { return source; });
}

std::vector<std::array<int, 2>> silhouette_edges(const mesh::IndexedMesh& surface,
                                                 const RadiographView& view) {
  return silhouette_edges_from(surface,
                               [&](const Eigen::Vector3d& x) { return source_for(view, x); });
}

std::vector<std::array<int, 2>> keep_contour_pieces(const std::vector<std::array<int, 2>>& edges,
                                                    int min_edges) {
  if (min_edges <= 1 || edges.empty()) return edges;
  // Union-find over the vertices the edges touch (path halving).
  std::vector<int> vertices;
  for (const auto& [a, b] : edges) vertices.insert(vertices.end(), {a, b});
  std::ranges::sort(vertices);
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  const auto slot = [&](int v) {
    return static_cast<std::size_t>(std::ranges::lower_bound(vertices, v) - vertices.begin());
  };
  std::vector<std::size_t> parent(vertices.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  const auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& [a, b] : edges) parent[root(slot(a))] = root(slot(b));
  std::vector<int> size(vertices.size(), 0);
  for (const auto& edge : edges) ++size[root(slot(edge[0]))];
  // The largest pieces are always kept: a box's whole outline has 4 to 6 edges.
  const int threshold = std::min(min_edges, *std::ranges::max_element(size));
  std::vector<std::array<int, 2>> kept;
  for (const auto& edge : edges) {
    if (size[root(slot(edge[0]))] >= threshold) kept.push_back(edge);
  }
  return kept;
}

std::vector<Polyline2d> silhouette_polylines(const mesh::IndexedMesh& surface,
                                             const RadiographView& view, int min_contour_edges) {
  if (min_contour_edges < 1) {
    throw InvalidInputError("silhouette_polylines: min_contour_edges must be >= 1, got " +
                            std::to_string(min_contour_edges));
  }
  validate_view(view);
  mesh::validate_indices_and_coordinates(surface);
  std::vector<Polyline2d> polylines;
  if (surface.F.rows() == 0) return polylines;
  const std::vector<Eigen::Vector2d> pixels =
      project_face_vertices(view, surface, "silhouette_polylines");
  const std::vector<std::array<int, 2>> edges =
      keep_contour_pieces(silhouette_edges(surface, view), min_contour_edges);
  for (const std::vector<int>& chain : chain_edges(edges)) {
    Polyline2d polyline;
    polyline.reserve(chain.size());
    for (const int v : chain) polyline.push_back(pixels[static_cast<std::size_t>(v)]);
    polylines.push_back(std::move(polyline));
  }
  return polylines;
}

}  // namespace mmm::image
