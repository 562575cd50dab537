// The cohort report: figures gathered from each study's database and
// outputs, their distributions and outliers, the operators' landmark
// errors, throughput (cohort_report_page.h).

#include "app/report/cohort_report_page.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "app/report/html.h"
#include "app/report/json_file.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/xml_escape.h"
#include "workflow/host_and_time.h"
#include "workflow/store/sqlite.h"
#include "worklists/cohort.h"
#include "worklists/task_store.h"
#include "worklists/worklist.h"

namespace mmm::app::report {

namespace fs = std::filesystem;
using CohortJson = nlohmann::json;

namespace {

struct FigureSpec {
  const char* key;
  const char* section;
  const char* label;
  const char* unit;
  int decimals;
};

// In page order.
constexpr std::array<FigureSpec, 11> kFigures = {{
    {"femur_length_factor", "scaling", "femur length factor", "", 3},
    {"tibia_length_factor", "scaling", "tibia length factor", "", 3},
    {"stretch_warnings", "scaling", "implausible stretch warnings", "", 0},
    {"landmark_error_mm", "landmarks", "worst landmark reprojection error", "mm", 2},
    {"contour_residual_mm", "outlines", "mean contour residual (all fitted bones)", "mm", 2},
    {"marker_rms_mm", "motion", "marker RMS", "mm", 1},
    {"volume_error_percent", "wrapping", "worst volume error", "%", 4},
    {"depth_in_bone_mm", "wrapping", "deepest vertex in bone", "mm", 2},
    {"depth_in_muscles_mm", "wrapping", "deepest vertex in another muscle", "mm", 2},
    {"fibres_inside", "fibres", "fraction of fibre points inside the muscle (worst)", "", 4},
    {"compute_seconds", "throughput", "compute time of the study's runs", "s", 1},
}};

double number_or_nan(const CohortJson& value) {
  return value.is_number() ? value.get<double>() : std::nan("");
}

void put(CohortStudyFigures& study, const char* key, double value) {
  if (std::isfinite(value)) study.figures[key] = value;
}

void read_outputs(const fs::path& outputs, CohortStudyFigures& study) {
  if (const auto scaling = read_json_if_present(outputs / "scaling_report.json")) {
    const CohortJson factors = scaling->value("length_factor", CohortJson::object());
    put(study, "femur_length_factor", number_or_nan(factors.value("femur_r", CohortJson())));
    put(study, "tibia_length_factor", number_or_nan(factors.value("tibia_r", CohortJson())));
    put(study, "stretch_warnings",
        static_cast<double>(scaling->value("warnings", CohortJson::array()).size()));
  }
  if (const auto landmarks = read_json_if_present(outputs / "landmarks.json")) {
    double worst = std::nan("");
    for (const CohortJson& landmark : landmarks->value("landmarks", CohortJson::array())) {
      double error = std::nan("");
      const CohortJson by_view = landmark.value("reprojection_error_mm", CohortJson::object());
      for (const auto& [view, value] : by_view.items()) {
        error = std::isnan(error) ? number_or_nan(value) : std::max(error, number_or_nan(value));
      }
      if (std::isfinite(error)) {
        study.landmark_errors_mm.push_back(error);
        worst = std::isnan(worst) ? error : std::max(worst, error);
      }
    }
    put(study, "landmark_error_mm", worst);
  }
  if (const auto outlines = read_json_if_present(outputs / "outline_report.json")) {
    double sum = 0;
    int count = 0;
    for (const CohortJson& bone : outlines->value("bones", CohortJson::array())) {
      for (const CohortJson& view : bone.value("views", CohortJson::array())) {
        const double mean = number_or_nan(view.value("mean_mm", CohortJson()));
        if (std::isfinite(mean)) {
          sum += mean;
          ++count;
        }
      }
    }
    if (count > 0) put(study, "contour_residual_mm", sum / count);
  }
  if (const auto motion = read_json_if_present(outputs / "motion_report.json")) {
    put(study, "marker_rms_mm",
        number_or_nan(
            motion->value("fit", CohortJson::object()).value("marker_rms_mm", CohortJson())));
  }
  if (const auto wrapping = read_json_if_present(outputs / "wrapping_report.json")) {
    put(study, "volume_error_percent",
        number_or_nan(wrapping->value("max_abs_volume_error_percent", CohortJson())));
    put(study, "depth_in_bone_mm", number_or_nan(wrapping->value("max_depth_mm", CohortJson())));
    if (wrapping->value("muscle_penetration_measured", false)) {
      put(study, "depth_in_muscles_mm",
          number_or_nan(wrapping->value("max_depth_in_other_muscles_mm", CohortJson())));
    }
  }
  if (const auto fibres = read_json_if_present(outputs / "fibre_report.json")) {
    put(study, "fibres_inside", number_or_nan(fibres->value("min_inside_fraction", CohortJson())));
  }
}

void read_database(const fs::path& dir, CohortStudyFigures& study) {
  workflow::Database database(dir / "study.db");
  workflow::Statement runs =
      database.prepare("SELECT started_at, COALESCE(finished_at, '') FROM runs ORDER BY id");
  while (runs.step()) {
    const std::string started = runs.column_text(0);
    const std::string finished = runs.column_text(1);
    if (study.first_started.empty()) study.first_started = started;
    if (!finished.empty()) {
      study.last_finished = finished;
      const double a = worklists::utc_seconds(started);
      const double b = worklists::utc_seconds(finished);
      if (a > 0 && b >= a) study.compute_seconds += b - a;
    }
  }
  if (study.compute_seconds > 0) put(study, "compute_seconds", study.compute_seconds);
  study.patient = worklists::patient_of(database, dir);
  if (worklists::tasks_table_exists(database)) {
    workflow::Statement placed = database.prepare(
        "SELECT submitted_by FROM tasks WHERE node_type = 'landmark_station' AND state = "
        "'accepted' ORDER BY updated_at DESC LIMIT 1");
    if (placed.step()) study.landmark_operator = placed.column_text(0);
  }
}

double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  const double at = p * static_cast<double>(values.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(at));
  const std::size_t above = std::min(below + 1, values.size() - 1);
  return values[below] + (at - static_cast<double>(below)) * (values[above] - values[below]);
}

struct Distribution {
  double median = 0, p5 = 0, p25 = 0, p75 = 0, p95 = 0, min = 0, max = 0, spread = 0;
};

Distribution distribution_of(const std::vector<double>& values) {
  Distribution d;
  d.median = percentile(values, 0.5);
  d.p5 = percentile(values, 0.05);
  d.p25 = percentile(values, 0.25);
  d.p75 = percentile(values, 0.75);
  d.p95 = percentile(values, 0.95);
  d.min = *std::min_element(values.begin(), values.end());
  d.max = *std::max_element(values.begin(), values.end());
  std::vector<double> deviations;
  deviations.reserve(values.size());
  for (const double v : values) deviations.push_back(std::abs(v - d.median));
  d.spread = 1.4826 * percentile(deviations, 0.5);  // the MAD scaled to a normal's sigma
  return d;
}

bool is_outlier(double value, const Distribution& d) {
  return d.spread > 0 && std::abs(value - d.median) > 3 * d.spread;
}

// A strip plot: the 25-75 % box, the median, one dot per study (outliers red).
std::string strip_svg(const std::vector<std::pair<std::string, double>>& values,
                      const Distribution& d) {
  constexpr double kWidth = 360;
  constexpr double kPad = 8;
  const double span = d.max > d.min ? d.max - d.min : 1.0;
  const auto x = [&](double v) {
    return kPad + (d.max > d.min ? (v - d.min) / span : 0.5) * (kWidth - 2 * kPad);
  };
  std::string svg =
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="360" height="26" viewBox="0 0 360 26">)";
  svg += R"(<rect x=")" + fixed(x(d.p25), 1) + R"(" y="5" width=")" +
         fixed(std::max(1.0, x(d.p75) - x(d.p25)), 1) +
         R"(" height="16" fill="#dde" stroke="#99a"/>)";
  svg += R"(<line x1=")" + fixed(x(d.median), 1) + R"(" x2=")" + fixed(x(d.median), 1) +
         R"(" y1="3" y2="23" stroke="#225" stroke-width="2"/>)";
  for (const auto& [study, value] : values) {
    svg += R"(<circle cx=")" + fixed(x(value), 1) + R"(" cy="13" r="3" fill=")" +
           (is_outlier(value, d) ? "#c22" : "#557") + R"(" fill-opacity="0.7"><title>)" +
           xml_escaped(study) + ": " + fixed(value, 4) + "</title></circle>";
  }
  return svg + "</svg>";
}

// A link to the study's report from the cohort report's folder, or how to
// make one.
std::string study_link(const fs::path& root, const fs::path& out, const std::string& study) {
  const fs::path report = root / study / "report" / "index.html";
  std::error_code error;
  if (fs::exists(report, error)) {
    const std::string href = fs::relative(report, out, error).generic_string();
    return "<a href=\"" + xml_escaped(href) + "\">" + xml_escaped(study) + "</a>";
  }
  return xml_escaped(study) + " (<code>mmm report " + xml_escaped((root / study).string()) +
         "</code>)";
}

std::string heading(const std::string& id, const std::string& title) {
  return "<h2 id=\"" + id + "\">" + xml_escaped(title) + "</h2>\n";
}

}  // namespace

std::vector<CohortStudyFigures> gather_cohort_figures(const fs::path& root) {
  const worklists::CohortStatus status = worklists::cohort_status(root);
  std::vector<CohortStudyFigures> studies;
  studies.reserve(status.studies.size());
  for (const worklists::CohortStudyState& state : status.studies) {
    CohortStudyFigures study;
    study.study = state.study;
    study.state = state.state;
    const fs::path dir = root / state.study;
    read_database(dir, study);
    read_outputs(dir / "outputs", study);
    studies.push_back(std::move(study));
  }
  return studies;
}

CohortReportResult write_cohort_report(const fs::path& root, const fs::path& out) {
  const std::vector<CohortStudyFigures> studies = gather_cohort_figures(root);
  CohortReportResult result;
  result.studies = studies.size();
  fs::create_directories(out);
  std::string body;

  // Throughput.
  std::map<std::string, int> states;
  std::vector<double> seconds;
  std::string first;
  std::string last;
  for (const CohortStudyFigures& study : studies) {
    ++states[study.state];
    if (study.compute_seconds > 0) seconds.push_back(study.compute_seconds);
    if (!study.first_started.empty() && (first.empty() || study.first_started < first)) {
      first = study.first_started;
    }
    if (study.last_finished > last) last = study.last_finished;
  }
  body += heading("throughput", "Throughput");
  std::vector<std::vector<std::string>> state_rows;
  state_rows.reserve(states.size());
  for (const auto& [state, count] : states) state_rows.push_back({state, std::to_string(count)});
  body += html_table({"state", "studies"}, state_rows);
  const double span = first.empty() || last.empty()
                          ? 0.0
                          : worklists::utc_seconds(last) - worklists::utc_seconds(first);
  const int done = states.contains("done") ? states.at("done") : 0;
  body += "<p>" + std::to_string(done) + " of " + std::to_string(studies.size()) +
          " studies done. First run " + xml_escaped(first.empty() ? "-" : first) + ", last " +
          xml_escaped(last.empty() ? "-" : last) + " (" + fixed(span / 3600.0, 2) + " h" +
          (span > 0 ? ", " + fixed(done / (span / 3600.0), 1) + " studies done per hour" : "") +
          "). Compute time per study (all its runs, waiting for operators excluded): median " +
          (seconds.empty() ? std::string("-") : fixed(percentile(seconds, 0.5), 1) + " s") +
          ".</p>\n";

  // Figures.
  body += heading("figures", "Figures across the cohort");
  body +=
      "<p>Per figure: the studies that have it, its distribution, and the studies further than 3 "
      "scaled median absolute deviations from the median (red dots; linked to their reports). "
      "Box: 25-75 %; line: median.</p>\n";
  std::string rows =
      "<table><tr><th>section</th><th>figure</th><th>studies</th><th>median</th><th>5-95 %</th>"
      "<th>range</th><th>outliers</th><th>distribution</th></tr>\n";
  const auto cell = [](const std::string& text) { return "<td>" + xml_escaped(text) + "</td>"; };
  std::string outlier_html;
  for (const FigureSpec& spec : kFigures) {
    std::vector<std::pair<std::string, double>> values;
    for (const CohortStudyFigures& study : studies) {
      const auto it = study.figures.find(spec.key);
      if (it != study.figures.end()) values.emplace_back(study.study, it->second);
    }
    const std::string name =
        std::string(spec.label) + (*spec.unit ? " (" + std::string(spec.unit) + ")" : "");
    if (values.empty()) {
      rows += "<tr>" + cell(spec.section) + cell(name) + cell("0") + cell("-") + cell("-") +
              cell("-") + cell("-") + cell("") + "</tr>\n";
      continue;
    }
    std::vector<double> numbers;
    numbers.reserve(values.size());
    for (const auto& [study, value] : values) numbers.push_back(value);
    const Distribution d = distribution_of(numbers);
    std::vector<std::string> outliers;
    for (const auto& [study, value] : values) {
      if (is_outlier(value, d)) {
        outliers.push_back(study);
        outlier_html += "<li>" + xml_escaped(name) + ": " + study_link(root, out, study) + " " +
                        fixed(value, spec.decimals) + " (median " + fixed(d.median, spec.decimals) +
                        ")</li>\n";
      }
    }
    result.outliers += outliers.size();
    rows += "<tr>" + cell(spec.section) + cell(name) + cell(std::to_string(values.size())) +
            cell(fixed(d.median, spec.decimals)) +
            cell(fixed(d.p5, spec.decimals) + " - " + fixed(d.p95, spec.decimals)) +
            cell(fixed(d.min, spec.decimals) + " - " + fixed(d.max, spec.decimals)) +
            cell(std::to_string(outliers.size())) + "<td data-figure=\"" + spec.key + "\">" +
            strip_svg(values, d) + "</td></tr>\n";
  }
  body += rows + "</table>\n";
  body += outlier_html.empty() ? "<p>No outlier.</p>\n"
                               : "<p>Outliers:</p>\n<ul>\n" + outlier_html + "</ul>\n";

  // Operators.
  body += heading("operators", "Operators: landmark reprojection errors");
  std::map<std::string, std::vector<double>> by_operator;
  std::map<std::string, int> sets;
  for (const CohortStudyFigures& study : studies) {
    if (study.landmark_errors_mm.empty()) continue;
    const std::string who =
        study.landmark_operator.empty() ? "(imported)" : study.landmark_operator;
    ++sets[who];
    auto& errors = by_operator[who];
    errors.insert(errors.end(), study.landmark_errors_mm.begin(), study.landmark_errors_mm.end());
  }
  std::vector<std::vector<std::string>> operator_rows;
  operator_rows.reserve(by_operator.size());
  for (const auto& [who, errors] : by_operator) {
    operator_rows.push_back({who, std::to_string(sets.at(who)), std::to_string(errors.size()),
                             fixed(percentile(errors, 0.5), 2), fixed(percentile(errors, 0.95), 2),
                             fixed(*std::max_element(errors.begin(), errors.end()), 2)});
  }
  body += operator_rows.empty() ? "<p class=\"pending\">No landmark set accepted yet.</p>\n"
                                : html_table({"operator", "studies", "landmarks", "median (mm)",
                                              "95 % (mm)", "worst (mm)"},
                                             operator_rows);

  // Studies.
  body += heading("studies", "Studies");
  std::string table =
      "<table><tr><th>study</th><th>patient</th><th>state</th><th>compute time "
      "(s)</th></tr>\n";
  for (const CohortStudyFigures& study : studies) {
    table += "<tr><td>" + study_link(root, out, study.study) + "</td><td>" +
             xml_escaped(study.patient) + "</td><td>" + xml_escaped(study.state) + "</td><td>" +
             fixed(study.compute_seconds, 1) + "</td></tr>\n";
  }
  body += table + "</table>\n";

  const std::string title = "Cohort " + fs::absolute(root).lexically_normal().filename().string();
  const std::string page =
      html_page(title, "<p>" + std::to_string(studies.size()) + " studies, written " +
                           workflow::utc_now() + " by mmm.</p>\n" + body);
  result.index = out / "index.html";
  write_file_atomically(result.index, page, "the cohort report");
  return result;
}

}  // namespace mmm::app::report
