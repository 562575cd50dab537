#include "core/fibres/iso_lines.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;
using Eigen::Vector3d;

constexpr int kNone = -1;

// The crossing points of the level set, one per crossing edge, and the
// directed segments between them (one per face the level set crosses).
struct Crossings {
  std::vector<Vector3d> points;
  std::vector<int> next;
  std::vector<int> previous;
  std::vector<bool> branching;  // a non-manifold edge: more than one segment leaves or enters
};

std::int64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::int64_t>(std::min(a, b));
  const auto hi = static_cast<std::int64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

void link(Crossings& crossings, int from, int to) {
  auto& out = crossings.next[static_cast<std::size_t>(from)];
  auto& in = crossings.previous[static_cast<std::size_t>(to)];
  if (out != kNone) {
    crossings.branching[static_cast<std::size_t>(from)] = true;
  } else {
    out = to;
  }
  if (in != kNone) {
    crossings.branching[static_cast<std::size_t>(to)] = true;
  } else {
    in = from;
  }
}

Crossings find_crossings(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                         double level) {
  Crossings crossings;
  std::unordered_map<std::int64_t, int> point_of_edge;
  const auto point_on = [&](int a, int b) {
    const auto [it, inserted] =
        point_of_edge.try_emplace(edge_key(a, b), static_cast<int>(crossings.points.size()));
    if (inserted) {
      const double fa = values(a) - level;
      const double fb = values(b) - level;
      const double w = fa / (fa - fb);  // fa and fb differ in sign: w in [0, 1]
      crossings.points.emplace_back((1.0 - w) * surface.V.row(a).transpose() +
                                    w * surface.V.row(b).transpose());
      crossings.next.push_back(kNone);
      crossings.previous.push_back(kNone);
      crossings.branching.push_back(false);
    }
    return it->second;
  };
  for (Index f = 0; f < surface.F.rows(); ++f) {
    int going_down = kNone;  // crossing on the edge (in face order) from above to below
    int going_up = kNone;
    for (int e = 0; e < 3; ++e) {
      const int a = surface.F(f, e);
      const int b = surface.F(f, (e + 1) % 3);
      const bool a_above = values(a) >= level;
      if (a_above != (values(b) >= level)) {
        (a_above ? going_down : going_up) = point_on(a, b);
      }
    }
    // Seen from outside, the segment from the downward to the upward
    // crossing has the higher values on its left.
    if (going_down != kNone && going_up != kNone) {
      link(crossings, going_down, going_up);
    }
  }
  return crossings;
}

IsoLine walk(const Crossings& crossings, int start, std::vector<bool>& visited) {
  std::vector<int> order{start};
  visited[static_cast<std::size_t>(start)] = true;
  int current = start;
  bool closed = false;
  while (!crossings.branching[static_cast<std::size_t>(current)]) {
    const int next = crossings.next[static_cast<std::size_t>(current)];
    if (next == kNone) {
      break;
    }
    if (next == start) {
      closed = true;
      break;
    }
    if (visited[static_cast<std::size_t>(next)]) {
      break;
    }
    visited[static_cast<std::size_t>(next)] = true;
    order.push_back(next);
    current = next;
  }
  IsoLine line;
  line.closed = closed && order.size() >= 3;
  line.points.resize(static_cast<Index>(order.size()), 3);
  for (std::size_t i = 0; i < order.size(); ++i) {
    line.points.row(static_cast<Index>(i)) =
        crossings.points[static_cast<std::size_t>(order[i])].transpose();
  }
  return line;
}

}  // namespace

std::vector<IsoLine> iso_lines(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                               double level) {
  if (values.size() != surface.V.rows()) {
    throw InvalidInputError("iso_lines: " + std::to_string(values.size()) + " values for " +
                            std::to_string(surface.V.rows()) +
                            " vertices; give one value per vertex");
  }
  if (!std::isfinite(level) || !values.allFinite()) {
    throw InvalidInputError("iso_lines: the level and every value must be finite");
  }
  mesh::validate_indices_and_coordinates(surface);
  const Crossings crossings = find_crossings(surface, values, level);
  std::vector<bool> visited(crossings.points.size(), false);
  std::vector<IsoLine> lines;
  // Open chains first, from their starts, so that none is entered midway.
  for (std::size_t i = 0; i < crossings.points.size(); ++i) {
    const bool chain_start = crossings.previous[i] == kNone || crossings.branching[i];
    if (!visited[i] && chain_start) {
      lines.push_back(walk(crossings, static_cast<int>(i), visited));
    }
  }
  for (std::size_t i = 0; i < crossings.points.size(); ++i) {
    if (!visited[i]) {
      lines.push_back(walk(crossings, static_cast<int>(i), visited));
    }
  }
  return lines;
}

Eigen::Vector3d vector_area(const Eigen::MatrixX3d& loop) {
  Vector3d sum = Vector3d::Zero();
  const Index n = loop.rows();
  for (Index i = 0; i < n; ++i) {
    sum += loop.row(i).transpose().cross(loop.row((i + 1) % n).transpose());
  }
  return 0.5 * sum;
}

double enclosed_area(const Eigen::MatrixX3d& loop) { return vector_area(loop).norm(); }

Eigen::MatrixX3d largest_loop(const std::vector<IsoLine>& lines) {
  const IsoLine* best = nullptr;
  double best_area = -1.0;
  for (const IsoLine& line : lines) {
    if (line.closed) {
      const double area = enclosed_area(line.points);
      if (area > best_area) {
        best_area = area;
        best = &line;
      }
    }
  }
  return best != nullptr ? best->points : Eigen::MatrixX3d();
}

}  // namespace mmm::fibres
