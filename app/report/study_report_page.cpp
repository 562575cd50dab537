#include "app/report/study_report_page.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "app/report/ground_truth.h"
#include "app/report/html.h"
#include "app/report/json_file.h"
#include "core/errors.h"
#include "core/plot/svg_plot.h"
#include "core/xml_escape.h"

namespace mmm::app::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Collects the page, the figures and the pending sections as it goes.
class Page {
 public:
  Page(fs::path outputs, fs::path figures)
      : outputs_(std::move(outputs)), figures_(std::move(figures)) {}

  void add(const std::string& html) { body_ += html; }
  void heading(const std::string& id, const std::string& title) {
    body_ += "<section id=\"" + id + "\">\n<h2>" + xml_escaped(title) + "</h2>\n";
  }
  void end_section() { body_ += "</section>\n"; }
  void paragraph(const std::string& text) { body_ += "<p>" + xml_escaped(text) + "</p>\n"; }
  void pending(const std::string& section, const std::string& what) {
    pending_.push_back(section);
    body_ += "<p class=\"pending\">Not computed yet: " + xml_escaped(what) + ".</p>\n";
  }

  // A PNG of the outputs copied next to the page; false when there is none.
  bool png(const std::string& name, const std::string& file, const std::string& caption) {
    const fs::path from = outputs_ / file;
    if (!fs::exists(from)) return false;
    fs::copy_file(from, figures_ / file, fs::copy_options::overwrite_existing);
    figure(name,
           "<img src=\"figures/" + xml_escaped(file) + "\" alt=\"" + xml_escaped(caption) + "\">",
           caption);
    return true;
  }
  // An SVG of the outputs, inlined; false when there is none.
  bool svg_file(const std::string& name, const std::string& file, const std::string& caption) {
    const fs::path from = outputs_ / file;
    if (!fs::exists(from)) return false;
    svg(name, read_text(from), caption);
    return true;
  }
  void svg(const std::string& name, std::string svg, const std::string& caption) {
    const auto start = svg.find("<svg");
    if (start != std::string::npos) svg.erase(0, start);  // no XML declaration inside HTML
    figure(name, svg, caption);
  }

  [[nodiscard]] const fs::path& outputs() const { return outputs_; }
  [[nodiscard]] const std::vector<std::string>& figures() const { return names_; }
  [[nodiscard]] const std::vector<std::string>& pending_sections() const { return pending_; }
  [[nodiscard]] const std::string& body() const { return body_; }

 private:
  void figure(const std::string& name, const std::string& content, const std::string& caption) {
    names_.push_back(name);
    body_ += "<figure data-figure=\"" + xml_escaped(name) + "\">\n" + content + "\n<figcaption>" +
             xml_escaped(caption) + "</figcaption>\n</figure>\n";
  }

  fs::path outputs_;
  fs::path figures_;
  std::string body_;
  std::vector<std::string> names_;
  std::vector<std::string> pending_;
};

std::string text_of(const json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

// The study input (as given: a path) that feeds port `port` of the first
// node of type `type`; "" when there is none.
std::string given_input_of(const json& status, const std::string& type, const std::string& port) {
  for (const json& node : status.value("nodes", json::array())) {
    if (node.value("type", "") != type) continue;
    const json inputs = node.value("key", json::object()).value("inputs", json::object());
    const std::string hash = inputs.is_object() ? inputs.value(port, "") : "";
    for (const json& input : status.value("inputs", json::array())) {
      if (!hash.empty() && input.value("hash", "") == hash) return input.value("given", "");
    }
  }
  return {};
}

// Where the landmarks came from, one sentence, from the set's source and the
// study's nodes.
std::string landmark_origin(const json& landmarks, const json& status) {
  const std::string source = landmarks.value("source", "");
  if (source == "slicer_markups") {
    const std::string file = given_input_of(status, "import_markups", "markups");
    return "Imported from " + (file.empty() ? std::string("a 3D Slicer point list") : file) +
           " (import_markups: 3-D points placed in 3D Slicer, checked for anatomy and "
           "orientation); no radiograph, so no reprojection error:";
  }
  if (source == "static_trial") {
    const std::string file = given_input_of(status, "static_trial_landmarks", "trial");
    return "From the static motion-capture trial " + (file.empty() ? std::string("(.trc)") : file) +
           " (static_trial_landmarks: joint centres from the markers, averaged over its "
           "frames); no radiograph:";
  }
  if (source == "radiographs") {
    return "Placed by the operator at the landmark station and triangulated from both "
           "radiographs (frontal and lateral); the reprojection error says how well the two "
           "views agree:";
  }
  return "Landmarks (source: " + (source.empty() ? std::string("not stated") : source) + "):";
}

void landmarks_section(Page& page, const ReportInput& input) {
  page.heading("landmarks", "Landmarks");
  std::vector<std::vector<std::string>> rows;
  for (const json& entry : input.audit) {
    // The landmarks a submission placed (its pixels are in the audit entry).
    std::string placed;
    const json after = entry.value("after", json());
    if (after.is_object() && after.contains("landmarks") && after["landmarks"].is_object()) {
      for (const auto& [name, views] : after["landmarks"].items()) {
        placed += (placed.empty() ? "" : ", ") + name;
      }
    }
    rows.push_back({text_of(entry.value("time", json())), text_of(entry.value("operator", json())),
                    text_of(entry.value("action", json())), text_of(entry.value("task_id", json())),
                    placed,
                    entry.value("reason", json()).is_null() ? "" : text_of(entry["reason"])});
  }
  if (rows.empty()) {
    page.pending("landmarks", "no manual action is recorded in the audit trail");
  } else {
    page.paragraph("Who did what, when (the study's audit trail, hash-chained; mmm audit verify):");
    page.add(html_table({"time (UTC)", "operator", "action", "task", "landmarks placed", "reason"},
                        rows));
  }
  const std::optional<json> landmarks = read_json_if_present(page.outputs() / "landmarks.json");
  if (landmarks) {
    std::vector<std::vector<std::string>> placed;
    for (const json& landmark : landmarks->value("landmarks", json::array())) {
      const json position = landmark.value("position_mm", json::array());
      std::string errors;
      const json errors_by_view = landmark.value("reprojection_error_mm", json::object());
      for (const auto& [view, error] : errors_by_view.items()) {
        errors += (errors.empty() ? "" : ", ") + view + " " + fixed(error.get<double>(), 2);
      }
      placed.push_back({landmark.value("name", ""),
                        position.size() == 3 ? fixed(position[0].get<double>(), 1) + ", " +
                                                   fixed(position[1].get<double>(), 1) + ", " +
                                                   fixed(position[2].get<double>(), 1)
                                             : "-",
                        errors});
    }
    page.paragraph(landmark_origin(*landmarks, input.status));
    page.add(html_table({"landmark", "position (mm)", "reprojection error (mm)"}, placed));
    if (input.truth) {
      page.add(truth_landmarks_html(*landmarks, page.outputs() / "landmarks.json", *input.truth));
    }
  }
  const bool radiographs = !landmarks || landmarks->value("source", "") == "radiographs";
  if (!page.png("overlay", "overlay.png",
                radiographs ? "The scaled bones' outlines over the frontal and lateral radiographs"
                            : "The scaled bones, front and side (no radiographs: the landmarks "
                              "did not come from them)")) {
    page.pending("overlay", "the scaled atlas over the radiographs (after scaling)");
  }
  page.end_section();
}

void scaling_section(Page& page, const ReportInput& input) {
  page.heading("scaling", "Scaling");
  const std::optional<json> report = read_json_if_present(page.outputs() / "scaling_report.json");
  if (!report) {
    page.pending("scaling", "the scaled atlas (after the landmarks are accepted)");
    page.end_section();
    return;
  }
  // The final per-bone factors (after the energy: what the patient's model
  // has), beside the first stage's estimate for the same segment.
  std::vector<std::vector<std::string>> factors;
  const json first = report->value("first_stage", json::object());
  const json segment_factors = first.value("segment_length_factor", json::object());
  for (const json& bone : report->value("bones", json::array())) {
    if (!bone.contains("length_factor") || bone.value("solve", "").starts_with("welded")) {
      continue;
    }
    const std::string name = bone.value("bone", "");
    const json stretch = bone.value("stretch_vs_first_stage", json::array());
    std::string stretches;
    for (const json& value : stretch) {
      stretches += (stretches.empty() ? "" : ", ") + fixed(value.get<double>(), 2);
    }
    factors.push_back(
        {name, fixed(bone["length_factor"].get<double>(), 3),
         segment_factors.contains(name) ? fixed(segment_factors[name].get<double>(), 3) : "-",
         stretches});
  }
  page.paragraph(
      "Per-bone length factors of the scaled model (patient / atlas, along the bone's "
      "long axis), the first stage's estimate, and the stretches relative to it:");
  page.add(html_table({"bone", "length factor", "first stage", "stretch vs first stage"}, factors));
  std::vector<std::vector<std::string>> warnings;
  for (const json& warning : report->value("warnings", json::array())) {
    warnings.push_back({warning.value("bone", ""), warning.value("part", ""),
                        warning.value("direction", ""), fixed(warning.value("factor", 1.0), 2)});
  }
  if (warnings.empty()) {
    page.paragraph("No implausible stretch: every bone within 0.75-1.35 of the first stage.");
  } else {
    page.paragraph(
        "Warning: implausible stretches (outside 0.75-1.35 of the first stage); "
        "check the landmarks on these bones:");
    page.add(html_table({"bone", "where", "direction", "factor"}, warnings));
  }
  std::vector<std::vector<std::string>> residuals;
  const json landmark_residuals = report->value("landmark_residual_mm", json::object());
  for (const auto& [name, residual] : landmark_residuals.items()) {
    residuals.push_back({name, fixed(residual.get<double>(), 3)});
  }
  page.paragraph("Landmark residuals of the scaled atlas:");
  page.add(html_table({"landmark", "residual (mm)"}, residuals));
  if (input.truth) page.add(truth_surfaces_html(page.outputs(), *input.truth, input.threads));
  page.end_section();
}

// A section's SVG plot and the node report beside it, both from the outputs.
struct PlotAndReport {
  std::string section;
  std::string figure;
  std::string svg_file;
  std::string caption;
  std::string report_file;
  std::string pending;  // what is missing while neither exists
};

// Adds the plot when it exists and returns the parsed report; marks the
// section pending when neither exists.
std::optional<json> plot_and_report(Page& page, const PlotAndReport& sources) {
  const bool plot = page.svg_file(sources.figure, sources.svg_file, sources.caption);
  std::optional<json> report = read_json_if_present(page.outputs() / sources.report_file);
  if (!plot && !report) page.pending(sources.section, sources.pending);
  return report;
}

// Per marker: how far the model's marker is from the measured one.
void marker_residuals(Page& page, const json& fit) {
  std::vector<std::vector<std::string>> rows;
  for (const json& m : fit.value("markers", json::array())) {
    rows.push_back({m.value("marker", ""), fixed(m.value("rms_mm", 0.0), 1),
                    fixed(m.value("max_mm", 0.0), 1),
                    std::to_string(m.value("frames_present", 0))});
  }
  if (rows.empty()) return;
  page.paragraph("Marker residuals (model marker to measured marker): RMS " +
                 fixed(fit.value("marker_rms_mm", 0.0), 1) + " mm over all markers and frames, " +
                 "per-frame RMS median " +
                 fixed(fit.value("marker_rms_per_frame_median_mm", 0.0), 1) + " mm, worst frame " +
                 fixed(fit.value("marker_rms_per_frame_max_mm", 0.0), 1) + " mm.");
  page.add(html_table({"marker", "RMS (mm)", "max (mm)", "frames"}, rows));
}

void motion_section(Page& page) {
  page.heading("motion", "Motion");
  const std::optional<json> report = plot_and_report(
      page, {"motion", "angles", "angle_plot.svg",
             "Joint angles over the trial (ours and OpenSim's own inverse kinematics)",
             "motion_report.json", "the retargeted walk (after scaling)"});
  if (report) {
    std::vector<std::vector<std::string>> rows;
    for (const json& c : report->value("fit", json::object()).value("coordinates", json::array())) {
      rows.push_back({c.value("coordinate", ""), fixed(c.value("min", 0.0), 1),
                      fixed(c.value("max", 0.0), 1), c.value("unit", "")});
    }
    page.paragraph("Range of each fitted coordinate over the trial:");
    page.add(html_table({"coordinate", "min", "max", "unit"}, rows));
    marker_residuals(page, report->value("fit", json::object()));
  }
  page.end_section();
}

// Where the wrapping node's time went, summed over muscles and frames.
void wrapping_stage_times(Page& page, const json& report) {
  const json muscle_reports = report.value("muscles", json::array());
  double hull_s = 0.0;
  double setup_s = 0.0;
  for (const json& m : muscle_reports) {
    hull_s += m.value("hull", json::object()).value("build_s", 0.0);
    setup_s += m.value("setup_s", 0.0);
  }
  const int frames = report.value("frames", 0);
  const std::size_t muscles = muscle_reports.size();
  const double total_s = report.value("node_seconds", 0.0);
  const double median_ms = report.value("median_ms_per_muscle_frame", 0.0);
  page.paragraph("Time per stage of the wrapping (" + std::to_string(report.value("threads", 0)) +
                 " threads):");
  page.add(html_table(
      {"stage", "seconds"},
      {{"progressive hulls built here (0 when reused from build_hulls)", fixed(hull_s, 2)},
       {"per-muscle set-up: decimation, binding, factorisation (summed over muscles)",
        fixed(setup_s, 2)},
       {"separating muscles at rest", fixed(report.value("separation_s", 0.0), 2)},
       {"measuring muscle-muscle penetration", fixed(report.value("muscle_penetration_s", 0.0), 2)},
       {"median per muscle-frame (ms), over " + std::to_string(muscles) + " muscles x " +
            std::to_string(frames) + " frames",
        fixed(median_ms, 1)},
       {"wrapping every muscle and frame (wall clock)", fixed(report.value("seconds", 0.0), 2)},
       {"whole node, with reading the atlas and writing the animation", fixed(total_s, 2)}}));
}

void wrapping_section(Page& page) {
  page.heading("wrapping", "Muscle wrapping");
  const std::optional<json> report = plot_and_report(
      page, {"wrapping", "wrapping", "wrapping_plot.svg",
             "Per muscle and frame: volume error, depth inside bone, time, smoothness change",
             "wrapping_report.json", "the wrapped muscles (after the motion)"});
  if (report) {
    // Muscle-muscle depth when the wrapping measured it (muscle_penetration).
    const bool measured = report->value("muscle_penetration_measured", false);
    std::vector<std::vector<std::string>> rows;
    for (const json& m : report->value("muscles", json::array())) {
      std::vector<std::string> row = {m.value("muscle", ""),
                                      fixed(m.value("max_abs_volume_error_percent", 0.0), 6),
                                      fixed(m.value("max_depth_mm", 0.0), 2)};
      if (measured) row.push_back(fixed(m.value("max_depth_in_other_muscles_mm", 0.0), 2));
      row.push_back(fixed(m.value("median_ms_per_frame", 0.0), 1));
      rows.push_back(std::move(row));
    }
    page.paragraph("Worst frame per muscle over " + std::to_string(report->value("frames", 0)) +
                   " frames:");
    std::vector<std::string> header = {"muscle", "volume error (%)", "depth in bone (mm)"};
    if (measured) header.emplace_back("depth in other muscles (mm)");
    header.emplace_back("median ms per frame");
    page.add(html_table(header, rows));
    if (measured) {
      page.paragraph("Deepest vertex of a muscle inside another muscle over the trial: " +
                     fixed(report->value("max_depth_in_other_muscles_mm", 0.0), 2) +
                     " mm (the segmentations already overlap at rest; muscles are deformed one "
                     "by one, so nothing keeps them apart unless muscle_contacts is on).");
    } else {
      page.paragraph(
          "Muscle-muscle penetration was not measured (wrap_muscles's "
          "muscle_penetration is off).");
    }
    wrapping_stage_times(page, *report);
  }
  page.end_section();
}

// Mean fibre length per muscle and frame, relative to its mean over the trial.
plot::Chart fibre_length_chart(const fs::path& csv_file) {
  std::ifstream in(csv_file);
  std::string line;
  std::getline(in, line);                                                // header
  std::map<std::string, std::map<double, std::pair<double, int>>> sums;  // muscle -> time -> sum, n
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream cell_stream(line);
    for (std::string cell; std::getline(cell_stream, cell, ',');) cells.push_back(cell);
    if (cells.size() != 6) {
      throw InvalidInputError(csv_file.string() + ": a row without 6 columns: '" + line + "'");
    }
    auto& [sum, n] = sums[cells[0]][std::stod(cells[4])];
    sum += std::stod(cells[5]);
    ++n;
  }
  plot::Chart chart;
  chart.title = "Mean fibre length per muscle over the trial";
  chart.x_label = "time (s)";
  chart.y_label = "relative to its trial mean (%)";
  for (const auto& [muscle, by_time] : sums) {
    plot::Series series;
    series.label = muscle;
    double total = 0.0;
    for (const auto& [time, sum_n] : by_time) total += sum_n.first / sum_n.second;
    const double mean = total / static_cast<double>(by_time.size());
    for (const auto& [time, sum_n] : by_time) {
      series.x.push_back(time);
      series.y.push_back(100.0 * (sum_n.first / sum_n.second / mean - 1.0));
    }
    chart.series.push_back(std::move(series));
  }
  chart.y_reference_lines = {0.0};
  return chart;
}

void fibres_section(Page& page) {
  page.heading("fibres", "Muscle fibres");
  const bool picture =
      page.png("fibre_picture", "fibre_picture.png", "A muscle with its fibres, front and side");
  const fs::path lengths = page.outputs() / "fibre_lengths.csv";
  if (fs::exists(lengths)) {
    page.svg("fibre_lengths", plot::svg_chart(fibre_length_chart(lengths), 900, 520),
             "Fibre length curves: each muscle's mean fibre length over the trial");
  }
  if (!picture && !fs::exists(lengths)) {
    page.pending("fibres", "the fibres (after the wrapping)");
  }
  page.end_section();
}

void provenance_section(Page& page, const json& status) {
  page.heading("provenance", "Provenance");
  const json meta = status.value("meta", json::object());
  page.add(html_table(
      {"study", "workflow", "workflow hash", "mmm", "git revision", "created"},
      {{status.value("study", ""), status.value("workflow", ""),
        text_of(meta.value("workflow_hash", json(""))),
        text_of(meta.value("mmm_version", json(""))), text_of(meta.value("git_revision", json(""))),
        text_of(meta.value("created_at", json("")))}}));
  std::vector<std::vector<std::string>> nodes;
  for (const json& node : status.value("nodes", json::array())) {
    const json result = node.value("result", json::object());
    std::string params;
    const json params_json = node.value("key", json::object()).value("params", json::object());
    for (const auto& [name, value] : params_json.items()) {
      params +=
          (params.empty() ? "" : ", ") + name + "=" +
          (value.is_object() && !value.empty() ? text_of(value.begin().value()) : text_of(value));
    }
    nodes.push_back({node.value("id", ""), node.value("type", ""),
                     std::to_string(node.value("version", 0)), node.value("state", ""),
                     result.contains("seconds") ? fixed(result["seconds"].get<double>(), 2) : "-",
                     node.value("cache_key", std::string()).substr(0, 12), params});
  }
  page.paragraph("Nodes (time per stage, cache keys and parameters):");
  page.add(html_table({"node", "type", "version", "state", "seconds", "cache key", "parameters"},
                      nodes));
  std::vector<std::vector<std::string>> inputs;
  for (const json& in : status.value("inputs", json::array())) {
    inputs.push_back({in.value("name", ""), in.value("type", ""),
                      in.value("hash", std::string()).substr(0, 12), in.value("given", "")});
  }
  page.paragraph("Inputs (SHA-256 of their content):");
  page.add(html_table({"input", "type", "hash", "given as"}, inputs));
  page.end_section();
}

}  // namespace

ReportResult write_study_report(const ReportInput& input, const fs::path& out) {
  const fs::path figures = out / "figures";
  fs::remove_all(figures);
  fs::create_directories(figures);
  Page page(input.outputs, figures);
  landmarks_section(page, input);
  scaling_section(page, input);
  motion_section(page);
  wrapping_section(page);
  fibres_section(page);
  provenance_section(page, input.status);
  const fs::path study_dir = input.status.value("study", std::string());
  const std::string title = "mmm study report: " + study_dir.filename().string();
  const std::string html = html_page(
      title, "<p>State: " + xml_escaped(input.status.value("state", std::string())) +
                 ". Study folder: " + xml_escaped(study_dir.string()) + "</p>\n" + page.body());
  ReportResult result{out / "index.html", page.figures(), page.pending_sections()};
  const fs::path partial = out / "index.html.partial";
  {
    std::ofstream file(partial, std::ios::binary);
    file << html;
    if (!file) throw InvalidInputError(partial.string() + ": cannot be written");
  }
  fs::rename(partial, result.index);
  return result;
}

}  // namespace mmm::app::report
