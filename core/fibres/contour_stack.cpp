#include "core/fibres/contour_stack.h"

#include <algorithm>
#include <optional>
#include <string>

#include "core/errors.h"
#include "core/fibres/contour_map.h"
#include "core/fibres/iso_lines.h"

namespace mmm::fibres {
namespace {

// The closed contour nearest the middle level keeps its start (on the side
// of the reference); every other one takes the start that best matches its
// already aligned neighbour toward the middle (align_start).
void align_starts(std::vector<std::optional<Contour>>& found) {
  const std::size_t n = found.size();
  std::size_t anchor = n;
  for (std::size_t step = 0; step < n && anchor == n; ++step) {
    for (const std::size_t k : {n / 2 - std::min(step, n / 2), n / 2 + step}) {
      if (k < n && found[k]) {
        anchor = k;
        break;
      }
    }
  }
  const Contour* previous = &*found[anchor];
  for (std::size_t k = anchor + 1; k < n; ++k) {
    if (found[k]) {
      found[k] = align_start(*found[k], *previous);
      previous = &*found[k];
    }
  }
  previous = &*found[anchor];
  for (std::size_t k = anchor; k-- > 0;) {
    if (found[k]) {
      found[k] = align_start(*found[k], *previous);
      previous = &*found[k];
    }
  }
}

}  // namespace

ContourStack contour_stack(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                           const std::vector<double>& levels, const Eigen::Vector3d& reference,
                           int contour_points) {
  std::vector<std::optional<Contour>> found(levels.size());
  int closed = 0;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const Eigen::MatrixX3d loop = largest_loop(iso_lines(surface, values, levels[k]));
    if (loop.rows() >= 3 && enclosed_area(loop) > 0.0) {
      found[k] = consistent_contour(loop, vector_area(loop), reference, contour_points);
      ++closed;
    }
  }
  if (closed < 2) {
    throw InvalidInputError("slicing: only " + std::to_string(closed) + " of " +
                            std::to_string(levels.size()) +
                            " levels cut the muscle in a closed loop; is the surface closed and "
                            "do its attachment areas lie at its two ends?");
  }
  align_starts(found);
  ContourStack stack;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (found[k]) {
      stack.contours.push_back(*found[k]);
      continue;
    }
    ++stack.interpolated;
    // The nearest closed levels below and above (or the one on one side).
    std::optional<std::size_t> below;
    std::optional<std::size_t> above;
    for (std::size_t j = k; j-- > 0;) {
      if (found[j]) {
        below = j;
        break;
      }
    }
    for (std::size_t j = k + 1; j < levels.size(); ++j) {
      if (found[j]) {
        above = j;
        break;
      }
    }
    if (below && above) {
      const double w = (levels[k] - levels[*below]) / (levels[*above] - levels[*below]);
      stack.contours.emplace_back((1.0 - w) * *found[*below] + w * *found[*above]);
    } else {
      stack.contours.push_back(*found[below ? *below : *above]);
    }
  }
  return stack;
}

}  // namespace mmm::fibres
