#pragma once
// What a person reads first of a wrapped trial: per muscle, the worst volume
// error, the deepest vertex inside a bone, the largest bending change and the
// median time per frame; and the same metrics over the trial as SVG panels.
// Shared by the wrap_muscles node and bench/run wrapping.

#include <string>
#include <vector>

#include "core/wrapping/muscle_wrapping.h"

namespace mmm::wrapping {

struct MuscleWrappingSummary {
  double max_abs_volume_error_percent = 0.0;
  double max_depth_mm = 0.0;
  double max_smoothness_change_percent = 0.0;
  int vertex_frames_deeper = 0;  // vertices deeper than the contact tolerance, summed over frames
  // When measured: the deepest vertex in another muscle beyond its rest
  // depth there, and vertices deeper than the tolerance, summed over frames.
  double max_muscle_depth_mm = 0.0;
  int muscle_vertex_frames_deeper = 0;
  int unconverged_frames = 0;
  std::vector<double> ms_per_frame;
  double median_ms_per_frame = 0.0;
};

MuscleWrappingSummary summarise(const WrappedMuscle& muscle);

// Median of the values (mean of the middle two for an even count; 0 when empty).
double median(std::vector<double> values);

// Volume error, deepest vertex in a bone, time and bending change per frame
// (and the deepest vertex in another muscle, when measured), one line per
// muscle, as small multiples (core/plot/svg_plot.h).
std::string wrapping_metrics_svg(const MuscleWrapping& wrapped, const std::string& title);

}  // namespace mmm::wrapping
