#pragma once
// Registration of the subcommand groups of the `mmm` executable. Each group
// lives in its own file and does its work inside CLI11 callbacks; a callback
// that finishes but has something to flag (e.g. a survey with unreadable
// files) sets the exit code instead of throwing.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <utility>

#include "workflow/node_registry.h"
#include "workflow/study/study.h"

namespace mmm::app {

// mmm mesh info|convert|decimate|survey
void register_mesh_commands(CLI::App& app);

// mmm validate|graph|nodes (the registry must outlive the parse)
void register_workflow_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// mmm atlas build|check|show
void register_atlas_commands(CLI::App& app);

// mmm patient synth
void register_patient_commands(CLI::App& app);

// mmm overlay: atlas bones outlined over a radiograph pair
void register_overlay_commands(CLI::App& app);

// mmm calibrate: a pair's calibration from a calibration object (beads)
void register_calibrate_commands(CLI::App& app);

// mmm study create|set, mmm run, mmm status, mmm explain
void register_study_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// mmm worklist, mmm task claim|release|reassign|submit|accept|reject|cancel|show,
// mmm audit verify|show, mmm operator add|list
void register_task_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// mmm report: the study report for people (index.html)
void register_report_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// mmm serve: the operator web UI (the registry must outlive the server)
void register_serve_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// mmm cohort create|run|status, mmm gc (the registry must outlive the parse)
void register_cohort_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// This program's version and build revision, recorded with what it creates.
workflow::Provenance this_program();

// The path of this executable (/proc/self/exe), for the processes it starts.
std::filesystem::path this_executable_path();

// mmm worker run-node REQUEST: one node execution for a Slurm job
void register_worker_commands(CLI::App& app, const workflow::NodeRegistry& registry);

// "NAME=VALUE" -> {NAME, VALUE}; throws InvalidInputError naming `what`
// otherwise.
std::pair<std::string, std::string> split_assignment(const std::string& text,
                                                     const std::string& what);

// Exit codes of every command (documented in docs/architecture.md, "Exit codes").
inline constexpr int kExitOk = 0;       // done
inline constexpr int kExitFailed = 1;   // the command (or a node) failed; message says why
inline constexpr int kExitUsage = 2;    // the command line is wrong
inline constexpr int kExitWaiting = 3;  // the study waits for a manual task
inline constexpr int kExitLocked = 4;   // another runner holds the study

// Exit code requested by the command that ran (0 unless it called
// set_exit_code).
int exit_code();
void set_exit_code(int code);

}  // namespace mmm::app
