#include "core/plot/svg_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <limits>
#include <numbers>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "tests/support/test_helpers.h"

namespace mmm::plot {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

using test::kNaN;

// Coordinates are written with 2 decimals: each number read back is within
// 0.005 px of the exact value, so a difference of two is within 0.01.
constexpr double kPixel = 0.011;

// --- Reading the SVG back --------------------------------------------------

struct Parsed {
  tinyxml2::XMLDocument doc;
  [[nodiscard]] const tinyxml2::XMLElement* root() const { return doc.RootElement(); }
};

// Parses `svg`, failing the test when it is not well-formed XML.
void parse(const std::string& svg, Parsed& parsed) {
  const tinyxml2::XMLError error = parsed.doc.Parse(svg.c_str(), svg.size());
  ASSERT_EQ(error, tinyxml2::XML_SUCCESS) << parsed.doc.ErrorStr() << "\n" << svg;
  ASSERT_NE(parsed.root(), nullptr);
}

// Every element below `element` (depth first, document order).
void collect(const tinyxml2::XMLElement* element, std::vector<const tinyxml2::XMLElement*>& out) {
  for (const tinyxml2::XMLElement* child = element->FirstChildElement(); child != nullptr;
       child = child->NextSiblingElement()) {
    out.push_back(child);
    collect(child, out);
  }
}

std::vector<const tinyxml2::XMLElement*> elements(const tinyxml2::XMLElement* from,
                                                  const std::string& name,
                                                  const std::string& css_class = "") {
  std::vector<const tinyxml2::XMLElement*> all;
  collect(from, all);
  std::vector<const tinyxml2::XMLElement*> matching;
  for (const tinyxml2::XMLElement* element : all) {
    const char* cls = element->Attribute("class");
    if (element->Name() == name && (css_class.empty() || (cls != nullptr && css_class == cls))) {
      matching.push_back(element);
    }
  }
  return matching;
}

double number(const tinyxml2::XMLElement* element, const char* attribute) {
  const char* text = element->Attribute(attribute);
  EXPECT_NE(text, nullptr) << attribute;
  return text == nullptr ? kNaN : std::strtod(text, nullptr);
}

struct Pixel {
  double x = 0, y = 0;
};

std::vector<Pixel> points_of(const tinyxml2::XMLElement* polyline) {
  std::vector<Pixel> points;
  std::istringstream in(polyline->Attribute("points"));
  std::string pair;
  while (in >> pair) {
    const std::size_t comma = pair.find(',');
    points.push_back({std::strtod(pair.substr(0, comma).c_str(), nullptr),
                      std::strtod(pair.substr(comma + 1).c_str(), nullptr)});
  }
  return points;
}

// Samples drawn by a <g class="series">: polyline points plus dots.
std::size_t samples_drawn(const tinyxml2::XMLElement* series) {
  std::size_t count = elements(series, "circle").size();
  for (const auto* line : elements(series, "polyline")) count += points_of(line).size();
  return count;
}

struct Rect {
  double x = 0, y = 0, width = 0, height = 0;
};

Rect plot_area(const tinyxml2::XMLElement* from) {
  const auto areas = elements(from, "rect", "plot-area");
  EXPECT_EQ(areas.size(), 1U);
  if (areas.empty()) return {};
  return {number(areas[0], "x"), number(areas[0], "y"), number(areas[0], "width"),
          number(areas[0], "height")};
}

// Every number in a coordinate-like attribute parses and is finite, and none
// is written with more than 2 decimals.
void expect_clean_numbers(const tinyxml2::XMLElement* root) {
  static const std::set<std::string> kNumeric = {
      "x",  "y",  "width", "height", "cx",      "cy",           "r",        "x1",
      "y1", "x2", "y2",    "points", "viewBox", "stroke-width", "transform"};
  static const std::regex kNumber(R"(-?[0-9]+(\.[0-9]+)?(e[-+][0-9]+)?)");
  std::vector<const tinyxml2::XMLElement*> all{root};
  collect(root, all);
  for (const auto* element : all) {
    for (const tinyxml2::XMLAttribute* a = element->FirstAttribute(); a != nullptr; a = a->Next()) {
      if (!kNumeric.contains(a->Name())) continue;
      std::string value = a->Value();
      if (std::string(a->Name()) == "transform") {
        value = std::regex_replace(value, std::regex("[a-z]+\\(|\\)"), " ");
      }
      for (char& c : value) c = c == ',' ? ' ' : c;
      std::istringstream in(value);
      std::string token;
      while (in >> token) {
        EXPECT_TRUE(std::regex_match(token, kNumber))
            << element->Name() << " " << a->Name() << "=\"" << a->Value() << "\"";
        EXPECT_TRUE(std::isfinite(std::strtod(token.c_str(), nullptr))) << token;
        const std::size_t dot = token.find('.');
        if (dot != std::string::npos && token.find('e') == std::string::npos) {
          EXPECT_LE(token.size() - dot - 1, 2U) << token;
        }
      }
    }
  }
}

Series line(const std::string& label, std::vector<double> x, std::vector<double> y) {
  Series series;
  series.label = label;
  series.x = std::move(x);
  series.y = std::move(y);
  return series;
}

std::vector<double> range(int count) {
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) values.push_back(i);
  return values;
}

// A knee-angle-like curve over a gait cycle (0..100 %).
Chart knee_chart() {
  Chart chart;
  chart.title = "Knee flexion";
  chart.x_label = "gait cycle (%)";
  chart.y_label = "knee angle (deg)";
  std::vector<double> x = range(101);
  std::vector<double> ours;
  std::vector<double> opensim;
  for (const double t : x) {
    ours.push_back(30 - 30 * std::cos(2 * std::numbers::pi * t / 100));
    opensim.push_back(31 - 29 * std::cos(2 * std::numbers::pi * t / 100));
  }
  chart.series.push_back(line("ours", x, ours));
  chart.series.push_back(line("OpenSim", x, opensim));
  chart.series.back().dashed = true;
  chart.bands.push_back({0, 60, "stance", ""});
  chart.y_reference_lines = {0};
  return chart;
}

// --- Document structure ------------------------------------------------------

TEST(SvgPlotTest, ChartIsAWellFormedSvgRootWithItsSize) {
  Parsed parsed;
  parse(svg_chart(knee_chart(), 640, 360), parsed);
  const auto* root = parsed.root();
  EXPECT_STREQ(root->Name(), "svg");
  EXPECT_STREQ(root->Attribute("xmlns"), "http://www.w3.org/2000/svg");
  EXPECT_STREQ(root->Attribute("width"), "640");
  EXPECT_STREQ(root->Attribute("height"), "360");
  EXPECT_STREQ(root->Attribute("viewBox"), "0 0 640 360");
  // The chart title is also the <title>: the accessible name of the image.
  ASSERT_NE(root->FirstChildElement("title"), nullptr);
  EXPECT_STREQ(root->FirstChildElement("title")->GetText(), "Knee flexion");
  expect_clean_numbers(root);
}

TEST(SvgPlotTest, IsSelfContained) {
  const std::string svg = svg_chart(knee_chart());
  // Nothing that runs, loads, or styles the page around an inlined chart.
  for (const char* banned :
       {"<script", "href", "url(", "<style", "@import", "<foreignObject", " id=", "<?xml"}) {
    EXPECT_EQ(svg.find(banned), std::string::npos) << banned;
  }
}

TEST(SvgPlotTest, HasAxisLabelsLegendAndBands) {
  Parsed parsed;
  parse(svg_chart(knee_chart()), parsed);
  std::vector<std::string> texts;
  for (const auto* text : elements(parsed.root(), "text")) texts.emplace_back(text->GetText());
  for (const char* expected :
       {"Knee flexion", "gait cycle (%)", "knee angle (deg)", "ours", "OpenSim", "stance"}) {
    EXPECT_NE(std::find(texts.begin(), texts.end(), expected), texts.end()) << expected;
  }
  // The legend sits below the plot area, so it never covers a line.
  const Rect area = plot_area(parsed.root());
  for (const auto* text : elements(parsed.root(), "text")) {
    if (std::string(text->GetText()) == "ours") {
      EXPECT_GT(number(text, "y"), area.y + area.height);
    }
  }
  // The stance band covers 0..60 % of an x axis of 0..100 %.
  const auto bands = elements(parsed.root(), "rect", "band");
  ASSERT_EQ(bands.size(), 1U);
  EXPECT_NEAR(number(bands[0], "x"), area.x, kPixel);
  EXPECT_NEAR(number(bands[0], "width"), 0.6 * area.width, kPixel);
  EXPECT_EQ(elements(parsed.root(), "line", "reference").size(), 1U);
}

TEST(SvgPlotTest, SeriesStylesFollowTheirSettings) {
  Chart chart = knee_chart();
  chart.series.push_back(line("red", {0, 1}, {2, 3}));
  chart.series.back().colour = "#ff0000";
  chart.series.back().width = 3;
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  const auto series = elements(parsed.root(), "g", "series");
  ASSERT_EQ(series.size(), 3U);
  const auto* ours = elements(series[0], "polyline").at(0);
  const auto* opensim = elements(series[1], "polyline").at(0);
  const auto* red = elements(series[2], "polyline").at(0);
  // Automatic colours come from the palette in order and differ.
  EXPECT_STREQ(ours->Attribute("stroke"), "#0072B2");
  EXPECT_STREQ(opensim->Attribute("stroke"), "#D55E00");
  EXPECT_EQ(ours->Attribute("stroke-dasharray"), nullptr);
  EXPECT_NE(opensim->Attribute("stroke-dasharray"), nullptr);
  EXPECT_STREQ(red->Attribute("stroke"), "#ff0000");
  EXPECT_STREQ(red->Attribute("stroke-width"), "3");
}

// --- Lines and coordinates ------------------------------------------------------

TEST(SvgPlotTest, EachSeriesDrawsAllItsFiniteSamples) {
  Chart chart = knee_chart();
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  const auto series = elements(parsed.root(), "g", "series");
  ASSERT_EQ(series.size(), 2U);
  for (const auto* group : series) {
    const auto lines = elements(group, "polyline");
    ASSERT_EQ(lines.size(), 1U);
    EXPECT_EQ(points_of(lines[0]).size(), 101U);
  }
}

TEST(SvgPlotTest, NanInYBreaksTheLine) {
  std::vector<double> y = range(12);
  y[5] = kNaN;
  // Samples 0-4 and 6-11 are two lines; a lone sample between gaps is a dot.
  Chart chart;
  chart.series.push_back(line("gappy", range(12), y));
  chart.series.push_back(line("lone", {0, 1, 2}, {kNaN, 4, kNaN}));
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  const auto series = elements(parsed.root(), "g", "series");
  ASSERT_EQ(series.size(), 2U);
  const auto lines = elements(series[0], "polyline");
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_EQ(points_of(lines[0]).size(), 5U);
  EXPECT_EQ(points_of(lines[1]).size(), 6U);
  // The gap is a gap: the lines end and start at the neighbours of sample 5,
  // not at y = 0.
  const Rect area = plot_area(parsed.root());
  EXPECT_LT(points_of(lines[0]).back().y, area.y + area.height - 1);
  EXPECT_EQ(elements(series[1], "polyline").size(), 0U);
  EXPECT_EQ(elements(series[1], "circle").size(), 1U);
  EXPECT_EQ(samples_drawn(series[1]), 1U);
}

TEST(SvgPlotTest, LinearSeriesSpansThePlotArea) {
  // x and y in [0, 10]: ticks 0, 2, ..., 10, so the range is exactly [0, 10]
  // and the line runs corner to corner.
  Chart chart;
  chart.series.push_back(line("y = x", range(11), range(11)));
  Parsed parsed;
  parse(svg_chart(chart, 500, 300), parsed);
  const Rect area = plot_area(parsed.root());
  EXPECT_GT(area.width, 300);
  EXPECT_GT(area.height, 150);
  const auto points = points_of(elements(parsed.root(), "polyline").at(0));
  ASSERT_EQ(points.size(), 11U);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double t = static_cast<double>(i) / 10;
    EXPECT_NEAR(points[i].x, area.x + t * area.width, kPixel) << i;
    EXPECT_NEAR(points[i].y, area.y + (1 - t) * area.height, kPixel) << i;  // y grows downwards
  }
}

TEST(SvgPlotTest, GivenRangesClipTheLineToThePlotArea) {
  Chart chart;
  chart.series.push_back(line("spike", {0, 1, 2, 3, 4}, {0, 1, 50, 1, 0}));
  chart.x_range = std::pair{0.5, 4.0};
  chart.y_range = std::pair{0.0, 2.0};
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  const Rect area = plot_area(parsed.root());
  const auto lines = elements(parsed.root(), "polyline");
  // Up to y = 2 on the way to the spike, then back down from y = 2.
  ASSERT_EQ(lines.size(), 2U);
  for (const auto* polyline : lines) {
    for (const Pixel& p : points_of(polyline)) {
      EXPECT_GE(p.x, area.x - kPixel);
      EXPECT_LE(p.x, area.x + area.width + kPixel);
      EXPECT_GE(p.y, area.y - kPixel);
      EXPECT_LE(p.y, area.y + area.height + kPixel);
    }
  }
  // The first line enters at x = 0.5 (the left edge) where y = 0.5.
  const Pixel entry = points_of(lines[0]).front();
  EXPECT_NEAR(entry.x, area.x, kPixel);
  EXPECT_NEAR(entry.y, area.y + 0.75 * area.height, kPixel);
  // It leaves through the top edge.
  EXPECT_NEAR(points_of(lines[0]).back().y, area.y, kPixel);
  // Only the ticks inside the given x range are labelled (x tick labels are
  // the centred ones).
  std::vector<std::string> x_ticks;
  for (const auto* tick : elements(parsed.root(), "text", "tick")) {
    if (std::string(tick->Attribute("text-anchor")) != "middle") continue;
    x_ticks.emplace_back(tick->GetText());
    EXPECT_GE(number(tick, "x"), area.x);
    EXPECT_LE(number(tick, "x"), area.x + area.width);
  }
  EXPECT_THAT(x_ticks, ElementsAre("1", "2", "3", "4"));
}

TEST(SvgPlotTest, CoordinatesAreShortAndOutputIsDeterministic) {
  Chart chart;
  std::vector<double> x = range(10000);
  std::vector<double> y;
  y.reserve(x.size());
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 1);
  for (const double t : x) y.push_back(std::sin(t / 300) + 0.1 * noise(rng));
  chart.series.push_back(line("noisy", x, y));
  const std::string svg = svg_chart(chart);
  EXPECT_EQ(svg, svg_chart(chart));
  // "123.45,67.89 " is 13 bytes a point; allow the rest of the chart on top.
  EXPECT_LT(svg.size(), 10000U * 14 + 10000);
  Parsed parsed;
  parse(svg, parsed);
  EXPECT_EQ(samples_drawn(elements(parsed.root(), "g", "series").at(0)), 10000U);
  expect_clean_numbers(parsed.root());
}

// --- Degenerate data -------------------------------------------------------------

// Draws `chart` and checks it parses and has no NaN, inf or long numbers.
void expect_drawable(const Chart& chart) {
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  expect_clean_numbers(parsed.root());
  // Labels of the ticks have no non-finite values either.
  for (const auto* tick : elements(parsed.root(), "text", "tick")) {
    EXPECT_TRUE(std::isfinite(std::strtod(tick->GetText(), nullptr))) << tick->GetText();
  }
}

TEST(SvgPlotTest, DegenerateDataStillDraws) {
  const double big = 1e300;
  const std::vector<std::pair<std::string, Series>> cases = {
      {"empty", line("empty", {}, {})},
      {"all NaN", line("all NaN", {0, 1, 2}, {kNaN, kNaN, kNaN})},
      {"single point", line("single", {3}, {4})},
      {"constant", line("constant", {0, 1, 2}, {5, 5, 5})},
      {"constant zero", line("zero", {1, 1, 1}, {0, 0, 0})},
      {"infinite y", line("inf", {0, 1, 2}, {1, std::numeric_limits<double>::infinity(), 2})},
      {"huge", line("huge", {0, 1e6, 2e6}, {1e12, 3e12, 2e12})},
      {"tiny", line("tiny", {0, 1e-9, 2e-9}, {1e-300, 3e-300, 2e-300})},
      {"extreme", line("extreme", {-big, big},
                       {-std::numeric_limits<double>::max(), std::numeric_limits<double>::max()})},
      {"subnormal", line("subnormal", {0, 1}, {0, 4.9e-324})},
      {"near 1e9", line("near 1e9", {0, 1}, {1e9, 1e9 + 1e-5})},
  };
  for (const auto& [name, series] : cases) {
    SCOPED_TRACE(name);
    Chart chart;
    chart.series.push_back(series);
    expect_drawable(chart);
  }
  Chart nothing;  // no series at all
  expect_drawable(nothing);
}

TEST(SvgPlotTest, ConstantSeriesIsCentredInAPaddedRange) {
  Chart chart;
  chart.series.push_back(line("flat", {0, 1, 2}, {5, 5, 5}));
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  const Rect area = plot_area(parsed.root());
  for (const Pixel& p : points_of(elements(parsed.root(), "polyline").at(0))) {
    EXPECT_NEAR(p.y, area.y + area.height / 2, kPixel);
  }
}

TEST(SvgPlotTest, EmptyChartSaysSo) {
  Chart chart;
  chart.series.push_back(line("soleus", {0, 1}, {kNaN, kNaN}));
  const std::string svg = svg_chart(chart);
  EXPECT_THAT(svg, HasSubstr(">no data<"));
  EXPECT_THAT(svg, HasSubstr(">soleus<"));  // still in the legend
}

// --- Text ------------------------------------------------------------------------

TEST(SvgPlotTest, EscapesTextAndAttributes) {
  Chart chart;
  chart.title = "a<b & c>d \"q\" 'p'";
  chart.y_label = "<&>";
  chart.series.push_back(line("x<y>&z", {0, 1}, {0, 1}));
  chart.series.back().colour = "red\" onload=\"alert(1)";
  Parsed parsed;
  parse(svg_chart(chart), parsed);
  std::set<std::string> texts;
  for (const auto* text : elements(parsed.root(), "text")) texts.insert(text->GetText());
  EXPECT_EQ(texts.count(chart.title), 1U);
  EXPECT_EQ(texts.count("<&>"), 1U);
  EXPECT_EQ(texts.count("x<y>&z"), 1U);
  // The odd colour stays one attribute value: no onload attribute appears.
  const auto* polyline = elements(parsed.root(), "polyline").at(0);
  EXPECT_STREQ(polyline->Attribute("stroke"), "red\" onload=\"alert(1)");
  EXPECT_EQ(polyline->Attribute("onload"), nullptr);
}

TEST(SvgPlotTest, ControlCharactersDoNotBreakTheXml) {
  Chart chart;
  chart.title = std::string("bell\x07") + "\x01";
  Parsed parsed;
  parse(svg_chart(chart), parsed);
}

// --- Small multiples -------------------------------------------------------------

TEST(SmallMultiplesTest, OnePanelPerChartInAGrid) {
  std::vector<Chart> charts(5, knee_chart());
  Layout layout;
  layout.columns = 2;
  layout.title = "Joint angles";
  Parsed parsed;
  parse(svg_small_multiples(charts, layout), parsed);
  const auto* root = parsed.root();
  const auto panels = elements(root, "g", "panel");
  ASSERT_EQ(panels.size(), 5U);
  EXPECT_EQ(number(root, "width"), 2 * 420);
  const double title_height = number(root, "height") - 3 * 260;
  EXPECT_GT(title_height, 0);
  // Row by row: the third panel starts the second row.
  EXPECT_STREQ(panels[1]->Attribute("transform"),
               ("translate(420 " + std::to_string(static_cast<int>(title_height)) + ")").c_str());
  EXPECT_STREQ(
      panels[2]->Attribute("transform"),
      ("translate(0 " + std::to_string(static_cast<int>(title_height + 260)) + ")").c_str());
  for (const auto* panel : panels) {
    EXPECT_EQ(elements(panel, "g", "series").size(), 2U);
    EXPECT_EQ(elements(panel, "rect", "plot-area").size(), 1U);
  }
  expect_clean_numbers(root);
}

TEST(SmallMultiplesTest, FewChartsNarrowTheGridAndNoneSaySo) {
  Layout layout;
  layout.columns = 4;
  Parsed two;
  parse(svg_small_multiples({knee_chart(), knee_chart()}, layout), two);
  EXPECT_EQ(number(two.root(), "width"), 2 * 420);
  EXPECT_EQ(number(two.root(), "height"), 260);
  const std::string none = svg_small_multiples({}, layout);
  Parsed parsed;
  parse(none, parsed);
  EXPECT_THAT(none, HasSubstr(">no charts<"));
}

// --- Errors ------------------------------------------------------------------------

// The message of the InvalidInputError `draw` throws; "" when none.
template <typename F>
std::string invalid_input_of(F&& draw) {
  try {
    draw();
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return {};
}

TEST(SvgPlotTest, RejectsMismatchedLengthsNamingTheSeries) {
  Chart chart = knee_chart();
  chart.series.push_back(line("rectus femoris", {0, 1, 2}, {0, 1}));
  const std::string message = invalid_input_of([&] { svg_chart(chart); });
  EXPECT_THAT(message, HasSubstr("rectus femoris"));
  EXPECT_THAT(message, HasSubstr("3 x values but 2 y values"));
  // In small multiples the message also names the chart.
  Chart other = knee_chart();
  other.title = "Hip";
  const std::string in_grid = invalid_input_of([&] {
    svg_small_multiples({other, chart}, Layout{});
  });
  EXPECT_THAT(in_grid, HasSubstr("chart 1 ('Knee flexion')"));
  EXPECT_THAT(in_grid, HasSubstr("rectus femoris"));
}

TEST(SvgPlotTest, RejectsBadInput) {
  Chart non_finite_x;
  non_finite_x.series.push_back(line("vastus", {0, kNaN}, {0, 1}));
  EXPECT_THAT(invalid_input_of([&] { svg_chart(non_finite_x); }),
              HasSubstr("'vastus'): x[1] is nan"));
  Chart zero_width = knee_chart();
  zero_width.series[0].width = 0;
  EXPECT_THROW(svg_chart(zero_width), InvalidInputError);
  Chart bad_band = knee_chart();
  bad_band.bands = {{60, 40, "stance", ""}};
  EXPECT_THAT(invalid_input_of([&] { svg_chart(bad_band); }), HasSubstr("band 0 ('stance')"));
  Chart bad_range = knee_chart();
  bad_range.y_range = std::pair{1.0, 1.0};
  EXPECT_THAT(invalid_input_of([&] { svg_chart(bad_range); }), HasSubstr("y_range"));
  Chart bad_reference = knee_chart();
  bad_reference.y_reference_lines = {kNaN};
  EXPECT_THROW(svg_chart(bad_reference), InvalidInputError);

  EXPECT_THROW(svg_chart(knee_chart(), 0, 100), InvalidInputError);
  EXPECT_THROW(svg_chart(knee_chart(), 100, -1), InvalidInputError);
  Layout no_columns;
  no_columns.columns = 0;
  EXPECT_THROW(svg_small_multiples({knee_chart()}, no_columns), InvalidInputError);
  Layout flat;
  flat.panel_height = 0;
  EXPECT_THROW(svg_small_multiples({knee_chart()}, flat), InvalidInputError);
}

// --- Files -------------------------------------------------------------------------

TEST(WriteSvgTest, WritesTheFileAndFailsWithIoError) {
  const test::ScratchDir dir("svg_plot");
  const std::string svg = svg_chart(knee_chart());
  write_svg(svg, dir / "knee.svg");
  EXPECT_EQ(test::read_text(dir / "knee.svg"), svg);
  // No temporary file left beside it.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
  EXPECT_THROW(write_svg(svg, dir / "missing" / "knee.svg"), IoError);
}

}  // namespace
}  // namespace mmm::plot
