// mmm worklist, mmm task ..., mmm audit ..., mmm operator ...: the manual
// side of studies (worklists/).

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "app/commands/operator_identity.h"
#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "mmm_git_revision.h"
#include "workflow/study/study.h"
#include "worklists/audit_anchor.h"
#include "worklists/audit_export.h"
#include "worklists/audit_trail.h"
#include "worklists/audit_verify.h"
#include "worklists/operators.h"
#include "worklists/study_runner.h"
#include "worklists/task_actions.h"
#include "worklists/worklist.h"

namespace mmm::app {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// --root: the option, else $MMM_ROOT, else the current folder.
fs::path root_of(const std::string& option) {
  if (!option.empty()) return option;
  const char* env = std::getenv("MMM_ROOT");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(".");
}

void print_table(const std::vector<worklists::WorklistEntry>& entries) {
  if (entries.empty()) {
    std::cout << "no tasks\n";
    return;
  }
  std::cout << std::left << std::setw(12) << "TASK" << std::setw(24) << "STUDY" << std::setw(14)
            << "PATIENT" << std::setw(18) << "NODE" << std::setw(11) << "STATE" << std::setw(14)
            << "ASSIGNEE"
            << "AGE\n";
  for (const worklists::WorklistEntry& entry : entries) {
    std::cout << std::setw(12) << entry.task.id << std::setw(24) << entry.study << std::setw(14)
              << entry.patient << std::setw(18) << entry.task.node << std::setw(11)
              << worklists::task_state_name(entry.task.state) << std::setw(14)
              << (entry.task.assignee.empty() ? "-" : entry.task.assignee)
              << worklists::format_age(entry.age_seconds) << '\n';
  }
}

Json entry_json(const worklists::WorklistEntry& entry, bool with_task) {
  Json json = {{"task", entry.task.id},
               {"study", entry.study},
               {"study_dir", entry.study_dir.string()},
               {"patient", entry.patient},
               {"node", entry.task.node},
               {"state", worklists::task_state_name(entry.task.state)},
               {"assignee", entry.task.assignee},
               {"created_at", entry.task.created_at},
               {"age_seconds", entry.age_seconds}};
  if (with_task) json["details"] = worklists::task_to_json(entry.task);
  return json;
}

struct WorklistArgs {
  std::string root;
  std::string assignee;
  std::string state;
  bool all = false;
  bool json = false;
};

void run_worklist(const WorklistArgs& args) {
  worklists::WorklistFilter filter;
  filter.include_closed = args.all;
  if (!args.assignee.empty()) filter.assignee = args.assignee;
  if (!args.state.empty()) {
    filter.state = worklists::task_state_from_name(args.state);
    if (!filter.state) {
      throw InvalidInputError("--state '" + args.state + "' is not a task state; hint: one of " +
                              worklists::task_state_names());
    }
  }
  const std::vector<worklists::WorklistEntry> entries =
      worklists::list_worklist(root_of(args.root), filter);
  if (args.json) {
    Json list = Json::array();
    for (const auto& entry : entries) list.push_back(entry_json(entry, false));
    std::cout << list.dump(2) << '\n';
  } else {
    print_table(entries);
  }
}

struct TaskArgs {
  std::string id;
  std::string root;
  OperatorCredentials credentials;
  std::string to;
  std::string file;
  std::vector<std::string> points;
  std::vector<std::string> reasons;
  bool no_run = false;
  bool json = false;
  int jobs = 2;
};

std::string joined_reasons(const std::vector<std::string>& reasons) {
  std::string text;
  for (const std::string& reason : reasons) text += (text.empty() ? "" : "; ") + reason;
  return text;
}

// "NAME:VIEW=U,V" -> submission["landmarks"][NAME][VIEW] = [U, V].
void add_point(Json& submission, const std::string& text) {
  const std::size_t colon = text.find(':');
  const std::size_t equals = text.find('=');
  const std::size_t comma = text.find(',', equals == std::string::npos ? 0 : equals);
  if (colon == std::string::npos || equals == std::string::npos || comma == std::string::npos ||
      colon > equals) {
    throw InvalidInputError("--point '" + text +
                            "' must be NAME:VIEW=U,V, e.g. femoral_head_centre_r:frontal=412.5,"
                            "880.0");
  }
  double u = 0;
  double v = 0;
  try {
    std::size_t used_u = 0;
    std::size_t used_v = 0;
    const std::string u_text = text.substr(equals + 1, comma - equals - 1);
    const std::string v_text = text.substr(comma + 1);
    u = std::stod(u_text, &used_u);
    v = std::stod(v_text, &used_v);
    if (used_u != u_text.size() || used_v != v_text.size()) throw std::invalid_argument("rest");
  } catch (const std::exception&) {
    throw InvalidInputError("--point '" + text + "': U and V must be numbers (pixels)");
  }
  submission["landmarks"][text.substr(0, colon)][text.substr(colon + 1, equals - colon - 1)] = {u,
                                                                                                v};
}

Json read_submission(const TaskArgs& args) {
  Json submission = Json::object();
  if (!args.file.empty()) {
    // A submission is a few landmarks: the web station's request limit.
    constexpr std::uintmax_t kMaxSubmissionBytes = std::uintmax_t{1} << 20;
    std::error_code size_error;
    const std::uintmax_t size = std::filesystem::file_size(args.file, size_error);
    if (size_error) throw IoError(args.file, "cannot be read; hint: check the path");
    if (size > kMaxSubmissionBytes) {
      throw IoError(args.file, "is " + std::to_string(size) + " bytes; a submission is at most " +
                                   std::to_string(kMaxSubmissionBytes) + " (1 MiB)");
    }
    try {
      submission = parse_json(read_file_bytes(args.file, size));
    } catch (const Json::parse_error& error) {
      throw IoError(args.file, std::string("is not valid JSON (") + error.what() +
                                   "); hint: {\"landmarks\": {NAME: {VIEW: [u, v]}}}");
    }
  }
  for (const std::string& point : args.points) add_point(submission, point);
  if (args.file.empty() && args.points.empty()) {
    throw InvalidInputError(
        "nothing to submit; hint: --file SUBMISSION.json or --point "
        "NAME:VIEW=U,V (repeat for each landmark and view)");
  }
  return submission;
}

// An outline review's verdict (core/image/outline_corrections.h).
void print_verdict(const Json& values) {
  std::cout << "  decision " << values.value("decision", "") << '\n';
  for (const Json& correction : values.value("corrections", Json::array())) {
    std::cout << "  " << std::left << std::setw(16) << correction.value("bone", "") << std::setw(10)
              << correction.value("view", "") << correction.value("points_px", Json::array()).size()
              << " point(s)\n";
  }
}

void print_values(const Json& values) {
  if (values.is_object() && values.value("format", "") == "mmm-outline-corrections") {
    print_verdict(values);
    return;
  }
  if (!values.is_object() || !values.contains("landmarks")) return;
  for (const Json& landmark : values["landmarks"]) {
    const Json& p = landmark["position_mm"];
    std::cout << "  " << std::left << std::setw(24) << landmark["name"].get<std::string>()
              << std::fixed << std::setprecision(1) << std::right << std::setw(8)
              << p[0].get<double>() << std::setw(8) << p[1].get<double>() << std::setw(8)
              << p[2].get<double>() << " mm";
    if (landmark.contains("reprojection_error_mm")) {
      std::cout << "   reprojection";
      for (const auto& [view, error] : landmark["reprojection_error_mm"].items()) {
        std::cout << ' ' << view << ' ' << std::setprecision(2) << error.get<double>() << " mm";
      }
    }
    std::cout << '\n';
  }
}

// After an accepted submission: continue the run (or say how).
void continue_run(workflow::Study& study, const TaskArgs& args) {
  if (args.no_run) {
    std::cout << "next: mmm run " << study.dir().string() << '\n';
    return;
  }
  workflow::RunOptions options;
  options.jobs = args.jobs;
  options.provenance = {MMM_VERSION, MMM_GIT_REVISION};
  const worklists::StudyRunResult result = worklists::run_study_with_tasks(study, options);
  if (result.locked) {
    std::cout << "another runner holds the study (" << result.lock_holder
              << "); when it ends: mmm run " << study.dir().string() << '\n';
    return;
  }
  const workflow::RunSummary& summary = *result.summary;
  std::cout << "study resumed: " << summary.executed.size() << " node(s) ran, "
            << summary.cached.size() << " cached; outcome "
            << workflow::run_outcome_name(summary.outcome) << '\n';
  for (const worklists::Task& task : result.opened) {
    std::cout << "new task " << task.id << " (" << task.node << ")\n";
  }
  if (summary.outcome == workflow::RunOutcome::kFailed) set_exit_code(kExitFailed);
  if (summary.outcome == workflow::RunOutcome::kWaiting) set_exit_code(kExitWaiting);
}

void run_task_action(const std::string& action, const TaskArgs& args,
                     const workflow::NodeRegistry& registry) {
  const fs::path root = root_of(args.root);
  const worklists::WorklistEntry entry = worklists::locate_task(root, args.id);
  workflow::Study study = workflow::Study::open(entry.study_dir, registry);
  const std::string& id = entry.task.id;
  if (action == "show") {
    if (args.json) {
      std::cout << entry_json(entry, true).dump(2) << '\n';
      return;
    }
    const worklists::Task& task = entry.task;
    std::cout << "task " << task.id << " (" << task.node_type << ", node '" << task.node
              << "') of study " << entry.study << ", patient " << entry.patient << "\n  state "
              << worklists::task_state_name(task.state)
              << (task.assignee.empty() ? "" : ", assignee " + task.assignee) << ", opened "
              << task.created_at << '\n';
    if (task.request.contains("landmarks")) {
      std::cout << "  landmarks:\n";
      for (const Json& landmark : task.request["landmarks"]) {
        std::cout << "    " << landmark["name"].get<std::string>()
                  << (landmark["required"].get<bool>() ? " (required)" : " (optional)") << ": "
                  << landmark["hint"].get<std::string>() << '\n';
      }
      std::cout << "  views:";
      for (const Json& view : task.request["views"]) {
        std::cout << ' ' << view["name"].get<std::string>() << " (" << view["width"] << " x "
                  << view["height"] << ")";
      }
      std::cout << "\n  " << task.request.value("instructions", "") << '\n';
    }
    if (task.request.contains("bones")) {
      std::cout << "  bones outlined (level " << task.request.value("level", "") << "):";
      for (const Json& bone : task.request["bones"]) {
        std::cout << ' ' << bone["name"].get<std::string>();
      }
      std::cout << "\n  views:";
      for (const Json& view : task.request["views"]) {
        std::cout << ' ' << view["name"].get<std::string>() << " (" << view["width"] << " x "
                  << view["height"] << ")";
      }
      std::cout << "\n  " << task.request.value("instructions", "")
                << "\n  submit {\"decision\": \"accept\"} or {\"decision\": \"correct\", "
                   "\"corrections\": [{\"bone\", \"view\", \"points\": [[u, v], ...]}]} "
                   "(--file; 'mmm task show ID --json' gives the outlines in pixels)\n";
    }
    if (!task.rejection_reasons.empty()) {
      std::cout << "  last rejection:\n";
      for (const std::string& reason : task.rejection_reasons)
        std::cout << "    - " << reason << '\n';
    }
    if (!task.result.is_null()) {
      std::cout << "  accepted values:\n";
      print_values(task.result);
    }
    return;
  }
  const worklists::Actor actor = command_line_actor(root, args.credentials);
  if (action == "claim") {
    worklists::claim_task(study, id, actor);
    std::cout << "task " << id << " claimed by " << actor.operator_name << '\n';
  } else if (action == "release") {
    worklists::release_task(study, id, actor);
    std::cout << "task " << id << " released (open)\n";
  } else if (action == "reassign") {
    worklists::reassign_task(study, id, actor, args.to);
    std::cout << "task " << id << " reassigned to " << args.to << '\n';
  } else if (action == "cancel") {
    worklists::cancel_task(study, id, actor, joined_reasons(args.reasons));
    std::cout << "task " << id << " cancelled\n";
  } else if (action == "reject") {
    worklists::reject_task(study, id, actor, args.reasons);
    std::cout << "task " << id << " rejected, back to open\n";
  } else if (action == "submit" || action == "accept") {
    const worklists::SubmitOutcome outcome =
        action == "submit" ? worklists::submit_task(study, id, actor, read_submission(args),
                                                    joined_reasons(args.reasons))
                           : worklists::accept_task(study, id, actor);
    print_values(outcome.values);
    if (!outcome.reasons.empty()) {
      std::cerr << (outcome.correction ? "correction" : "submission") << " rejected ("
                << outcome.reasons.size() << " reason(s)):\n";
      for (const std::string& reason : outcome.reasons) std::cerr << "  - " << reason << '\n';
      std::cerr << (outcome.correction
                        ? "the accepted values stay in force\n"
                        : "the task is open again; claim it, fix the submission and submit\n");
      set_exit_code(kExitFailed);
      return;
    }
    if (outcome.awaiting_review) {
      std::cout << "task " << id << (outcome.correction ? ": correction" : "")
                << " submitted; it awaits review by a second operator "
                << "('mmm task accept " << id << "' under a second operator's token)"
                << (outcome.correction ? "; the accepted values stay in force until then" : "")
                << '\n';
      return;
    }
    std::cout << "task " << id << (outcome.correction ? " corrected" : " accepted") << '\n';
    continue_run(study, args);
  }
}

void run_audit(const std::string& action, const std::string& dir, const std::string& format,
               const workflow::NodeRegistry& registry, const std::string& anchor_log = {}) {
  workflow::Study study = workflow::Study::open(dir, registry);
  worklists::prepare_audit_tables(study.database());
  if (action == "anchor") {
    const worklists::AuditAnchor anchor =
        worklists::anchor_audit(study.database(), study.dir(), anchor_log);
    std::cout << "anchored entry " << anchor.seq << " " << anchor.hash << " of " << anchor.study
              << " in " << anchor_log << '\n';
    return;
  }
  if (action == "verify") {
    worklists::AuditVerification verification =
        worklists::verify_audit(study.database(), study.dir());
    if (!anchor_log.empty()) {
      for (worklists::AuditProblem& problem :
           worklists::verify_anchors(study.database(), anchor_log)) {
        verification.problems.push_back(std::move(problem));
        verification.intact = false;
      }
    }
    for (const worklists::AuditProblem& problem : verification.problems) {
      (worklists::is_audit_warning(problem.kind) ? std::cout : std::cerr)
          << (worklists::is_audit_warning(problem.kind) ? "warning" : "TAMPERING") << " ["
          << worklists::audit_problem_kind_name(problem.kind) << ", entry " << problem.seq
          << "]: " << problem.message << '\n';
    }
    if (verification.intact) {
      std::cout << "audit trail intact: " << verification.entries << " entries, head "
                << verification.head_seq << " " << verification.head.substr(0, 16) << "...\n";
    } else {
      std::cerr << "audit trail NOT intact: " << verification.problems.size() << " problem(s) in "
                << dir << '\n';
      set_exit_code(kExitFailed);
    }
    return;
  }
  const std::vector<worklists::AuditEntry> entries = worklists::read_audit(study.database());
  if (format == "json") {
    std::cout << worklists::audit_to_json(entries).dump(2) << '\n';
  } else if (format == "csv") {
    std::cout << worklists::audit_to_csv(entries);
  } else {
    for (const worklists::AuditEntry& entry : entries) {
      std::cout << std::setw(4) << entry.seq << "  " << entry.time << "  " << std::left
                << std::setw(10) << entry.operator_name << std::setw(10) << entry.action
                << entry.task_id << (entry.reason.empty() ? "" : "  (" + entry.reason + ")")
                << std::right << '\n';
    }
  }
}

}  // namespace

void register_task_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto worklist_args = std::make_shared<WorklistArgs>();
  auto* worklist = app.add_subcommand(
      "worklist", "Tasks waiting for operators, across every study under a root folder");
  worklist->add_option("--root", worklist_args->root,
                       "Folder holding the studies (default: $MMM_ROOT, else .)");
  worklist->add_option("--operator", worklist_args->assignee,
                       "Only tasks assigned to this operator");
  worklist->add_option("--state", worklist_args->state,
                       "Only tasks in this state (" + worklists::task_state_names() + ")");
  worklist->add_flag("--all", worklist_args->all, "Also accepted and cancelled tasks");
  worklist->add_flag("--json", worklist_args->json, "JSON instead of a table");
  worklist->callback([worklist_args] { run_worklist(*worklist_args); });

  auto* task = app.add_subcommand("task", "Work on one manual task (ID from 'mmm worklist')");
  task->footer(
      "Tasks by node type (see docs/operators.md):\n"
      "  landmark_station  place landmarks in both views:\n"
      "                    {\"landmarks\": {NAME: {VIEW: [u, v]}}} (or --point NAME:VIEW=U,V)\n"
      "  outline_review    check the bones' outlines on the radiographs: {\"decision\": "
      "\"accept\"}\n"
      "                    or {\"decision\": \"correct\", \"corrections\": [{\"bone\": "
      "\"femur_r\",\n"
      "                    \"view\": \"frontal\", \"points\": [[u, v], ...]}]} (pixels on the "
      "true edge)");
  task->require_subcommand(1);
  const auto add_action = [&](const std::string& name, const std::string& help,
                              bool needs_operator) {
    auto args = std::make_shared<TaskArgs>();
    auto* command = task->add_subcommand(name, help);
    command
        ->add_option("ID", args->id,
                     "Task id (or a unique prefix of 4+ characters); STUDY/ID for one study's")
        ->required();
    command->add_option("--root", args->root,
                        "Folder holding the studies (default: $MMM_ROOT, else .)");
    if (needs_operator) {
      command->add_option("--operator", args->credentials.operator_name,
                          "Who acts: checked against the token (needed with --admin-override)");
      command->add_option("--token-file", args->credentials.token_file,
                          "File holding the operator's token (default: $MMM_OPERATOR_TOKEN, "
                          "else the file named by $MMM_OPERATOR_TOKEN_FILE)");
      command->add_option("--admin-override", args->credentials.override_reason,
                          "Act as --operator without their token, for scripts of whoever may "
                          "change the root's operators file; the reason goes into the audit");
    }
    command->callback([name, args, &registry] { run_task_action(name, *args, registry); });
    return std::pair{command, args};
  };
  {
    auto [command, args] = add_action("show", "What the task asks for and where it stands", false);
    command->add_flag("--json", args->json, "Everything, as JSON");
  }
  add_action("claim", "Take an open task (exactly one of two racing operators wins)", true);
  add_action("release", "Give a claimed task back (open again)", true);
  {
    auto [command, args] = add_action("reassign", "Hand a claimed task to another operator", true);
    command->add_option("--to", args->to, "The new assignee")->required();
  }
  {
    auto [command, args] = add_action(
        "submit",
        "Submit a task's values (landmark pixels, an outline verdict); validated, then accepted "
        "or rejected with reasons",
        true);
    command->add_option(
        "--file", args->file,
        "Submission JSON. Landmark station: {\"landmarks\": {NAME: {VIEW: [u, v]}}}. Outline "
        "review: {\"decision\": \"accept\"} or {\"decision\": \"correct\", \"corrections\": "
        "[{\"bone\": B, \"view\": V, \"points\": [[u, v], ...]}]} (pixels on the true edge)");
    command->add_option("--point", args->points,
                        "Landmark station: NAME:VIEW=U,V (pixels); repeatable");
    command->add_option("--reason", args->reasons, "Why: required to correct an accepted task");
    command->add_flag("--no-run", args->no_run, "Do not continue the study's run afterwards");
    command->add_option("--jobs,-j", args->jobs, "Nodes run at the same time when continuing")
        ->check(CLI::Range(1, 256));
  }
  {
    auto [command, args] =
        add_action("accept", "Review: accept a submitted task (not your own)", true);
    command->add_flag("--no-run", args->no_run, "Do not continue the study's run afterwards");
  }
  {
    auto [command, args] =
        add_action("reject", "Review: send a submitted task back, with reasons", true);
    command->add_option("--reason", args->reasons, "Why (repeatable)")->required();
  }
  {
    auto [command, args] = add_action("cancel", "Cancel a task that is no longer needed", true);
    command->add_option("--reason", args->reasons, "Why")->required();
  }

  auto* audit = app.add_subcommand("audit", "The audit trail of a study's manual actions");
  audit->require_subcommand(1);
  auto audit_dir = std::make_shared<std::string>();
  auto audit_format = std::make_shared<std::string>("table");
  auto* verify = audit->add_subcommand(
      "verify",
      "Check the hash chain and its checkpoint: edits, deletions, reordering, truncation");
  verify->add_option("DIR", *audit_dir, "Study folder")->required();
  auto anchor_log = std::make_shared<std::string>();
  verify
      ->add_option("--anchors", *anchor_log,
                   "Also check the entries anchored in this log ('mmm audit anchor'): a trail "
                   "rewritten end to end is found only this way")
      ->check(CLI::ExistingFile);
  verify->callback([audit_dir, anchor_log, &registry] {
    run_audit("verify", *audit_dir, "", registry, *anchor_log);
  });
  auto* anchor = audit->add_subcommand(
      "anchor", "Append the trail's head to a log kept outside the study (an external anchor)");
  anchor->add_option("DIR", *audit_dir, "Study folder")->required();
  anchor->add_option("--log", *anchor_log, "The anchor log (JSON lines, appended)")->required();
  anchor->callback([audit_dir, anchor_log, &registry] {
    run_audit("anchor", *audit_dir, "", registry, *anchor_log);
  });
  auto* show = audit->add_subcommand("show", "Every entry (table, --json or --csv)");
  show->add_option("DIR", *audit_dir, "Study folder")->required();
  auto json_flag = std::make_shared<bool>(false);
  auto csv_flag = std::make_shared<bool>(false);
  show->add_flag("--json", *json_flag, "JSON");
  show->add_flag("--csv", *csv_flag, "CSV (RFC 4180)");
  show->callback([audit_dir, json_flag, csv_flag, &registry] {
    run_audit("show", *audit_dir, *json_flag ? "json" : (*csv_flag ? "csv" : "table"), registry);
  });

  auto* operators = app.add_subcommand("operator", "Operators of a root folder (web UI tokens)");
  operators->require_subcommand(1);
  auto op_root = std::make_shared<std::string>();
  auto op_name = std::make_shared<std::string>();
  auto op_replace = std::make_shared<bool>(false);
  auto op_supervisor = std::make_shared<bool>(false);
  auto* add = operators->add_subcommand("add", "Register an operator; prints their token once");
  add->add_option("NAME", *op_name, "Operator name")->required();
  add->add_option("--root", *op_root, "Folder holding the studies (default: $MMM_ROOT, else .)");
  add->add_flag("--replace", *op_replace, "Give an existing operator a new token");
  add->add_flag("--supervisor", *op_supervisor,
                "May also release, reassign or cancel tasks other operators have claimed");
  add->callback([op_root, op_name, op_replace, op_supervisor] {
    const fs::path root = root_of(*op_root);
    const std::string token = worklists::add_operator(
        root, *op_name, *op_replace,
        *op_supervisor ? worklists::kSupervisorRole : worklists::kOperatorRole);
    std::cout << token << '\n';
    std::cerr << "operator '" << *op_name << "' registered under " << root.string()
              << "; the token above is shown only once (the web UI asks for it)\n";
  });
  auto* list = operators->add_subcommand("list", "Registered operators");
  list->add_option("--root", *op_root, "Folder holding the studies (default: $MMM_ROOT, else .)");
  list->callback([op_root] {
    for (const worklists::OperatorRecord& record : worklists::read_operators(root_of(*op_root))) {
      std::cout << record.name << "  " << record.role << " since " << record.created_at << '\n';
    }
  });
}

}  // namespace mmm::app
