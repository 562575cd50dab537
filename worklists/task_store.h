#pragma once
// The tasks table of a study database (study.db, beside the workflow
// engine's tables) and its rows. The writes here are the raw ones; the state
// machine, validation and audit entries are in task_actions.h, which calls
// them inside one transaction per action.

#include <optional>
#include <string>
#include <vector>

#include "workflow/store/sqlite.h"
#include "worklists/task.h"

namespace mmm::worklists {

// Creates the tasks table when missing (idempotent; older studies get it on
// first use).
void prepare_task_tables(workflow::Database& database);

// Whether the study has a tasks table (a study without manual nodes, or one
// whose tasks were never prepared, has none).
bool tasks_table_exists(workflow::Database& database);

// A fresh task id: 10 lowercase hex characters from the system's random
// source (40 bits: a clash among a million tasks has odds of about 1 in 2000,
// and insert_task refuses a duplicate rather than overwrite).
std::string new_task_id();

void insert_task(workflow::Database& database, const Task& task);

// Writes every field of `task` whose row has revision `task.revision - 1`;
// returns false (and writes nothing) when the row changed meanwhile (another
// operator was faster).
bool update_task(workflow::Database& database, const Task& task);

std::optional<Task> find_task(workflow::Database& database, const std::string& id);
std::vector<Task> tasks_of_node(workflow::Database& database, const std::string& node);
std::vector<Task> all_tasks(workflow::Database& database);

}  // namespace mmm::worklists
