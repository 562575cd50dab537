#include "core/outlines/fit_rows.h"

namespace mmm::outlines {

double add_point(FitRow& row, const Eigen::Vector3d& a, const Eigen::Vector3d& rest,
                 const Eigen::Vector3d& centre, const std::vector<std::pair<int, double>>& w,
                 double scale) {
  const Eigen::Vector3d offset = rest - centre;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) row.terms.emplace_back(3 * r + c, scale * a[r] * offset[c]);
    row.terms.emplace_back(9 + r, scale * a[r]);
  }
  for (const auto& [node, weight] : w) {
    for (int r = 0; r < 3; ++r) {
      row.terms.emplace_back(kAffineUnknowns + 3 * node + r, scale * weight * a[r]);
    }
  }
  return scale * a.dot(rest);
}

}  // namespace mmm::outlines
