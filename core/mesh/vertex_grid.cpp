#include "core/mesh/vertex_grid.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/errors.h"

namespace mmm::mesh {

VertexGrid::VertexGrid(const Eigen::MatrixX3d& points, double points_per_cell) : points_(points) {
  if (points.rows() == 0) throw InvalidInputError("vertex grid: no points");
  if (!points.allFinite()) throw InvalidInputError("vertex grid: a point is not finite");
  const Eigen::Vector3d low = points.colwise().minCoeff().transpose();
  const Eigen::Vector3d high = points.colwise().maxCoeff().transpose();
  const Eigen::Vector3d extent = (high - low).cwiseMax(1e-9);
  // Cells of equal size holding about points_per_cell points if the points
  // filled the box; surfaces fill it far less, which only makes cells sparser.
  const double volume = extent.prod();
  const double cells = std::max(1.0, static_cast<double>(points.rows()) / points_per_cell);
  cell_size_ = std::max(std::cbrt(volume / cells), extent.maxCoeff() / 256.0);
  origin_ = low;
  for (int axis = 0; axis < 3; ++axis) {
    dims_[axis] = std::max(1, static_cast<int>(std::ceil(extent[axis] / cell_size_)) + 1);
  }
  const auto flat = [&](const Eigen::Vector3i& c) {
    return (c.z() * dims_.y() + c.y()) * dims_.x() + c.x();
  };
  std::vector<int> cell(static_cast<std::size_t>(points.rows()));
  cell_start_.assign(static_cast<std::size_t>(dims_.prod()) + 1, 0);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    cell[static_cast<std::size_t>(i)] = flat(cell_of(points.row(i).transpose()));
    ++cell_start_[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]) + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  order_.resize(cell.size());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < cell.size(); ++i) {
    order_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell[i])]++)] =
        static_cast<int>(i);
  }
}

Eigen::Vector3i VertexGrid::cell_of(const Eigen::Vector3d& point) const {
  Eigen::Vector3i c;
  for (int axis = 0; axis < 3; ++axis) {
    const int index = static_cast<int>(std::floor((point[axis] - origin_[axis]) / cell_size_));
    c[axis] = std::clamp(index, 0, dims_[axis] - 1);
  }
  return c;
}

std::vector<int> VertexGrid::nearest(const Eigen::Vector3d& query, int k) const {
  k = std::min<int>(k, static_cast<int>(points_.rows()));
  if (k <= 0) return {};
  const Eigen::Vector3i centre = cell_of(query);
  // Distance from the query to the outside of the box of cells within
  // `shell` of the centre cell: every unvisited point is at least this far.
  const auto reach = [&](int shell) {
    double nearest_wall = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
      const double low = origin_[axis] + (centre[axis] - shell) * cell_size_;
      const double high = origin_[axis] + (centre[axis] + shell + 1) * cell_size_;
      if (centre[axis] - shell > 0) nearest_wall = std::min(nearest_wall, query[axis] - low);
      if (centre[axis] + shell < dims_[axis] - 1) {
        nearest_wall = std::min(nearest_wall, high - query[axis]);
      }
    }
    return nearest_wall;
  };
  std::vector<std::pair<double, int>> found;
  const int max_shell = dims_.maxCoeff();
  for (int shell = 0; shell <= max_shell; ++shell) {
    for (int z = centre.z() - shell; z <= centre.z() + shell; ++z) {
      if (z < 0 || z >= dims_.z()) continue;
      for (int y = centre.y() - shell; y <= centre.y() + shell; ++y) {
        if (y < 0 || y >= dims_.y()) continue;
        for (int x = centre.x() - shell; x <= centre.x() + shell; ++x) {
          if (x < 0 || x >= dims_.x()) continue;
          const bool on_shell = std::abs(x - centre.x()) == shell ||
                                std::abs(y - centre.y()) == shell ||
                                std::abs(z - centre.z()) == shell;
          if (!on_shell) continue;
          const int c = (z * dims_.y() + y) * dims_.x() + x;
          for (int s = cell_start_[static_cast<std::size_t>(c)];
               s < cell_start_[static_cast<std::size_t>(c) + 1]; ++s) {
            const int i = order_[static_cast<std::size_t>(s)];
            found.emplace_back((points_.row(i).transpose() - query).squaredNorm(), i);
          }
        }
      }
    }
    if (static_cast<int>(found.size()) >= k) {
      std::nth_element(found.begin(), found.begin() + (k - 1), found.end());
      const double kth = found[static_cast<std::size_t>(k - 1)].first;
      const double wall = reach(shell);
      if (kth <= wall * wall) break;
    }
  }
  std::partial_sort(found.begin(), found.begin() + k, found.end());
  std::vector<int> rows(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i)
    rows[static_cast<std::size_t>(i)] = found[static_cast<std::size_t>(i)].second;
  return rows;
}

}  // namespace mmm::mesh
