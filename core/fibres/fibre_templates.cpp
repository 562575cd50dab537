#include "core/fibres/fibre_templates.h"

#include <cmath>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector2d;

constexpr double kFanWidth = 1.0 / 3.0;  // width of the narrow end of a fan
constexpr double kPennateShift = 0.4;    // u travelled by a pennate fibre
constexpr double kCurvedBow = 0.3;       // bow of a curved fibre at mid-length

TemplateFibre straight(const Vector2d& label, const Vector2d& start, const Vector2d& end) {
  return {label, {start, 0.5 * (start + end), end}};
}

}  // namespace

Vector2d TemplateFibre::at(double s) const {
  const double r = 1.0 - s;
  return r * r * control[0] + 2.0 * r * s * control[1] + s * s * control[2];
}

std::vector<Vector2d> fibre_labels(int count) {
  if (count < 1) {
    throw InvalidInputError("fibres: " + std::to_string(count) + " asked for; ask for at least 1");
  }
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count)) - 1e-9));
  const int rows = (count + columns - 1) / columns;
  std::vector<Vector2d> labels;
  labels.reserve(static_cast<std::size_t>(count));
  for (int row = 0; row < rows; ++row) {
    const int in_row = std::min(columns, count - row * columns);
    const double offset = 0.5 * (columns - in_row);  // centres a short last row
    for (int column = 0; column < in_row; ++column) {
      labels.emplace_back((column + offset + 0.5) / columns, (row + 0.5) / rows);
    }
  }
  return labels;
}

std::vector<TemplateFibre> fibre_template(atlas::FibreArchitecture architecture, int count,
                                          bool narrow_at_insertion) {
  std::vector<TemplateFibre> fibres;
  for (const Vector2d& label : fibre_labels(count)) {
    const double a = label.x();
    const double b = label.y();
    switch (architecture) {
      case atlas::FibreArchitecture::kParallel:
        fibres.push_back(straight(label, label, label));
        break;
      case atlas::FibreArchitecture::kFanned: {
        const Vector2d narrow(0.5 + kFanWidth * (a - 0.5), b);
        fibres.push_back(narrow_at_insertion ? straight(label, label, narrow)
                                             : straight(label, narrow, label));
        break;
      }
      case atlas::FibreArchitecture::kPennate: {
        const double start = (1.0 - kPennateShift) * a;
        fibres.push_back(straight(label, {start, b}, {start + kPennateShift, b}));
        break;
      }
      case atlas::FibreArchitecture::kCurved: {
        // Mid-length position a + bow (1 - a): the middle control point sits
        // twice as far out (a quadratic Bezier passes half-way to it).
        const Vector2d middle(a + 2.0 * kCurvedBow * (1.0 - a), b);
        fibres.push_back({label, {label, middle, label}});
        break;
      }
    }
  }
  return fibres;
}

}  // namespace mmm::fibres
