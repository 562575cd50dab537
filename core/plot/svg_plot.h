#pragma once
// Line charts as self-contained SVG, for people to look at: joint angles over
// a gait trial (ours vs OpenSim), per-muscle volume error over frames, fibre
// lengths over the gait cycle. The output is a complete <svg> element that is
// valid both as a standalone .svg file and inlined in an offline HTML report:
// no scripts, no external fonts or links, no <style> (CSS inside inline SVG
// applies to the whole HTML page), no element ids (two charts in one page
// would collide), presentation attributes only. Text is escaped for XML.
//
//   axis range  = the data (and reference lines) widened to the nearest
//                 nice_ticks (steps 1, 2, 2.5 or 5 x 10^k), or the range given
//   lines       = one <polyline> per run of finite samples, clipped to the
//                 plot area (Liang & Barsky 1984); a lone finite sample
//                 between gaps is drawn as a dot (<circle>)
//   legend      = below the plot, wrapped into rows, so it never covers data
//
// Coordinates are written in pixels with at most 2 decimals, and the same
// input always gives the same bytes (no clock, no randomness, no locale).
//
// Structure, for tools and tests that read the SVG back: the plot area is
// <rect class="plot-area">; series i (in order) is <g class="series"> whose
// <polyline>s and <circle>s hold its samples; small multiples put each chart
// in <g class="panel" transform="translate(x,y)">.

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/plot/nice_ticks.h"  // the axis ticks, part of what a chart promises

namespace mmm::plot {

// One line on a chart.
struct Series {
  std::string label;  // legend text; "" = not in the legend
  // Samples, same length. x must be finite (any order is drawn as given);
  // a non-finite y (NaN, +-inf) is a gap: the line breaks there.
  std::vector<double> x, y;
  // Any SVG paint ("#0072B2", "crimson"); "" = the palette colour of the
  // series' position in the chart (Okabe & Ito 2008, colour-blind safe), so
  // series keep their colours across the panels of small multiples.
  std::string colour;
  bool dashed = false;
  double width = 1.5;  // stroke width (px), > 0
};

// A shaded interval of x across the whole plot height (e.g. stance phase).
struct Band {
  double x0 = 0, x1 = 0;  // x0 <= x1, finite; the part outside the x range is cut off
  std::string label;      // written at the top of the band; "" = none
  std::string colour;     // "" = grey; drawn at 15% opacity either way
};

struct Chart {
  std::string title, x_label;
  std::string y_label;  // with units, e.g. "knee angle (deg)"
  std::vector<Series> series;
  std::vector<Band> bands;
  // Axis ranges (first < second, finite). Default: the data widened to nice
  // ticks; the y default also covers y_reference_lines. Lines leaving a given
  // range are clipped at its edge; a sample more than 1e9 plot sizes outside
  // it (beyond what double precision clips accurately) counts as a gap.
  std::optional<std::pair<double, double>> x_range, y_range;
  std::vector<double> y_reference_lines;  // horizontal dashed guides (e.g. 0 or a limit)
};

// A grid of charts, filled row by row.
struct Layout {
  int columns = 1;         // > 0; fewer when there are fewer charts
  int panel_width = 420;   // px, > 0
  int panel_height = 260;  // px, > 0
  std::string title;       // above the grid; "" = none
};

// One chart as an <svg> element of `width` x `height` px.
// Throws InvalidInputError naming the series (or band, or range) for x and y
// of different lengths, a non-finite x, a non-positive line width, a bad band
// or range, or a non-positive size.
std::string svg_chart(const Chart& chart, int width = 640, int height = 360);

// The charts as panels of one <svg>, `layout.columns` per row. No charts give
// a single empty panel that says so. Throws InvalidInputError like svg_chart
// (naming the chart by index and title), or for a bad layout.
std::string svg_small_multiples(const std::vector<Chart>& charts, const Layout& layout);

// Writes `svg` to `file` through a temporary sibling renamed into place, so a
// crash never leaves half a chart. The parent folder must exist. Throws
// IoError on failure.
void write_svg(const std::string& svg, const std::filesystem::path& file);

}  // namespace mmm::plot
