#include "core/plot/svg_plot.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/plot/nice_ticks.h"
#include "core/plot/shortest_text.h"
#include "core/xml_escape.h"

namespace mmm::plot {

namespace {

// Okabe & Ito (2008), "Color Universal Design": distinguishable with every
// common colour-vision deficiency. Their yellow (#F0E442) is left out: it
// is too pale to read as a thin line on white.
constexpr std::array<std::string_view, 7> kPalette = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                      "#E69F00", "#56B4E9", "#000000"};

// Layout, in px.
constexpr double kPad = 8;          // blank border around everything
constexpr double kFont = 12;        // ticks, axis labels, legend (the root's font-size)
constexpr double kTitleFont = 14;   // chart and grid titles
constexpr double kBandFont = 10;    // band labels
constexpr double kTickLength = 4;   // tick marks outside the plot area
constexpr double kLegendRow = 16;   // height of one legend row
constexpr double kLegendLine = 22;  // length of the line sample in the legend
constexpr double kLegendGap = 16;   // between legend entries in a row
constexpr double kMinPlot = 10;     // the plot area never shrinks below this
// Without font metrics, text width is estimated as this fraction of the font
// size per character: about the mean advance of sans-serif fonts.
constexpr double kCharWidth = 0.6;
// Samples further than this many plot sizes outside a given range cannot be
// clipped accurately in double precision and are treated as gaps.
constexpr double kFarOutside = 1e9;

// --- Numbers as text ---------------------------------------------------

// A pixel coordinate with at most 2 decimals (1/100 px is below anything
// visible), trailing zeros dropped. std::to_chars does not depend on the
// locale (snprintf would write "0,5" under a German one), which keeps the
// output the same everywhere.
std::string px(double value) {
  // Fixed notation of the largest double needs 309 digits plus decimals.
  std::array<char, 400> buffer{};
  const auto [end, error] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                          std::chars_format::fixed, 2);
  if (error != std::errc{}) return "0";  // not reached: every double fits the buffer
  std::string text(buffer.data(), end);
  text.erase(text.find_last_not_of('0') + 1);  // there is always a '.' before the zeros
  if (text.back() == '.') text.pop_back();
  return text == "-0" ? "0" : text;
}

using detail::shortest;

// --- XML (text escaped by core/xml_escape.h) ---------------------------

// Writes one element: Tag(out, "line").attr("x1", 3.5).empty();
class Tag {
 public:
  Tag(std::string& out, std::string_view name) : out_(out), name_(name) {
    out_ += '<';
    out_ += name_;
  }
  Tag& attr(std::string_view name, std::string_view value) {
    out_ += ' ';
    out_ += name;
    out_ += "=\"";
    append_xml_escaped(out_, value);
    out_ += '"';
    return *this;
  }
  Tag& attr(std::string_view name, double value) { return attr(name, px(value)); }
  // <name .../>
  void empty() { out_ += "/>\n"; }
  // <name ...>text</name>
  void text(std::string_view content) {
    out_ += '>';
    append_xml_escaped(out_, content);
    out_ += "</";
    out_ += name_;
    out_ += ">\n";
  }
  // <name ...> with children to follow; the caller closes it.
  void open() { out_ += ">\n"; }

 private:
  std::string& out_;
  std::string_view name_;
};

void close(std::string& out, std::string_view name) {
  out += "</";
  out += name;
  out += ">\n";
}

// Estimated width (px) of `text` at `font_size`: UTF-8 code points times the
// mean advance.
double text_width(std::string_view text, double font_size) {
  const auto glyphs = std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0U) != 0x80U;  // not a continuation byte
  });
  return static_cast<double>(glyphs) * kCharWidth * font_size;
}

double widest(const std::vector<std::string>& texts, double font_size) {
  double width = 0;
  for (const std::string& text : texts) width = std::max(width, text_width(text, font_size));
  return width;
}

// --- Validation ----------------------------------------------------------

std::string series_name(std::size_t index, const Series& series) {
  return "series " + std::to_string(index) + " ('" + series.label + "')";
}

void check_range(const std::optional<std::pair<double, double>>& range, std::string_view axis,
                 const std::string& where) {
  if (!range) return;
  const auto [lo, hi] = *range;
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) {
    throw InvalidInputError(where + ": " + std::string(axis) + " is [" + shortest(lo) + ", " +
                            shortest(hi) +
                            "]; it must be finite with first < second (leave it unset to "
                            "fit the data)");
  }
}

// Every contract of Chart, so that the drawing code can rely on it.
void validate(const Chart& chart, const std::string& where) {
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const Series& series = chart.series[i];
    if (series.x.size() != series.y.size()) {
      throw InvalidInputError(where + ": " + series_name(i, series) + " has " +
                              std::to_string(series.x.size()) + " x values but " +
                              std::to_string(series.y.size()) +
                              " y values; give one y per x (NaN in y marks a gap)");
    }
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      if (!std::isfinite(series.x[k])) {
        throw InvalidInputError(where + ": " + series_name(i, series) + ": x[" + std::to_string(k) +
                                "] is " + shortest(series.x[k]) +
                                "; x must be finite (mark a gap with NaN in y instead)");
      }
    }
    if (!(series.width > 0) || !std::isfinite(series.width)) {
      throw InvalidInputError(where + ": " + series_name(i, series) + ": line width is " +
                              shortest(series.width) + " px; it must be positive");
    }
  }
  for (std::size_t i = 0; i < chart.bands.size(); ++i) {
    const Band& band = chart.bands[i];
    if (!std::isfinite(band.x0) || !std::isfinite(band.x1) || band.x0 > band.x1) {
      throw InvalidInputError(where + ": band " + std::to_string(i) + " ('" + band.label +
                              "') spans [" + shortest(band.x0) + ", " + shortest(band.x1) +
                              "]; it must be finite with x0 <= x1");
    }
  }
  for (std::size_t i = 0; i < chart.y_reference_lines.size(); ++i) {
    if (!std::isfinite(chart.y_reference_lines[i])) {
      throw InvalidInputError(where + ": y_reference_lines[" + std::to_string(i) + "] is " +
                              shortest(chart.y_reference_lines[i]) + "; it must be finite");
    }
  }
  check_range(chart.x_range, "x_range", where);
  check_range(chart.y_range, "y_range", where);
}

void check_size(double width, double height, std::string_view what, const std::string& where) {
  if (!(width > 0) || !(height > 0)) {
    throw InvalidInputError(where + ": the " + std::string(what) + " must be positive, got " +
                            shortest(width) + " x " + shortest(height) + " px");
  }
}

// --- Axes ------------------------------------------------------------------

// The value range of a set of numbers; empty until the first add.
struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double value) {
    lo = std::min(lo, value);
    hi = std::max(hi, value);
  }
  [[nodiscard]] bool empty() const { return lo > hi; }
};

// One axis: the range mapped onto the plot area and its labelled ticks.
struct Axis {
  double lo = 0, hi = 1;
  std::vector<double> ticks;  // inside [lo, hi]
  std::vector<std::string> labels;
  // Position of `value` along the axis, 0 at lo and 1 at hi. Halving first
  // keeps hi - lo from overflowing for ranges near the largest double.
  [[nodiscard]] double unit(double value) const { return (value / 2 - lo / 2) / (hi / 2 - lo / 2); }
};

// The axis for data spanning `data` (default [0, 1] when empty): the given
// range with the nice ticks inside it, or the data widened to its ticks.
Axis make_axis(Extent data, const std::optional<std::pair<double, double>>& given, int target) {
  if (data.empty()) data = Extent{0, 1};
  Axis axis;
  if (given) {
    axis.lo = given->first;
    axis.hi = given->second;
    const std::vector<double> ticks = nice_ticks(axis.lo, axis.hi, target);
    const std::vector<std::string> labels = tick_labels(ticks);  // spaced as all ticks
    const double slack = (axis.hi / 2 - axis.lo / 2) * 2e-9;     // rounding of the tick values
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      if (ticks[i] >= axis.lo - slack && ticks[i] <= axis.hi + slack) {
        axis.ticks.push_back(ticks[i]);
        axis.labels.push_back(labels[i]);
      }
    }
    return axis;
  }
  axis.ticks = nice_ticks(data.lo, data.hi, target);
  axis.labels = tick_labels(axis.ticks);
  // An end tick is a rounded product k * step: keep the data inside the range
  // even when that rounding puts the tick an ulp inside the data.
  axis.lo = std::min(data.lo, axis.ticks.front());
  axis.hi = std::max(data.hi, axis.ticks.back());
  if (!(axis.lo < axis.hi)) axis.hi = axis.lo + 1;  // not reached: nice_ticks widens
  return axis;
}

// --- Lines ---------------------------------------------------------------

// A position in the plot area: (0, 0) bottom left, (1, 1) top right.
struct Point {
  double u = 0, v = 0;
};

// What of one series is visible: polylines (>= 2 points each) and lone dots.
struct Trace {
  std::vector<std::vector<Point>> lines;
  std::vector<Point> dots;
};

bool inside_unit(Point p) { return p.u >= 0 && p.u <= 1 && p.v >= 0 && p.v <= 1; }

// Liang & Barsky (1984): the part of segment a-b inside the unit square as
// parameters 0 <= t0 <= t1 <= 1 along it; nothing when it misses.
std::optional<std::pair<double, double>> clip_to_unit(Point a, Point b) {
  const double du = b.u - a.u;
  const double dv = b.v - a.v;
  double t0 = 0;
  double t1 = 1;
  // Each side as p * t <= q.
  const std::array<std::pair<double, double>, 4> sides = {
      {{-du, a.u}, {du, 1 - a.u}, {-dv, a.v}, {dv, 1 - a.v}}};
  for (const auto& [p, q] : sides) {
    if (p == 0) {
      if (q < 0) return std::nullopt;  // parallel to this side and outside it
      continue;
    }
    const double t = q / p;
    if (p < 0) {
      if (t > t1) return std::nullopt;
      t0 = std::max(t0, t);
    } else {
      if (t < t0) return std::nullopt;
      t1 = std::min(t1, t);
    }
  }
  return std::pair{t0, t1};
}

Point along(Point a, Point b, double t) {
  if (t <= 0) return a;
  if (t >= 1) return b;
  // Clamped: rounding may put a clipped end a hair outside the square.
  return {std::clamp(a.u + t * (b.u - a.u), 0.0, 1.0), std::clamp(a.v + t * (b.v - a.v), 0.0, 1.0)};
}

// Adds the visible parts of one run of consecutive drawable samples.
void trace_run(const std::vector<Point>& run, Trace& trace) {
  if (run.size() == 1) {
    if (inside_unit(run.front())) trace.dots.push_back(run.front());
    return;
  }
  std::vector<Point> line;
  const auto finish_line = [&] {
    if (line.size() >= 2) trace.lines.push_back(std::move(line));
    line.clear();
  };
  for (std::size_t k = 0; k + 1 < run.size(); ++k) {
    const auto visible = clip_to_unit(run[k], run[k + 1]);
    if (!visible) {
      finish_line();
      continue;
    }
    const auto [t0, t1] = *visible;
    if (line.empty() || t0 > 0) {  // (re-)entering the plot area
      finish_line();
      line.push_back(along(run[k], run[k + 1], t0));
    }
    line.push_back(along(run[k], run[k + 1], t1));
    if (t1 < 1) finish_line();  // leaving it
  }
  finish_line();
}

Trace trace_series(const Series& series, const Axis& x, const Axis& y) {
  Trace trace;
  std::vector<Point> run;
  for (std::size_t k = 0; k < series.x.size(); ++k) {
    const Point p{x.unit(series.x[k]), y.unit(series.y[k])};
    const bool drawable =
        std::isfinite(p.v) && std::abs(p.u) < kFarOutside && std::abs(p.v) < kFarOutside;
    if (drawable) {
      run.push_back(p);
    } else if (!run.empty()) {
      trace_run(run, trace);
      run.clear();
    }
  }
  if (!run.empty()) trace_run(run, trace);
  return trace;
}

// --- Chart layout ---------------------------------------------------------

std::string colour_of(const Series& series, std::size_t index) {
  if (!series.colour.empty()) return series.colour;
  return std::string(kPalette[index % kPalette.size()]);
}

std::string dash_of(const Series& series) {
  const double scale = std::max(1.0, series.width / 1.5);  // longer dashes for thick lines
  return px(6 * scale) + " " + px(4 * scale);
}

// The plot area in px, with maps from axis units to px.
struct Frame {
  double left = 0, top = 0, width = 0, height = 0;
  [[nodiscard]] double x(double u) const { return left + u * width; }
  [[nodiscard]] double y(double v) const { return top + (1 - v) * height; }
  [[nodiscard]] double right() const { return left + width; }
  [[nodiscard]] double bottom() const { return top + height; }
};

struct LegendEntry {
  std::size_t series = 0;
  double x = 0;  // left end of the line sample
  int row = 0;
};

struct Legend {
  std::vector<LegendEntry> entries;
  int rows = 0;
};

// Labelled series in rows that fit `width`, each row centred.
Legend layout_legend(const std::vector<Series>& series, double width) {
  Legend legend;
  std::vector<double> entry_widths;
  std::vector<std::size_t> labelled;
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (series[i].label.empty()) continue;
    labelled.push_back(i);
    entry_widths.push_back(kLegendLine + 6 + text_width(series[i].label, kFont));
  }
  const double available = width - 2 * kPad;
  std::size_t row_start = 0;
  while (row_start < labelled.size()) {
    // As many entries as fit (at least one, however long).
    std::size_t row_end = row_start + 1;
    double row_width = entry_widths[row_start];
    while (row_end < labelled.size() &&
           row_width + kLegendGap + entry_widths[row_end] <= available) {
      row_width += kLegendGap + entry_widths[row_end];
      ++row_end;
    }
    double x = std::max(kPad, (width - row_width) / 2);
    for (std::size_t k = row_start; k < row_end; ++k) {
      legend.entries.push_back({labelled[k], x, legend.rows});
      x += entry_widths[k] + kLegendGap;
    }
    ++legend.rows;
    row_start = row_end;
  }
  return legend;
}

// Where everything of one chart goes, in the box (0, 0)-(width, height).
struct Plan {
  double width = 0, height = 0;
  Frame frame;
  Axis x, y;
  Legend legend;
  bool any_sample = false;  // some series has a finite y
};

// Top to bottom: title, plot, x tick labels, x label, legend rows. Left to
// right: y label, y tick labels, plot, half the widest x tick label (the
// last one is centred on the right edge). The y ticks depend on the plot
// height and set the left margin, which sets the plot width and so the x
// ticks: computed in that order, nothing goes round in a circle.
Plan plan_chart(const Chart& chart, double width, double height) {
  Plan plan;
  plan.width = width;
  plan.height = height;
  Extent x_data;
  Extent y_data;
  for (const Series& series : chart.series) {
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      x_data.add(series.x[k]);
      if (std::isfinite(series.y[k])) y_data.add(series.y[k]);
    }
  }
  plan.any_sample = !y_data.empty();
  for (const double level : chart.y_reference_lines) y_data.add(level);

  plan.legend = layout_legend(chart.series, width);
  Frame& frame = plan.frame;
  frame.top = kPad + 6 + (chart.title.empty() ? 0 : kTitleFont + 6);
  const double legend_height = plan.legend.rows == 0 ? 0 : plan.legend.rows * kLegendRow + 4;
  const double bottom =
      kTickLength + 2 + kFont + (chart.x_label.empty() ? 0 : kFont + 6) + legend_height + kPad;
  frame.height = std::max(height - frame.top - bottom, kMinPlot);
  // About one y tick per 36 px, 3 to 6 of them.
  const int y_target = std::clamp(static_cast<int>(frame.height / 36) + 1, 3, 6);
  plan.y = make_axis(y_data, chart.y_range, y_target);

  frame.left = kPad + (chart.y_label.empty() ? 0 : kFont + 6) + widest(plan.y.labels, kFont) +
               kTickLength + 3;
  // Fewer x ticks when their labels would run into each other.
  for (int target = 6; target >= 3; --target) {
    plan.x = make_axis(x_data, chart.x_range, target);
    const double label_width = widest(plan.x.labels, kFont);
    frame.width = std::max(width - frame.left - kPad - label_width / 2, kMinPlot);
    if (plan.x.ticks.size() < 2) break;
    const double spacing =
        frame.width * (plan.x.unit(plan.x.ticks[1]) - plan.x.unit(plan.x.ticks[0]));
    if (spacing >= label_width + 8) break;
  }
  return plan;
}

// --- Drawing --------------------------------------------------------------

// <line> from (x1, y1) to (x2, y2) px, for the caller to style and close.
Tag line_tag(std::string& out, double x1, double y1, double x2, double y2) {
  Tag tag(out, "line");
  tag.attr("x1", x1).attr("y1", y1).attr("x2", x2).attr("y2", y2);
  return tag;
}

// Shaded intervals, behind everything else in the plot.
void draw_bands(std::string& out, const Chart& chart, const Plan& plan) {
  const Frame& frame = plan.frame;
  for (const Band& band : chart.bands) {
    const double u0 = std::clamp(plan.x.unit(band.x0), 0.0, 1.0);
    const double u1 = std::clamp(plan.x.unit(band.x1), 0.0, 1.0);
    if (!(u1 > u0)) continue;  // outside the x range
    Tag(out, "rect")
        .attr("class", "band")
        .attr("x", frame.x(u0))
        .attr("y", frame.top)
        .attr("width", frame.x(u1) - frame.x(u0))
        .attr("height", frame.height)
        .attr("fill", band.colour.empty() ? "#888888" : band.colour)
        .attr("fill-opacity", "0.15")
        .empty();
    if (band.label.empty()) continue;
    Tag(out, "text")
        .attr("x", frame.x((u0 + u1) / 2))
        .attr("y", frame.top + kBandFont + 2)
        .attr("font-size", kBandFont)
        .attr("text-anchor", "middle")
        .attr("fill", "#555555")
        .text(band.label);
  }
}

// Light grid lines at the ticks and the dashed reference levels.
void draw_grid(std::string& out, const Chart& chart, const Plan& plan) {
  const Frame& frame = plan.frame;
  for (const double tick : plan.y.ticks) {
    const double y = frame.y(plan.y.unit(tick));
    line_tag(out, frame.left, y, frame.right(), y).attr("stroke", "#e3e3e3").empty();
  }
  for (const double tick : plan.x.ticks) {
    const double x = frame.x(plan.x.unit(tick));
    line_tag(out, x, frame.top, x, frame.bottom()).attr("stroke", "#e3e3e3").empty();
  }
  for (const double level : chart.y_reference_lines) {
    const double v = plan.y.unit(level);
    if (v < 0 || v > 1) continue;  // outside a given y range
    line_tag(out, frame.left, frame.y(v), frame.right(), frame.y(v))
        .attr("class", "reference")
        .attr("stroke", "#666666")
        .attr("stroke-dasharray", "4 3")
        .empty();
  }
}

// One <g class="series"> per series, in order (later ones on top).
void draw_series(std::string& out, const Chart& chart, const Plan& plan) {
  const Frame& frame = plan.frame;
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const Series& series = chart.series[i];
    const std::string colour = colour_of(series, i);
    const Trace trace = trace_series(series, plan.x, plan.y);
    Tag(out, "g").attr("class", "series").open();
    if (!series.label.empty()) Tag(out, "title").text(series.label);  // tooltip
    for (const std::vector<Point>& line : trace.lines) {
      std::string points;
      points.reserve(line.size() * 14);  // "123.45,67.89 "
      for (const Point& p : line) {
        points += px(frame.x(p.u));
        points += ',';
        points += px(frame.y(p.v));
        points += ' ';
      }
      points.pop_back();
      Tag polyline(out, "polyline");
      polyline.attr("points", points)
          .attr("fill", "none")
          .attr("stroke", colour)
          .attr("stroke-width", series.width)
          .attr("stroke-linejoin", "round")
          .attr("stroke-linecap", "round");
      if (series.dashed) polyline.attr("stroke-dasharray", dash_of(series));
      polyline.empty();
    }
    for (const Point& p : trace.dots) {
      Tag(out, "circle")
          .attr("cx", frame.x(p.u))
          .attr("cy", frame.y(p.v))
          .attr("r", std::max(series.width, 2.0))
          .attr("fill", colour)
          .empty();
    }
    close(out, "g");
  }
  if (!plan.any_sample) {
    Tag(out, "text")
        .attr("x", frame.x(0.5))
        .attr("y", frame.y(0.5))
        .attr("text-anchor", "middle")
        .attr("fill", "#888888")
        .text("no data");
  }
}

// The plot-area frame, tick marks and tick labels.
void draw_axes(std::string& out, const Plan& plan) {
  const Frame& frame = plan.frame;
  Tag(out, "rect")
      .attr("class", "plot-area")
      .attr("x", frame.left)
      .attr("y", frame.top)
      .attr("width", frame.width)
      .attr("height", frame.height)
      .attr("fill", "none")
      .attr("stroke", "#888888")
      .empty();
  for (std::size_t i = 0; i < plan.y.ticks.size(); ++i) {
    const double y = frame.y(plan.y.unit(plan.y.ticks[i]));
    line_tag(out, frame.left - kTickLength, y, frame.left, y).attr("stroke", "#888888").empty();
    Tag(out, "text")
        .attr("class", "tick")
        .attr("x", frame.left - kTickLength - 3)
        .attr("y", y + kFont * 0.35)  // about half the cap height: centred on the tick
        .attr("text-anchor", "end")
        .text(plan.y.labels[i]);
  }
  for (std::size_t i = 0; i < plan.x.ticks.size(); ++i) {
    const double x = frame.x(plan.x.unit(plan.x.ticks[i]));
    line_tag(out, x, frame.bottom(), x, frame.bottom() + kTickLength)
        .attr("stroke", "#888888")
        .empty();
    Tag(out, "text")
        .attr("class", "tick")
        .attr("x", x)
        .attr("y", frame.bottom() + kTickLength + 2 + kFont * 0.85)  // cap height below the mark
        .attr("text-anchor", "middle")
        .text(plan.x.labels[i]);
  }
}

// Chart title and axis labels.
void draw_titles(std::string& out, const Chart& chart, const Plan& plan) {
  const Frame& frame = plan.frame;
  if (!chart.title.empty()) {
    Tag(out, "text")
        .attr("x", plan.width / 2)
        .attr("y", kPad + kTitleFont)
        .attr("font-size", kTitleFont)
        .attr("font-weight", "bold")
        .attr("text-anchor", "middle")
        .text(chart.title);
  }
  if (!chart.x_label.empty()) {
    Tag(out, "text")
        .attr("x", frame.x(0.5))
        .attr("y", frame.bottom() + kTickLength + 2 + kFont + kFont + 4)
        .attr("text-anchor", "middle")
        .text(chart.x_label);
  }
  if (!chart.y_label.empty()) {
    // Rotated to read bottom to top; its baseline is a font size in from the pad.
    const std::string place =
        "translate(" + px(kPad + kFont) + " " + px(frame.y(0.5)) + ") rotate(-90)";
    Tag(out, "text").attr("transform", place).attr("text-anchor", "middle").text(chart.y_label);
  }
}

// Legend rows at the bottom: a line sample in the series' style, then its label.
void draw_legend(std::string& out, const Chart& chart, const Plan& plan) {
  const double top = plan.height - kPad - plan.legend.rows * kLegendRow;
  for (const LegendEntry& entry : plan.legend.entries) {
    const Series& series = chart.series[entry.series];
    const double baseline = top + entry.row * kLegendRow + kFont;
    const double line_y = baseline - kFont * 0.35;
    Tag sample = line_tag(out, entry.x, line_y, entry.x + kLegendLine, line_y);
    sample.attr("stroke", colour_of(series, entry.series))
        .attr("stroke-width", std::min(series.width, 4.0));  // thick lines would hide the text
    if (series.dashed) sample.attr("stroke-dasharray", dash_of(series));
    sample.empty();
    Tag(out, "text").attr("x", entry.x + kLegendLine + 6).attr("y", baseline).text(series.label);
  }
}

// Draws `chart` into the box (0, 0)-(width, height) of `out`, which the
// caller wraps in <svg> or a translated <g>. The chart has been validated.
void render_chart(std::string& out, const Chart& chart, double width, double height) {
  const Plan plan = plan_chart(chart, width, height);
  Tag(out, "rect").attr("width", width).attr("height", height).attr("fill", "white").empty();
  draw_bands(out, chart, plan);
  draw_grid(out, chart, plan);
  draw_series(out, chart, plan);
  draw_axes(out, plan);
  draw_titles(out, chart, plan);
  draw_legend(out, chart, plan);
}

// <svg ...> with a <title> (the accessible name of the image) when given.
void open_svg(std::string& out, double width, double height, const std::string& title) {
  Tag(out, "svg")
      .attr("xmlns", "http://www.w3.org/2000/svg")
      .attr("width", width)
      .attr("height", height)
      .attr("viewBox", "0 0 " + px(width) + " " + px(height))
      .attr("role", "img")
      .attr("font-family", "sans-serif")
      .attr("font-size", kFont)
      .open();
  if (!title.empty()) Tag(out, "title").text(title);
}

}  // namespace

std::string svg_chart(const Chart& chart, int width, int height) {
  const std::string where = "svg_chart ('" + chart.title + "')";
  check_size(width, height, "chart size", where);
  validate(chart, where);
  std::string out;
  open_svg(out, width, height, chart.title);
  render_chart(out, chart, width, height);
  close(out, "svg");
  return out;
}

std::string svg_small_multiples(const std::vector<Chart>& charts, const Layout& layout) {
  const std::string where = "svg_small_multiples ('" + layout.title + "')";
  check_size(layout.panel_width, layout.panel_height, "panel size", where);
  if (layout.columns <= 0) {
    throw InvalidInputError(where + ": columns is " + std::to_string(layout.columns) +
                            "; it must be positive");
  }
  for (std::size_t i = 0; i < charts.size(); ++i) {
    validate(charts[i], where + ": chart " + std::to_string(i) + " ('" + charts[i].title + "')");
  }
  const std::size_t count = charts.size();
  const std::size_t columns =
      std::min(static_cast<std::size_t>(layout.columns), std::max(count, std::size_t{1}));
  const std::size_t rows = std::max((count + columns - 1) / columns, std::size_t{1});
  const double panel_width = layout.panel_width;
  const double panel_height = layout.panel_height;
  const double title_height = layout.title.empty() ? 0 : kTitleFont + 2 * kPad;
  const double width = static_cast<double>(columns) * panel_width;
  const double height = title_height + static_cast<double>(rows) * panel_height;

  std::string out;
  open_svg(out, width, height, layout.title);
  Tag(out, "rect").attr("width", width).attr("height", height).attr("fill", "white").empty();
  if (!layout.title.empty()) {
    Tag(out, "text")
        .attr("x", width / 2)
        .attr("y", kPad + kTitleFont)
        .attr("font-size", kTitleFont)
        .attr("font-weight", "bold")
        .attr("text-anchor", "middle")
        .text(layout.title);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t row = i / columns;
    const std::size_t column = i % columns;
    const double x = static_cast<double>(column) * panel_width;
    const double y = title_height + static_cast<double>(row) * panel_height;
    Tag(out, "g")
        .attr("class", "panel")
        .attr("transform", "translate(" + px(x) + " " + px(y) + ")")
        .open();
    render_chart(out, charts[i], panel_width, panel_height);
    close(out, "g");
  }
  if (count == 0) {
    Tag(out, "text")
        .attr("x", width / 2)
        .attr("y", title_height + panel_height / 2)
        .attr("text-anchor", "middle")
        .attr("fill", "#888888")
        .text("no charts");
  }
  close(out, "svg");
  return out;
}

void write_svg(const std::string& svg, const std::filesystem::path& file) {
  write_file_atomically(file, svg, "an SVG chart");
}

}  // namespace mmm::plot
