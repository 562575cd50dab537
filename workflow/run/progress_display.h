#pragma once
// Showing a run to a person. On a terminal: one status line, redrawn in
// place at most ten times a second ("[3/12] running: fit (frame 40/121),
// wrap"), with finished, failed and cached nodes printed above it. Elsewhere
// (a log file, CI, a pipe): plain spdlog lines, with a node's progress at
// most every few seconds.

#include <iosfwd>
#include <memory>

#include "workflow/run/run_observer.h"

namespace mmm::workflow {

struct ProgressDisplayOptions {
  // Status line redrawn in place (a terminal) or log lines.
  bool terminal = false;
  // Print a line for every reused node too (off: only a count at the end).
  bool show_cached = false;
};

// A display writing to `out` (the status line mode) or to spdlog's default
// logger (log mode). `out` must outlive the display.
std::unique_ptr<RunObserver> make_progress_display(std::ostream& out,
                                                   const ProgressDisplayOptions& options);

}  // namespace mmm::workflow
