#pragma once
// The study report for people: one offline HTML page (index.html, no
// scripts, no network) with the figures beside it, built from what a study
// already holds: its status (nodes, times, cache keys, inputs), its audit
// trail and its outputs folder. Sections whose outputs do not exist yet (a
// study still waiting for its landmarks) say so instead of failing.
//
//   landmarks   who did what when (audit), the accepted landmarks with their
//               reprojection errors, the scaled bones over both radiographs
//   scaling     per-segment length factors, landmark residuals; for a
//               synthetic patient (ReportInput::truth) the errors of the
//               landmarks and of every surface against its ground truth
//   motion      joint angles over the trial, the fit's coordinate ranges,
//               marker residuals
//   wrapping    volume error, depth in bone and (when measured) in other
//               muscles, time per muscle (table + plot), time per stage
//   fibres      a muscle with its fibres, fibre length curves over the trial
//   provenance  mmm version, workflow hash, per node: type, version, state,
//               seconds, cache key, parameters; inputs with their hashes
//
// Every figure is a <figure data-figure="NAME"> holding an <img> (a PNG in
// figures/) or an inline <svg>.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace mmm::app::report {

struct ReportInput {
  nlohmann::json status;  // app::study_status
  nlohmann::json audit;   // worklists::audit_to_json
  std::filesystem::path outputs;
  // A synthetic patient's folder (mmm patient synth): adds the ground-truth
  // comparison to the scaling section.
  std::optional<std::filesystem::path> truth;
  int threads = 2;
};

struct ReportResult {
  std::filesystem::path index;       // out/index.html
  std::vector<std::string> figures;  // data-figure names, in page order
  std::vector<std::string> pending;  // sections without their outputs yet
};

// Writes out/index.html and out/figures/ (replacing an earlier report there).
// Throws InvalidInputError naming an output file that exists but cannot be
// read or parsed, or a truth folder that is not a synthetic patient's.
ReportResult write_study_report(const ReportInput& input, const std::filesystem::path& out);

}  // namespace mmm::app::report
