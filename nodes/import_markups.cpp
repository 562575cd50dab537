#include "nodes/import_markups.h"

#include "core/errors.h"
#include "core/landmarks/landmark_set.h"
#include "core/landmarks/landmark_validation.h"
#include "core/landmarks/slicer_markups.h"

namespace mmm::nodes {

workflow::NodeSpec ImportMarkups::spec() {
  using workflow::port::File;
  using workflow::port::LandmarkSet;
  return workflow::NodeSpec{"import_markups", 1,
                            "3-D landmarks from a 3D Slicer Markups file (.mrk.json)"}
      .input<File>("markups", "The .mrk.json point list (LPS or RAS, mm)")
      .output<LandmarkSet>("landmarks", "Landmarks, patient frame (RAS, mm)");
}

void ImportMarkups::run(workflow::NodeContext& context) {
  const std::filesystem::path& file = context.input("markups").path;
  const landmarks::MarkupsReadResult result = landmarks::read_slicer_markups(file);
  for (const std::string& note : result.notes) context.warn(note);
  // The station's anatomical checks, and the mirror check a wrong
  // coordinateSystem fails: such a file is rejected, never scaled.
  landmarks::AnatomyRules rules;
  rules.declared_coordinate_system = result.coordinate_system;
  const std::vector<std::string> reasons =
      landmarks::check_landmark_anatomy(result.landmarks, rules);
  if (!reasons.empty()) {
    std::string text;
    for (const std::string& reason : reasons) text += "\n  - " + reason;
    throw InvalidInputError("input 'markups' (" + result.coordinate_system +
                            " point list): the landmarks fail the anatomical checks:" + text);
  }
  context.info(std::to_string(result.landmarks.landmarks.size()) + " landmark(s) read (" +
               result.coordinate_system + ")");
  context.set_output("landmarks", landmarks::landmark_set_to_json_text(result.landmarks));
}

}  // namespace mmm::nodes
