#include "app/commands/study_report.h"

#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "app/commands/commands.h"
#include "core/errors.h"
#include "workflow/run/export_outputs.h"
#include "workflow/run/study_plan.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/study.h"

namespace mmm::app {
namespace {

using workflow::ExecutionRecord;
using workflow::NodePlan;
using workflow::StudyPlan;

// Plans the study, refreshing changed input files when no runner is busy
// with it (refreshing writes; while a runner holds the lock, its view wins).
StudyPlan current_plan(workflow::Study& study) {
  std::optional<workflow::StudyLock> lock = workflow::StudyLock::try_acquire(study.dir());
  return workflow::plan_study(study, lock.has_value());
}

std::string short_hash(const std::string& hash) { return hash.substr(0, 12); }

nlohmann::json execution_json(const ExecutionRecord& record) {
  nlohmann::json json = {{"id", record.id},
                         {"run", record.run_id},
                         {"node", record.node},
                         {"status", std::string(workflow::execution_status_name(record.status))},
                         {"reason", record.reason},
                         {"started_at", record.started_at},
                         {"finished_at", record.finished_at},
                         {"seconds", record.seconds},
                         {"host", record.host},
                         {"pid", record.pid},
                         {"cache_key", record.cache_key},
                         {"outputs", workflow::outputs_json(record.outputs)}};
  if (!record.error.empty()) json["error"] = record.error;
  if (record.manual) json["submitted_by"] = record.submitted_by;
  return json;
}

nlohmann::json node_plan_json(const NodePlan& plan) {
  nlohmann::json json = {{"id", plan.node->id},
                         {"type", plan.node->type},
                         {"version", plan.type->spec.version()},
                         {"manual", plan.type->spec.is_manual()},
                         {"state", std::string(workflow::node_state_name(plan.state))},
                         {"reason", plan.reason}};
  if (!plan.cache_key.empty()) json["cache_key"] = plan.cache_key;
  if (plan.key_parts) json["key"] = workflow::cache_key_json(*plan.key_parts);
  if (!plan.blocked_by.empty()) json["blocked_by"] = plan.blocked_by;
  if (plan.result) json["result"] = execution_json(*plan.result);
  if (plan.last) json["last_execution"] = execution_json(*plan.last);
  return json;
}

nlohmann::json last_run_json(workflow::Study& study) {
  workflow::Statement select = study.database().prepare(
      "SELECT id, started_at, finished_at, status, host, mmm_version, git_revision, jobs, "
      "executed, cached, failed, waiting FROM runs ORDER BY id DESC LIMIT 1");
  if (!select.step()) return nullptr;
  return {{"id", select.column_int64(0)},          {"started_at", select.column_text(1)},
          {"finished_at", select.column_text(2)},  {"status", select.column_text(3)},
          {"host", select.column_text(4)},         {"mmm_version", select.column_text(5)},
          {"git_revision", select.column_text(6)}, {"jobs", select.column_int64(7)},
          {"executed", select.column_int64(8)},    {"cached", select.column_int64(9)},
          {"failed", select.column_int64(10)},     {"waiting", select.column_int64(11)}};
}

nlohmann::json status_json(workflow::Study& study, const StudyPlan& plan) {
  nlohmann::json json;
  json["study"] = study.dir().string();
  json["workflow"] = study.workflow().name;
  json["meta"] = study.meta();
  nlohmann::json inputs = nlohmann::json::array();
  for (const auto& [name, input] : study.inputs()) {
    inputs.push_back({{"name", name},
                      {"type", std::string(workflow::port_type_name(input.type))},
                      {"hash", input.hash},
                      {"kind", input.is_file ? "file" : "value"},
                      {"given", input.given},
                      {"updated_at", input.updated_at}});
  }
  json["inputs"] = inputs;
  json["input_changes"] = plan.input_changes;
  nlohmann::json nodes = nlohmann::json::array();
  nlohmann::json counts = nlohmann::json::object();
  for (const NodePlan& node : plan.nodes) {
    nodes.push_back(node_plan_json(node));
    counts[std::string(workflow::node_state_name(node.state))] =
        counts.value(std::string(workflow::node_state_name(node.state)), 0) + 1;
  }
  json["nodes"] = nodes;
  json["counts"] = counts;
  json["last_run"] = last_run_json(study);
  const bool all_cached =
      plan.count(workflow::NodeState::kCached) == static_cast<int>(plan.nodes.size());
  // Whether outputs/ shows the current results (a run killed while exporting
  // leaves it behind them; the next run brings it up to date).
  std::map<std::string, std::map<std::string, workflow::OutputArtifact>> results;
  for (const NodePlan& node : plan.nodes) {
    if (node.state == workflow::NodeState::kCached && node.result) {
      results[node.node->id] = node.result->outputs;
    }
  }
  const std::vector<std::string> stale = workflow::stale_exports(study, results);
  json["outputs_match"] = stale.empty();
  json["stale_outputs"] = stale;
  json["state"] = all_cached && !stale.empty()                    ? "outputs_stale"
                  : all_cached                                    ? "done"
                  : plan.count(workflow::NodeState::kWaiting) > 0 ? "waiting"
                  : plan.count(workflow::NodeState::kFailed) > 0 ||
                          plan.count(workflow::NodeState::kInvalid) > 0
                      ? "failed"
                      : "incomplete";
  return json;
}

void print_status(const nlohmann::json& json, const std::string& dir) {
  const nlohmann::json& meta = json["meta"];
  std::cout << "study     " << json["study"].get<std::string>() << '\n'
            << "workflow  " << json["workflow"].get<std::string>() << " (hash "
            << short_hash(meta.value("workflow_hash", "")) << ")\n"
            << "created   " << meta.value("created_at", "?") << " by mmm "
            << meta.value("mmm_version", "?") << " (" << meta.value("git_revision", "?") << ") on "
            << meta.value("host", "?") << '\n';
  std::cout << "inputs:\n";
  for (const auto& input : json["inputs"]) {
    std::cout << "  " << std::left << std::setw(18) << input["name"].get<std::string>()
              << std::setw(20) << input["type"].get<std::string>() << short_hash(input["hash"])
              << "  " << input["given"].get<std::string>() << '\n';
  }
  for (const auto& change : json["input_changes"]) {
    std::cout << "  " << change.get<std::string>() << '\n';
  }
  std::cout << "nodes:\n";
  for (const auto& node : json["nodes"]) {
    std::cout << "  " << std::left << std::setw(18) << node["id"].get<std::string>()
              << std::setw(20) << node["type"].get<std::string>() << std::setw(9)
              << node["state"].get<std::string>() << node["reason"].get<std::string>() << '\n';
  }
  if (!json["last_run"].is_null()) {
    const nlohmann::json& run = json["last_run"];
    std::cout << "last run  #" << run["id"] << " " << run["status"].get<std::string>() << ", "
              << run["executed"] << " ran, " << run["cached"] << " cached, " << run["failed"]
              << " failed (" << run["started_at"].get<std::string>() << ", "
              << run["host"].get<std::string>() << ")\n";
  }
  for (const auto& stale : json["stale_outputs"]) {
    std::cout << "outputs   " << stale.get<std::string>() << '\n';
  }
  const std::string state = json["state"];
  std::cout << "state     " << state;
  if (state != "done") std::cout << "  -> mmm run " << dir;
  std::cout << '\n';
}

struct StatusArgs {
  std::string dir;
  bool json = false;
};

void run_status(const StatusArgs& args, const workflow::NodeRegistry& registry) {
  workflow::Study study = workflow::Study::open(args.dir, registry);
  const nlohmann::json json = study_status(study);
  if (args.json) {
    std::cout << json.dump(2) << '\n';
  } else {
    print_status(json, args.dir);
  }
}

struct ExplainArgs {
  std::string dir;
  std::string node;
  bool json = false;
};

void print_explanation(const nlohmann::json& json) {
  std::cout << "node      " << json["id"].get<std::string>() << " ("
            << json["type"].get<std::string>() << " v" << json["version"] << ")\n"
            << "state     " << json["state"].get<std::string>() << ": "
            << json["reason"].get<std::string>() << '\n';
  if (json.contains("cache_key")) {
    std::cout << "cache key " << json["cache_key"].get<std::string>() << '\n';
    const nlohmann::json& key = json["key"];
    for (const auto& [name, value] : key["params"].items()) {
      std::cout << "  param   " << name << " = "
                << workflow::param_value_text(workflow::param_value_from_json(value)) << '\n';
    }
    for (const auto& [port, hash] : key["inputs"].items()) {
      std::cout << "  input   " << port << " sha256 " << hash.get<std::string>() << '\n';
    }
  }
  std::cout << "history:\n";
  if (json["history"].empty()) std::cout << "  (never ran)\n";
  for (const auto& run : json["history"]) {
    std::cout << "  #" << run["id"] << " " << std::left << std::setw(12)
              << run["status"].get<std::string>() << run["started_at"].get<std::string>() << "  "
              << std::fixed << std::setprecision(2) << run["seconds"].get<double>() << " s  "
              << run["reason"].get<std::string>();
    if (run.contains("error")) std::cout << "\n      error: " << run["error"].get<std::string>();
    std::cout << '\n';
  }
  if (!json["log"].empty()) {
    std::cout << "log of the last execution:\n";
    for (const auto& line : json["log"]) {
      std::cout << "  " << line["time"].get<std::string>() << " " << std::setw(8)
                << line["level"].get<std::string>() << line["message"].get<std::string>() << '\n';
    }
  }
}

void run_explain(const ExplainArgs& args, const workflow::NodeRegistry& registry) {
  workflow::Study study = workflow::Study::open(args.dir, registry);
  const StudyPlan plan = current_plan(study);
  const NodePlan* node = plan.find(args.node);
  if (node == nullptr) {
    std::string ids;
    for (const NodePlan& p : plan.nodes) ids += (ids.empty() ? "" : ", ") + p.node->id;
    throw InvalidInputError("no node '" + args.node + "' in the study's workflow (nodes: " + ids +
                            ")");
  }
  nlohmann::json json = node_plan_json(*node);
  nlohmann::json history = nlohmann::json::array();
  for (const ExecutionRecord& record : workflow::executions_of(study.database(), args.node)) {
    history.push_back(execution_json(record));
  }
  json["history"] = history;
  nlohmann::json log = nlohmann::json::array();
  if (node->last) {
    for (const workflow::LogLine& line :
         workflow::execution_logs(study.database(), node->last->id)) {
      log.push_back({{"time", line.time},
                     {"level", std::string(workflow::log_level_name(line.level))},
                     {"message", line.message}});
    }
  }
  json["log"] = log;
  if (args.json) {
    std::cout << json.dump(2) << '\n';
  } else {
    print_explanation(json);
  }
}

}  // namespace

nlohmann::json study_status(workflow::Study& study) {
  return status_json(study, current_plan(study));
}

void register_study_report_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto status_args = std::make_shared<StatusArgs>();
  auto* status = app.add_subcommand(
      "status", "Where a study stands: inputs, each node's state and why, the last run");
  status->add_option("DIR", status_args->dir, "Study folder")->required();
  status->add_flag("--json", status_args->json, "Print JSON instead of text");
  status->callback([status_args, &registry] { run_status(*status_args, registry); });

  auto explain_args = std::make_shared<ExplainArgs>();
  auto* explain = app.add_subcommand(
      "explain", "Why a node ran, will run or is cached: its cache key, history and log");
  explain->add_option("DIR", explain_args->dir, "Study folder")->required();
  explain->add_option("NODE", explain_args->node, "Node id")->required();
  explain->add_flag("--json", explain_args->json, "Print JSON instead of text");
  explain->callback([explain_args, &registry] { run_explain(*explain_args, registry); });
}

}  // namespace mmm::app
