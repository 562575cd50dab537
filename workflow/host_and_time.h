#pragma once
// Facts about "here and now" recorded with studies, runs and locks: the host
// name, the process id and the current time as UTC ISO 8601 text.

#include <string>

namespace mmm::workflow {

// gethostname(), or "unknown".
std::string host_name();

// Current time, UTC, second resolution: "2026-11-22T14:03:00Z".
std::string utc_now();

// Current time, UTC, millisecond resolution: "2026-11-22T14:03:00.123Z"
// (execution start and end times, log lines).
std::string utc_now_precise();

}  // namespace mmm::workflow
