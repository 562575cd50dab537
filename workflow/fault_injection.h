#pragma once
// Deterministic crash injection for the crash-safety tests. The engine calls
// fault_point("name") at every place where a crash would be interesting:
// inside artifact writes, around database commits, between nodes, inside a
// running node, while exporting. Nothing happens unless the environment asks
// for it:
//
//   MMM_FAULT_TRACE=FILE  append the name of every fault point reached, one
//                         per line, to FILE (how a test learns the points of
//                         an uninterrupted run);
//   MMM_KILL_AT=K         the process sends itself SIGKILL when it reaches its
//                         K-th fault point (1-based, counting every point).
//
// Both are read once, at the first fault point. Without them a fault point
// costs one relaxed atomic load.

#include <string_view>

namespace mmm::workflow {

void fault_point(std::string_view name);

}  // namespace mmm::workflow
