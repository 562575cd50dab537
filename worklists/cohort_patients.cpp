// The cohort's patients CSV: RFC 4180 records, then each row checked
// against the workflow's study inputs, every problem collected.

#include "worklists/cohort_patients.h"

#include <sys/stat.h>

#include <algorithm>
#include <set>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/suggest.h"
#include "workflow/port_type.h"
#include "workflow/study/value_text.h"

namespace mmm::worklists {

namespace fs = std::filesystem;

namespace {

bool valid_id(const std::string& id) {
  if (id.empty() || id.size() > 64 || id.front() == '.') return false;
  return std::ranges::all_of(id, [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '_' || c == '-';
  });
}

bool blank(const CsvRecord& record) {
  return record.fields.empty() || (record.fields.size() == 1 && record.fields[0].empty());
}

}  // namespace

std::vector<CsvRecord> parse_csv(std::string_view text, const fs::path& source) {
  std::vector<CsvRecord> records;
  CsvRecord record{1, {}};
  std::string field;
  bool quoted = false;
  bool field_started = false;
  int line = 1;
  int quote_line = 0;
  const auto end_field = [&] {
    record.fields.push_back(std::move(field));
    field.clear();
    field_started = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        if (c == '\n') ++line;
        field += c;
      }
      continue;
    }
    if (c == '"' && !field_started) {
      quoted = true;
      field_started = true;
      quote_line = line;
    } else if (c == ',') {
      end_field();
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      end_field();
      records.push_back(std::move(record));
      ++line;
      record = CsvRecord{line, {}};
    } else {
      field += c;
      field_started = true;
    }
  }
  if (quoted) {
    throw InvalidInputError(source.string() + ": line " + std::to_string(quote_line) +
                            ": a quoted field is not closed; hint: double a quote inside a "
                            "quoted field (\"\")");
  }
  if (field_started || !record.fields.empty()) {
    end_field();
    records.push_back(std::move(record));
  }
  // Blank lines and comments.
  std::erase_if(records, [](const CsvRecord& r) {
    return blank(r) || (!r.fields.empty() && r.fields[0].starts_with('#'));
  });
  return records;
}

std::vector<CohortPatient> read_cohort_patients(const fs::path& csv,
                                                const workflow::WorkflowDefinition& workflow,
                                                const std::map<std::string, std::string>& shared) {
  struct stat info {};
  if (::stat(csv.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
    throw IoError(csv,
                  "no such file; hint: --patients names the CSV file with one row per "
                  "patient (id and the study inputs)");
  }
  if (static_cast<std::size_t>(info.st_size) > kMaxCohortCsvBytes) {
    throw IoError(csv, "is " + std::to_string(info.st_size) +
                           " bytes; a patients file is at most " +
                           std::to_string(kMaxCohortCsvBytes) + " (16 MiB)");
  }
  const std::string text = read_file_bytes(csv, static_cast<std::uintmax_t>(info.st_size));
  std::vector<CsvRecord> records = parse_csv(text, csv);
  if (records.empty()) {
    throw InvalidInputError(csv.string() +
                            ": no header; hint: the first line names the columns, "
                            "e.g. id,patient,frontal,lateral");
  }
  if (records.size() - 1 > kMaxCohortPatients) {
    throw InvalidInputError(csv.string() + ": " + std::to_string(records.size() - 1) +
                            " patients; a cohort file holds at most " +
                            std::to_string(kMaxCohortPatients));
  }
  const fs::path base = fs::absolute(csv).parent_path();
  std::vector<std::string> input_names;
  for (const workflow::StudyInput& input : workflow.inputs) input_names.push_back(input.name);

  // The header.
  const CsvRecord header = records.front();
  std::vector<std::string> problems;
  const auto problem = [&](int line, const std::string& text_of_problem) {
    problems.push_back("line " + std::to_string(line) + ": " + text_of_problem);
  };
  std::map<std::string, std::size_t> column;
  for (std::size_t k = 0; k < header.fields.size(); ++k) {
    const std::string& name = header.fields[k];
    if (name != "id" && workflow.find_input(name) == nullptr) {
      problem(header.line, "column '" + name + "' is not an input of the workflow" +
                               did_you_mean(name, input_names) +
                               " (its inputs: " + join_names(input_names) + ")");
    } else if (!column.emplace(name, k).second) {
      problem(header.line, "column '" + name + "' appears twice");
    }
  }
  if (!column.contains("id")) problem(header.line, "no column 'id' (the study's folder name)");
  for (const auto& [name, value] : shared) {
    if (workflow.find_input(name) == nullptr) {
      throw InvalidInputError("--input " + name + "=...: not an input of the workflow" +
                              did_you_mean(name, input_names));
    }
  }
  for (const workflow::StudyInput& input : workflow.inputs) {
    if (!column.contains(input.name) && !shared.contains(input.name) && !input.default_value) {
      problem(header.line, "no column for the input '" + input.name +
                               "', which has no default (or give it once with --input " +
                               input.name + "=...)");
    }
  }
  if (!problems.empty()) {
    throw InvalidInputError(csv.string() + ": the header is wrong:\n  " + [&] {
      std::string all;
      for (const std::string& p : problems) all += (all.empty() ? "" : "\n  ") + p;
      return all;
    }());
  }

  std::vector<CohortPatient> patients;
  std::set<std::string, std::less<>> ids;
  for (std::size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    if (record.fields.size() != header.fields.size()) {
      problem(record.line, std::to_string(record.fields.size()) + " fields, the header has " +
                               std::to_string(header.fields.size()));
      continue;
    }
    CohortPatient patient;
    patient.line = record.line;
    patient.id = record.fields[column.at("id")];
    if (!valid_id(patient.id)) {
      problem(record.line, "id '" + patient.id +
                               "' is not a folder name: 1-64 of A-Z a-z 0-9 . _ - , not "
                               "starting with a dot");
    } else if (!ids.insert(patient.id).second) {
      problem(record.line, "id '" + patient.id + "' is used by an earlier row");
    }
    for (const workflow::StudyInput& input : workflow.inputs) {
      std::string value;
      fs::path relative_to = base;
      if (const auto it = column.find(input.name); it != column.end()) {
        value = record.fields[it->second];
      }
      if (value.empty()) {
        if (const auto it = shared.find(input.name); it != shared.end()) {
          value = it->second;
          relative_to = fs::current_path();
        }
      }
      if (value.empty()) {
        if (!input.default_value) {
          problem(record.line, "input '" + input.name + "' is empty and has no default");
        }
        continue;
      }
      if (!input.type) continue;  // the workflow's own validation names the type
      if (workflow::is_value_type(*input.type)) {
        try {
          (void)workflow::parse_value_text(*input.type, value, "input '" + input.name + "'");
        } catch (const std::exception& error) {
          problem(record.line, error.what());
          continue;
        }
        patient.inputs[input.name] = value;
        continue;
      }
      const fs::path path = (relative_to / value).lexically_normal();
      std::error_code error;
      if (!fs::exists(path, error)) {
        problem(record.line, "input '" + input.name + "': " + path.string() + " does not exist");
        continue;
      }
      patient.inputs[input.name] = path.string();
    }
    patients.push_back(std::move(patient));
  }
  if (!problems.empty()) {
    std::string all;
    for (const std::string& p : problems) all += "\n  " + p;
    throw InvalidInputError(csv.string() + ": " + std::to_string(problems.size()) +
                            " problem(s), nothing was created:" + all);
  }
  return patients;
}

}  // namespace mmm::worklists
