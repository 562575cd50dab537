#include "core/landmarks/scripted_clicks.h"

#include <cmath>
#include <random>

#include "core/errors.h"

namespace mmm::landmarks {

nlohmann::json scripted_clicks(const nlohmann::json& ground_truth,
                               const ScriptedClickOptions& options) {
  if (!(options.noise_px >= 0.0) || !std::isfinite(options.noise_px)) {
    throw InvalidInputError("scripted clicks: noise " + std::to_string(options.noise_px) +
                            " px; use a finite value >= 0 (1.5 px)");
  }
  const auto found = ground_truth.find("landmarks");
  if (found == ground_truth.end() || !found->is_object()) {
    throw InvalidInputError(
        "scripted clicks: the ground truth has no 'landmarks' object; give the "
        "ground_truth.json that mmm patient synth writes");
  }
  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  nlohmann::json clicks = nlohmann::json::object();
  for (const std::string& name : options.landmarks) {
    const auto landmark = found->find(name);
    if (landmark == found->end() || !landmark->contains("pixels")) {
      throw InvalidInputError("scripted clicks: the ground truth has no pixels for landmark '" +
                              name + "'");
    }
    for (const auto& [view, pixel] : (*landmark)["pixels"].items()) {
      const auto where = [&name, &view = view] {
        std::string text = "scripted clicks: landmark '";
        text += name;
        text += "', view '";
        text += view;
        return text + "': ";
      };
      if (!pixel.is_array() || pixel.size() != 2 || !pixel[0].is_number() ||
          !pixel[1].is_number()) {
        throw InvalidInputError(where() + "the pixel is not [u, v]");
      }
      const double u = pixel[0].get<double>() + options.noise_px * noise(random);
      const double v = pixel[1].get<double>() + options.noise_px * noise(random);
      if (!std::isfinite(u) || !std::isfinite(v)) {
        throw InvalidInputError(where() + "the pixel is not finite");
      }
      clicks[name][view] = {u, v};
    }
  }
  return nlohmann::json{{"landmarks", clicks}};
}

}  // namespace mmm::landmarks
