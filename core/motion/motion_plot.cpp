#include "core/motion/motion_plot.h"

#include <numbers>

#include "core/plot/svg_plot.h"

namespace mmm::motion {

std::string joint_angle_svg(const FusedMotion& motion, const opensim::StorageTable* reference,
                            const AnglePlotOptions& options) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  const std::vector<double> times(motion.times.data(), motion.times.data() + motion.times.size());
  std::vector<plot::Chart> charts;
  for (std::size_t c = 0; c < motion.coordinate_names.size(); ++c) {
    const bool angle = motion.coordinate_units[c] == CoordinateUnit::kAngle;
    if (options.angles_only && !angle) continue;
    const Eigen::VectorXd column = motion.coordinates.col(static_cast<Eigen::Index>(c));
    const double unit = angle ? kDeg : 1.0;
    if (unit * (column.maxCoeff() - column.minCoeff()) < options.min_range_deg) continue;
    plot::Chart chart;
    chart.title = motion.coordinate_names[c];
    chart.x_label = "time (s)";
    chart.y_label = angle ? "deg" : "mm";
    plot::Series ours{options.ours_label, times, {}, "", false, 1.8};
    for (Eigen::Index k = 0; k < column.size(); ++k) ours.y.push_back(unit * column(k));
    chart.series.push_back(std::move(ours));
    if (reference != nullptr) {
      if (const auto index = reference->column_index(motion.coordinate_names[c])) {
        plot::Series theirs{options.reference_label, {}, {}, "", true, 1.5};
        const double their_unit = angle ? (reference->in_degrees ? 1.0 : kDeg) : 1000.0;  // m -> mm
        for (Eigen::Index r = 0; r < reference->num_rows(); ++r) {
          const double t = reference->times(r);
          if (t < times.front() - 1e-9 || t > times.back() + 1e-9) continue;
          theirs.x.push_back(t);
          theirs.y.push_back(their_unit * reference->values(r, *index));
        }
        if (!theirs.x.empty()) chart.series.push_back(std::move(theirs));
      }
    }
    charts.push_back(std::move(chart));
  }
  plot::Layout layout;
  layout.columns = options.columns;
  layout.panel_width = 380;
  layout.panel_height = 240;
  layout.title = options.title;
  return plot::svg_small_multiples(charts, layout);
}

}  // namespace mmm::motion
