#include "workflow/run/node_execution.h"

#include <chrono>
#include <mutex>

#include "core/errors.h"
#include "workflow/fault_injection.h"
#include "workflow/host_and_time.h"
#include "workflow/run/crash_marker.h"

namespace mmm::workflow {

namespace {

using Clock = std::chrono::steady_clock;

std::vector<std::string> declared_outputs_missing(const NodeSpec& spec,
                                                  const std::map<std::string, ArtifactRef>& set) {
  std::vector<std::string> missing;
  for (const PortSpec& port : spec.outputs()) {
    if (!set.contains(port.name)) missing.push_back(port.name);
  }
  return missing;
}

}  // namespace

Completion execute(const Job& job, ArtifactStore& artifacts,
                   const std::filesystem::path& scratch_root,
                   const std::filesystem::path& crash_marker, RunObserver* observer) {
  const auto start = Clock::now();
  Completion completion{job.node, job.execution_id, {}, {}, {}, 0};
  std::mutex log_mutex;
  const std::filesystem::path scratch =
      scratch_root / (std::to_string(job.execution_id) + "-" + job.node);
  NodeContext::Channels channels;
  channels.store = [&artifacts](std::string_view bytes) {
    fault_point("node.store");
    return artifacts.put(bytes);
  };
  channels.store_file = [&artifacts](const std::filesystem::path& file) {
    fault_point("node.store");
    return artifacts.put_file(file);
  };
  channels.progress = [&](std::int64_t done, std::int64_t total, std::string_view what) {
    fault_point("node.progress");
    if (observer != nullptr) observer->node_progress(job.node, done, total, what);
  };
  channels.log = [&](LogLevel level, std::string_view message) {
    {
      const std::lock_guard lock(log_mutex);
      completion.logs.push_back({utc_now_precise(), level, std::string(message)});
    }
    if (observer != nullptr) observer->node_log(job.node, level, message);
  };
  try {
    // Every input is checked against its content hash right before the node
    // reads it: an artifact changed in place (by hand, or by a disk fault)
    // fails the node instead of flowing into its results.
    for (const auto& [port, ref] : job.inputs) {
      if (!artifacts.verify(ref.hash)) {
        throw IoError(ref.path, "input '" + port + "' of node '" + job.node +
                                    "' is missing or was changed after it was stored (its "
                                    "content no longer hashes to " +
                                    ref.hash +
                                    "); hint: 'mmm audit verify' on the study, then re-run or "
                                    "restore the node that produced it");
      }
    }
    std::filesystem::create_directories(scratch);
    NodeContext context(job.type->spec, job.inputs, job.params, scratch, channels);
    fault_point("node.before_run");
    {
      const RunningNodeScope crash_scope(crash_marker, job.node, job.cache_key);
      job.type->run(context);
    }
    fault_point("node.after_run");
    const std::vector<std::string> missing =
        declared_outputs_missing(job.type->spec, context.outputs());
    if (!missing.empty()) {
      std::string names;
      for (const std::string& name : missing) names += (names.empty() ? "'" : ", '") + name + "'";
      throw InvalidInputError("node type '" + job.type->spec.name() +
                              "' finished without setting output(s) " + names +
                              " (a bug in the node)");
    }
    for (const auto& [port, ref] : context.outputs()) {
      completion.outputs[port] = {ref.type, ref.hash};
    }
  } catch (const std::exception& e) {
    completion.error = e.what();
  } catch (...) {
    completion.error = "unknown exception";
  }
  std::error_code ignored;
  std::filesystem::remove_all(scratch, ignored);
  if (!completion.error.empty()) {
    completion.logs.push_back({utc_now_precise(), LogLevel::kError, completion.error});
  }
  completion.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return completion;
}

}  // namespace mmm::workflow
