#pragma once
// A small deterministic mesh workflow for the CLI tests of studies: one
// surface (an icosphere written as PLY) is loaded, decimated twice in a
// chain and once on a side branch, and measured; everything runs the real
// node types of the mmm executable.
//
//   load -> coarse -> coarser -> measure_coarser
//        \-> side
//         \-> measure_full

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/mesh/io/ply.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::app::test {

inline constexpr const char* kMeshWorkflow = R"yaml(mmm_workflow: 1
name: crash_demo
description: Chain and branch of mesh nodes for the study CLI tests
inputs:
  surface: {type: File, description: The input surface (PLY)}
nodes:
  - id: load
    type: load_mesh
    params: {format: ply}
    inputs: {file: study.surface}
  - id: coarse
    type: decimate_mesh
    params: {target_faces: 1200}
    inputs: {mesh: load.mesh}
  - id: coarser
    type: decimate_mesh
    params: {target_faces: 300}
    inputs: {mesh: coarse.decimated}
  - id: side
    type: decimate_mesh
    params: {target_faces: 800}
    inputs: {mesh: load.mesh}
  - id: measure_coarser
    type: measure_mesh
    inputs: {mesh: coarser.decimated}
  - id: measure_full
    type: measure_mesh
    inputs: {mesh: load.mesh}
outputs:
  coarser: coarser.decimated
  side: side.decimated
  coarser_report: measure_coarser.report
  full_report: measure_full.report
)yaml";

// Writes the workflow and an icosphere (5120 faces, radius 40 mm) into
// `dir`; returns {workflow, surface}.
inline std::pair<std::filesystem::path, std::filesystem::path> write_mesh_workflow(
    const std::filesystem::path& dir, int subdivisions = 4) {
  const std::filesystem::path workflow =
      mmm::test::write_file(dir / "crash_demo.yaml", kMeshWorkflow);
  const std::filesystem::path surface = dir / "surface.ply";
  mesh::write_ply(mesh::make_icosphere(subdivisions, 40.0, Eigen::Vector3d::Zero()), surface);
  return {workflow, surface};
}

inline std::string create_command(const std::filesystem::path& study,
                                  const std::filesystem::path& workflow,
                                  const std::filesystem::path& surface) {
  return "study create " + study.string() + " --workflow " + workflow.string() +
         " --input surface=" + surface.string();
}

// `mmm status DIR --json`, parsed.
inline nlohmann::json status_json(const std::filesystem::path& study) {
  const mmm::test::CommandResult result =
      mmm::test::run_mmm("status " + study.string() + " --json");
  if (result.exit_code != 0) throw std::runtime_error("mmm status failed: " + result.err);
  return nlohmann::json::parse(result.out);
}

// node id -> its current result's outputs ({"port": {"type", "hash"}}).
inline std::map<std::string, nlohmann::json> result_outputs(const nlohmann::json& status) {
  std::map<std::string, nlohmann::json> outputs;
  for (const auto& node : status["nodes"]) {
    if (node.contains("result")) outputs[node["id"]] = node["result"]["outputs"];
  }
  return outputs;
}

}  // namespace mmm::app::test
