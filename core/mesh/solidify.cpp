#include "core/mesh/solidify.h"

#include <array>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/winding_number.h"

namespace mmm::mesh {
namespace {

// Cube corners: bit 0 -> +x, bit 1 -> +y, bit 2 -> +z.
constexpr std::array<std::array<int, 3>, 8> kCorner = {
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
// Six tetrahedra sharing the diagonal 0-6.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra = {
    {{0, 5, 1, 6}, {0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}}};

class Grid {
 public:
  Grid(Eigen::Vector3d origin, double h, std::array<long, 3> n)
      : origin_(std::move(origin)), h_(h), n_(n) {}
  [[nodiscard]] long index(long i, long j, long k) const { return (k * n_[1] + j) * n_[0] + i; }
  [[nodiscard]] Eigen::Vector3d point(long i, long j, long k) const {
    return origin_ + h_ * Eigen::Vector3d(static_cast<double>(i), static_cast<double>(j),
                                          static_cast<double>(k));
  }
  [[nodiscard]] Eigen::Vector3d point(long index) const {
    const long i = index % n_[0];
    const long j = (index / n_[0]) % n_[1];
    const long k = index / (n_[0] * n_[1]);
    return point(i, j, k);
  }
  [[nodiscard]] const std::array<long, 3>& size() const { return n_; }

 private:
  Eigen::Vector3d origin_;
  double h_;
  std::array<long, 3> n_;
};

struct EdgeKey {
  long a;
  long b;
  bool operator==(const EdgeKey&) const = default;
};
struct EdgeHash {
  std::size_t operator()(const EdgeKey& key) const {
    return std::hash<long>()(key.a) * 1000003U ^ std::hash<long>()(key.b);
  }
};

}  // namespace

IndexedMesh solidify(const IndexedMesh& mesh, const SolidifyOptions& options) {
  validate_indices_and_coordinates(mesh);
  if (mesh.F.rows() == 0) throw InvalidInputError("solidify: the mesh has no face");
  const double h = options.grid_spacing_mm;
  if (!(h > 0) || !std::isfinite(h)) {
    throw InvalidInputError("solidify: grid_spacing_mm must be a positive number");
  }
  if (options.padding_cells < 1) {
    throw InvalidInputError(
        "solidify: padding_cells must be >= 1 (the grid's outer layer must "
        "lie outside the solid for the surface to close)");
  }
  const AabbTree tree(mesh);
  const WindingNumber winding(tree);
  const Eigen::AlignedBox3d box = bounding_box(mesh);
  const double pad = h * options.padding_cells;
  const Eigen::Vector3d origin = box.min() - Eigen::Vector3d::Constant(pad);
  std::array<long, 3> n{};
  for (int d = 0; d < 3; ++d) {
    n[static_cast<std::size_t>(d)] =
        static_cast<long>(std::ceil((box.max()(d) - box.min()(d) + 2 * pad) / h)) + 1;
  }
  if (static_cast<double>(n[0]) * static_cast<double>(n[1]) * static_cast<double>(n[2]) > 5e7) {
    throw InvalidInputError(
        "solidify: the grid would exceed 50 million points; use a larger "
        "grid_spacing_mm");
  }
  const Grid grid(origin, h, n);
  std::vector<double> value(static_cast<std::size_t>(n[0] * n[1] * n[2]));
  for (long k = 0; k < n[2]; ++k) {
    for (long j = 0; j < n[1]; ++j) {
      for (long i = 0; i < n[0]; ++i) {
        value[static_cast<std::size_t>(grid.index(i, j, k))] =
            std::abs(winding.at(grid.point(i, j, k))) - 0.5;
      }
    }
  }
  std::vector<Eigen::Vector3d> vertices;
  // The midpoint of each vertex's grid edge: orientation is decided on these
  // (never degenerate), as interpolated vertices coincide where w = 1/2 at a
  // grid point (faces on grid planes) and their normals are rounding noise.
  std::vector<Eigen::Vector3d> midpoints;
  std::vector<Eigen::Vector3i> faces;
  std::unordered_map<EdgeKey, int, EdgeHash> edge_vertex;
  const auto crossing = [&](long a, long b) {
    const EdgeKey key{std::min(a, b), std::max(a, b)};
    const auto found = edge_vertex.find(key);
    if (found != edge_vertex.end()) return found->second;
    const double va = value[static_cast<std::size_t>(a)];
    const double vb = value[static_cast<std::size_t>(b)];
    const double t = va / (va - vb);
    vertices.emplace_back((1 - t) * grid.point(a) + t * grid.point(b));
    midpoints.emplace_back(0.5 * (grid.point(a) + grid.point(b)));
    const int index = static_cast<int>(vertices.size()) - 1;
    edge_vertex.emplace(key, index);
    return index;
  };
  const auto emit = [&](int p, int q, int r, const Eigen::Vector3d& inside_point,
                        const Eigen::Vector3d& outside_point) {
    const Eigen::Vector3d normal =
        (midpoints[static_cast<std::size_t>(q)] - midpoints[static_cast<std::size_t>(p)])
            .cross(midpoints[static_cast<std::size_t>(r)] - midpoints[static_cast<std::size_t>(p)]);
    if (normal.dot(outside_point - inside_point) >= 0) {
      faces.emplace_back(p, q, r);
    } else {
      faces.emplace_back(p, r, q);
    }
  };
  for (long k = 0; k + 1 < n[2]; ++k) {
    for (long j = 0; j + 1 < n[1]; ++j) {
      for (long i = 0; i + 1 < n[0]; ++i) {
        std::array<long, 8> corner{};
        for (std::size_t c = 0; c < 8; ++c) {
          corner[c] = grid.index(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2]);
        }
        for (const auto& tet : kTetrahedra) {
          std::array<long, 4> in{};
          std::array<long, 4> out{};
          int n_in = 0;
          int n_out = 0;
          for (const int c : tet) {
            const long g = corner[static_cast<std::size_t>(c)];
            if (value[static_cast<std::size_t>(g)] > 0) {
              in[static_cast<std::size_t>(n_in++)] = g;
            } else {
              out[static_cast<std::size_t>(n_out++)] = g;
            }
          }
          if (n_in == 0 || n_out == 0) continue;
          if (n_in == 1 || n_out == 1) {
            const bool single_inside = n_in == 1;
            const long apex = single_inside ? in[0] : out[0];
            const auto& others = single_inside ? out : in;
            const int a = crossing(apex, others[0]);
            const int b = crossing(apex, others[1]);
            const int c = crossing(apex, others[2]);
            const Eigen::Vector3d apex_point = grid.point(apex);
            const Eigen::Vector3d base =
                (grid.point(others[0]) + grid.point(others[1]) + grid.point(others[2])) / 3.0;
            emit(a, b, c, single_inside ? apex_point : base, single_inside ? base : apex_point);
          } else {  // two inside, two outside: a quad
            const int a = crossing(in[0], out[0]);
            const int b = crossing(in[0], out[1]);
            const int c = crossing(in[1], out[1]);
            const int d = crossing(in[1], out[0]);
            const Eigen::Vector3d inside_point = 0.5 * (grid.point(in[0]) + grid.point(in[1]));
            const Eigen::Vector3d outside_point = 0.5 * (grid.point(out[0]) + grid.point(out[1]));
            emit(a, b, c, inside_point, outside_point);
            emit(a, c, d, inside_point, outside_point);
          }
        }
      }
    }
  }
  IndexedMesh result;
  result.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    result.V.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  }
  result.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    result.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  }
  return result;
}

}  // namespace mmm::mesh
