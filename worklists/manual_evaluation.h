#pragma once
// What a manual node type makes of a person's submission (defined with the
// manual task behaviour a node type registers: workflow/manual_task.h).

#include "workflow/manual_task.h"

namespace mmm::worklists {

using workflow::ManualEvaluation;
using workflow::ManualOutput;

}  // namespace mmm::worklists
