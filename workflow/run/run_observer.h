#pragma once
// What a run reports while it goes, for a progress display or a log. The
// scheduler calls node_progress and node_log from the worker threads running
// the nodes, the others from its own thread: implementations must be thread
// safe. Every member has an empty default.

#include <cstdint>
#include <string>
#include <string_view>

#include "workflow/node_context.h"

namespace mmm::workflow {

struct RunSummary;

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  RunObserver() = default;
  RunObserver(const RunObserver&) = delete;
  RunObserver& operator=(const RunObserver&) = delete;
  RunObserver(RunObserver&&) = delete;
  RunObserver& operator=(RunObserver&&) = delete;

  virtual void run_started(int /*nodes*/, int /*jobs*/) {}
  virtual void input_changed(std::string_view /*message*/) {}
  virtual void node_cached(const std::string& /*node*/) {}
  virtual void node_started(const std::string& /*node*/, const std::string& /*type*/,
                            const std::string& /*reason*/) {}
  virtual void node_progress(const std::string& /*node*/, std::int64_t /*done*/,
                             std::int64_t /*total*/, std::string_view /*what*/) {}
  virtual void node_log(const std::string& /*node*/, LogLevel /*level*/,
                        std::string_view /*message*/) {}
  virtual void node_finished(const std::string& /*node*/, bool /*ok*/, double /*seconds*/,
                             const std::string& /*error*/) {}
  virtual void node_waiting(const std::string& /*node*/) {}
  virtual void run_finished(const RunSummary& /*summary*/) {}
};

}  // namespace mmm::workflow
