#include "core/wrapping/wrapping_summary.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "core/plot/svg_plot.h"

namespace mmm::wrapping {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

MuscleWrappingSummary summarise(const WrappedMuscle& muscle) {
  MuscleWrappingSummary summary;
  for (const MuscleFrameMetrics& frame : muscle.frames) {
    summary.max_abs_volume_error_percent =
        std::max(summary.max_abs_volume_error_percent, std::abs(frame.volume_error_percent));
    summary.max_depth_mm = std::max(summary.max_depth_mm, frame.max_depth_mm);
    summary.max_smoothness_change_percent =
        std::max(summary.max_smoothness_change_percent, frame.smoothness_change_percent);
    summary.vertex_frames_deeper += frame.vertices_deeper;
    summary.max_muscle_depth_mm = std::max(summary.max_muscle_depth_mm, frame.muscle_depth_mm);
    summary.muscle_vertex_frames_deeper += frame.muscle_vertices_deeper;
    if (!frame.converged) ++summary.unconverged_frames;
    summary.ms_per_frame.push_back(1000.0 * frame.seconds);
  }
  summary.median_ms_per_frame = median(summary.ms_per_frame);
  return summary;
}

std::string wrapping_metrics_svg(const MuscleWrapping& wrapped, const std::string& title) {
  const std::vector<double> times(wrapped.times.data(),
                                  wrapped.times.data() + wrapped.times.size());
  auto chart = [&](const char* chart_title, const char* y_label,
                   const std::function<double(const MuscleFrameMetrics&)>& value) {
    plot::Chart c;
    c.title = chart_title;
    c.x_label = "time (s)";
    c.y_label = y_label;
    for (const WrappedMuscle& muscle : wrapped.muscles) {
      plot::Series series;
      series.label = muscle.name;
      series.x = times;
      for (const MuscleFrameMetrics& frame : muscle.frames) series.y.push_back(value(frame));
      c.series.push_back(std::move(series));
    }
    return c;
  };
  plot::Chart volume = chart("Volume error", "volume error (%)",
                             [](const MuscleFrameMetrics& f) { return f.volume_error_percent; });
  volume.y_reference_lines = {-0.5, 0.5};
  plot::Chart depth = chart("Deepest vertex inside a bone", "depth (mm)",
                            [](const MuscleFrameMetrics& f) { return f.max_depth_mm; });
  depth.y_reference_lines = {1.0};
  const plot::Chart time = chart("Time per muscle-frame", "time (ms)",
                                 [](const MuscleFrameMetrics& f) { return 1000.0 * f.seconds; });
  const plot::Chart bending =
      chart("Surface bending vs rest", "change (%)",
            [](const MuscleFrameMetrics& f) { return f.smoothness_change_percent; });
  plot::Layout layout;
  layout.columns = 2;
  layout.panel_width = 560;
  layout.panel_height = 420;
  layout.title = title;
  std::vector<plot::Chart> charts = {volume, depth, time, bending};
  if (wrapped.muscle_penetration) {
    charts.push_back(chart("Deepest vertex in another muscle, beyond its rest overlap",
                           "depth (mm)",
                           [](const MuscleFrameMetrics& f) { return f.muscle_depth_mm; }));
  }
  return plot::svg_small_multiples(charts, layout);
}

}  // namespace mmm::wrapping
