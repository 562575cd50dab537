// mmm report: the study report for people (app/report/study_report_page.h).

#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "app/commands/commands.h"
#include "app/commands/study_report.h"
#include "app/report/study_report_page.h"
#include "workflow/study/study.h"
#include "worklists/audit_export.h"
#include "worklists/audit_trail.h"

namespace mmm::app {
namespace {

struct ReportArgs {
  std::string dir;
  std::string out;
  std::string truth;
  int threads = 2;
};

void run_report(const ReportArgs& args, const workflow::NodeRegistry& registry) {
  workflow::Study study = workflow::Study::open(args.dir, registry);
  worklists::prepare_audit_tables(study.database());
  const report::ReportInput input{
      .status = study_status(study),
      .audit = worklists::audit_to_json(worklists::read_audit(study.database())),
      .outputs = study.dir() / "outputs",
      .truth = args.truth.empty() ? std::nullopt : std::optional<std::filesystem::path>(args.truth),
      .threads = args.threads};
  const std::filesystem::path out =
      args.out.empty() ? study.dir() / "report" : std::filesystem::path(args.out);
  std::filesystem::create_directories(out);
  const report::ReportResult result = report::write_study_report(input, out);
  std::cout << "report: " << result.index.string() << " (" << result.figures.size()
            << " figures; open it in a browser, it needs no network)\n";
  if (!result.pending.empty()) {
    std::cout << "not computed yet:";
    for (const std::string& section : result.pending) std::cout << ' ' << section;
    std::cout << " (run the study further, then report again)\n";
  }
}

}  // namespace

void register_report_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto args = std::make_shared<ReportArgs>();
  auto* report = app.add_subcommand(
      "report",
      "The study report for people: index.html with the landmarks and who placed them, scaling, "
      "motion, wrapping, fibres and provenance (offline: no scripts, no network)");
  report->add_option("dir", args->dir, "Study folder")->required();
  report->add_option("-o,--out", args->out, "Report folder (default: STUDY/report)");
  report
      ->add_option("--truth", args->truth,
                   "A synthetic patient's folder (mmm patient synth -o): adds the landmark and "
                   "surface errors against its ground truth")
      ->check(CLI::ExistingDirectory);
  report->add_option("-j,--threads", args->threads, "Threads for the ground-truth comparison")
      ->check(CLI::Range(1, 256));
  report->callback([args, &registry] { run_report(*args, registry); });
}

}  // namespace mmm::app
