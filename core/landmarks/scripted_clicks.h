#pragma once
// A scripted operator for demonstrations and tests, never for patients: the
// landmark pixels a person would click, made from a synthetic patient's
// ground truth (ground_truth.json of mmm patient synth: each landmark's
// exact pixel in each view) plus Gaussian click noise. The result is the
// submission the landmark station takes from people
// ({"landmarks": {NAME: {VIEW: [u, v]}}}), so it goes through the same
// validation, audit and review.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mmm::landmarks {

struct ScriptedClickOptions {
  std::vector<std::string> landmarks = {"femoral_head_centre_r", "patella_centre_r",
                                        "ankle_centre_r"};
  // Standard deviation of each click coordinate (pixels, >= 0). 1.5 px is
  // about 0.6 mm on the synthetic radiographs: a careful operator at full zoom.
  double noise_px = 1.5;
  std::uint64_t seed = 1;
};

// Throws InvalidInputError naming the landmark or view when the ground truth
// lacks it or a pixel is not finite, and for a negative or non-finite noise.
nlohmann::json scripted_clicks(const nlohmann::json& ground_truth,
                               const ScriptedClickOptions& options);

}  // namespace mmm::landmarks
