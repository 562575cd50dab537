#include "nodes/import_markups.h"

#include "core/landmarks/landmark_set.h"
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
  const landmarks::MarkupsReadResult result =
      landmarks::read_slicer_markups(context.input("markups").path);
  for (const std::string& note : result.notes) context.warn(note);
  context.info(std::to_string(result.landmarks.landmarks.size()) + " landmark(s) read");
  context.set_output("landmarks", landmarks::landmark_set_to_json_text(result.landmarks));
}

}  // namespace mmm::nodes
