#pragma once
// The cohort report (`mmm cohort report ROOT`): one offline HTML page (no
// scripts, no network) across every study under a root, from what each
// study already holds (its database and its outputs folder):
//
//   throughput  studies per state, compute time per study, the span from
//               the first run to the last, studies done per hour
//   figures     per figure, its distribution over the studies (median, 5th
//               and 95th percentiles, range, a strip plot) and its outliers
//               (further than 3 scaled median absolute deviations from the
//               median), each linked to its study's report:
//                 scaling: femur and tibia length factors, stretch warnings;
//                 landmarks: worst reprojection error;
//                 outlines: mean contour residual;
//                 motion: marker RMS;
//                 wrapping: volume error, depth in bone, depth in other
//                 muscles; fibres: fraction inside the muscle
//   operators   per operator: landmark sets accepted, their reprojection
//               errors (median, 95th percentile, worst)
//   studies     one row per study: state, patient, compute time, report
//
// A study without a figure's output yet (waiting, failed) is counted as
// such, not as a value.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace mmm::app::report {

struct CohortStudyFigures {
  std::string study;           // relative to the root
  std::string patient;         // the study input 'patient', else the folder name
  std::string state;           // as `mmm cohort status` says
  double compute_seconds = 0;  // all its runs
  std::string first_started;
  std::string last_finished;
  std::map<std::string, double> figures;  // figure key -> value
  // Landmark reprojection errors (worst view, mm) by who placed them.
  std::string landmark_operator;
  std::vector<double> landmark_errors_mm;
};

// Everything the page shows, read from the studies under `root`.
std::vector<CohortStudyFigures> gather_cohort_figures(const std::filesystem::path& root);

struct CohortReportResult {
  std::filesystem::path index;
  std::size_t studies = 0;
  std::size_t outliers = 0;
};

// Writes out/index.html (replacing an earlier one). Throws IoError when root
// is not a folder or a study's output cannot be parsed (naming the file).
CohortReportResult write_cohort_report(const std::filesystem::path& root,
                                       const std::filesystem::path& out);

}  // namespace mmm::app::report
