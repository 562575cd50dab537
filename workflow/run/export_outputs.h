#pragma once
// The workflow's exported outputs, copied from the artifact store into
// DIR/outputs/<name><extension> for people and other tools (ParaView opens
// the .ply, a spreadsheet the .json/.csv, an atlas folder its atlas.yaml). Each file is written to
// a temporary name, flushed and renamed, so outputs/ never holds a partial file; a file whose
// content is already current is left alone. An output whose node has no current result (failed,
// waiting, blocked) has its old file removed, so outputs/ never shows a result that does not match
// the study's current inputs and parameters.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "workflow/study/execution_records.h"
#include "workflow/study/study.h"

namespace mmm::workflow {

struct ExportReport {
  std::vector<std::string> written;  // export names whose file was (re)written
  std::vector<std::string> removed;  // export names whose stale file was removed
};

// `available`: node -> port -> artifact, the current results.
ExportReport export_outputs(
    Study& study, const std::map<std::string, std::map<std::string, OutputArtifact>>& available);

// What in outputs/ does not match the study's current results, one sentence
// per export ("'total': outputs/total.json holds an earlier result"): a file
// that is missing, changed or left from an earlier result, or a result not
// exported yet (a run killed while exporting). `results`: node -> port ->
// artifact, the current results (as plan_study finds them). Empty: outputs/
// matches the results. Reads only.
std::vector<std::string> stale_exports(
    Study& study, const std::map<std::string, std::map<std::string, OutputArtifact>>& results);

// The file name of an export: name + the extension of its port type; for an
// opaque File, the extension its content shows (.png, .svg, .pdf, .trc,
// .mot, .osim, .csv, .bundle for a folder bundle; none otherwise) when
// `blob` is given. An Atlas or a folder bundle is also unpacked into the
// folder DIR/outputs/<name>/.
std::string export_file_name(const std::string& name, PortType type,
                             const std::filesystem::path& blob = {});

}  // namespace mmm::workflow
