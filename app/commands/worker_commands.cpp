// mmm worker run-node REQUEST: the process a Slurm job runs for one node
// execution (workflow/run/slurm_executor.h). It reads the request, runs the
// node against the study's artifact store and writes the result file; it
// never opens the study database.

#include <sys/stat.h>

#include <iostream>
#include <memory>
#include <string>

#include "app/commands/commands.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "workflow/run/node_request.h"

namespace mmm::app {
namespace {

constexpr std::uintmax_t kMaxRequestFileBytes = std::uintmax_t{16} << 20U;

void run_node(const std::string& request_file, const workflow::NodeRegistry& registry) {
  struct stat info {};
  if (::stat(request_file.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
    throw IoError(request_file, "no such request file");
  }
  if (static_cast<std::uintmax_t>(info.st_size) > kMaxRequestFileBytes) {
    throw IoError(request_file, "is larger than a node request can be (16 MiB)");
  }
  const workflow::NodeRequest request = workflow::node_request_from_text(
      read_file_bytes(request_file, static_cast<std::uintmax_t>(info.st_size)), request_file,
      registry);
  const workflow::Completion completion = workflow::run_node_request(request);
  for (const workflow::LogLine& line : completion.logs) {
    std::cerr << line.time << ' ' << workflow::log_level_name(line.level) << ' ' << line.message
              << '\n';
  }
  if (!completion.error.empty()) set_exit_code(kExitFailed);
}

}  // namespace

void register_worker_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto* worker = app.add_subcommand("worker", "What cluster jobs run (mmm run --executor slurm)");
  worker->require_subcommand(1);
  auto request = std::make_shared<std::string>();
  auto* run_node_command = worker->add_subcommand(
      "run-node", "Run one node execution from its request file; write its result file");
  run_node_command->add_option("REQUEST", *request, "request.json written by the runner")
      ->required();
  run_node_command->callback([request, &registry] { run_node(*request, registry); });
}

}  // namespace mmm::app
