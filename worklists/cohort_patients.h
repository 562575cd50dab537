#pragma once
// The patients of a cohort (`mmm cohort create ROOT --workflow WF --patients
// patients.csv`): one row per patient, its id and the study inputs.
//
//   id,patient,frontal,lateral,calibration
//   p001,P001,p001/frontal.png,p001/lateral.png,p001/views.json
//   p002,P002,p002/radiographs,p002/radiographs,
//
// - The header names `id` and workflow inputs; every input without a
//   default must have a column. An unknown column is an error (with the
//   closest input name).
// - `id` is the study's folder name under the root: 1-64 of A-Z a-z 0-9 .
//   _ - (not starting with a dot), unique in the file.
// - A cell left empty takes the input's default; an input without one must
//   be given. File inputs are paths, relative to the CSV file's folder;
//   they must exist. Value inputs are checked as `study create` checks them.
// - Columns that every row shares (the atlas, the trial) may also be given
//   once on the command line (`--input NAME=VALUE`, relative to the current
//   folder); a column of the same name overrides them per row.
// - RFC 4180 quoting ("a, b", "say ""x"""), CRLF or LF, blank lines and
//   lines starting with '#' ignored. At most kMaxCohortCsvBytes and
//   kMaxCohortPatients rows, checked before the file is read in full.
// Every bad row is reported with its line number, all at once.

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "workflow/definition/workflow_definition.h"

namespace mmm::worklists {

inline constexpr std::size_t kMaxCohortCsvBytes = std::size_t{16} << 20U;
inline constexpr std::size_t kMaxCohortPatients = 100'000;

struct CohortPatient {
  std::string id;
  int line = 0;  // in the CSV file, 1-based
  // Study input name -> text for `study create` (paths made absolute).
  std::map<std::string, std::string> inputs;
};

// Reads and checks the file against the workflow's inputs; `shared` are
// inputs given once for every row. Throws InvalidInputError naming the file
// and listing every bad line (IoError when it cannot be read or is too
// large).
std::vector<CohortPatient> read_cohort_patients(const std::filesystem::path& csv,
                                                const workflow::WorkflowDefinition& workflow,
                                                const std::map<std::string, std::string>& shared);

// RFC 4180 fields of a CSV text: one vector per record, with the line each
// record starts on. Throws InvalidInputError for an unclosed quote.
struct CsvRecord {
  int line = 0;
  std::vector<std::string> fields;
};
std::vector<CsvRecord> parse_csv(std::string_view text, const std::filesystem::path& source);

}  // namespace mmm::worklists
