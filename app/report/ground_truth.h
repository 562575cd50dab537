#pragma once
// The report's comparison with a synthetic patient's ground truth
// (mmm patient synth writes PATIENT/ground_truth.json and PATIENT/atlas):
// how far each accepted landmark lies from the true one, and how far every
// scaled bone and muscle surface lies from the patient's own
// (atlas_surface_errors.h). Only synthetic patients have a truth.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace mmm::app::report {

// HTML fragments (a paragraph and a table) comparing the study's outputs
// with the patient folder's truth.
// Throw InvalidInputError naming a patient folder without ground_truth.json
// or atlas/, or an element the truth lacks.

// The accepted landmarks (landmarks.json, parsed; the file named in errors)
// against ground_truth.json: distance per landmark.
std::string truth_landmarks_html(const nlohmann::json& landmarks,
                                 const std::filesystem::path& landmarks_file,
                                 const std::filesystem::path& patient);

// outputs/patient_atlas against patient/atlas: surface distance per bone
// and muscle at rest; empty while there is no scaled atlas yet.
std::string truth_surfaces_html(const std::filesystem::path& outputs,
                                const std::filesystem::path& patient, int threads);

}  // namespace mmm::app::report
