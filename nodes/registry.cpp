#include "nodes/registry.h"

#include "core/image/deidentified_radiograph.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_series.h"
#include "nodes/build_hulls.h"
#include "nodes/build_muscle_lattice.h"
#include "nodes/decimate_mesh.h"
#include "nodes/decompose_fibres.h"
#include "nodes/fit_bone_outlines.h"
#include "nodes/fuse_motion.h"
#include "nodes/import_markups.h"
#include "nodes/landmark_report.h"
#include "nodes/load_mesh.h"
#include "nodes/load_radiographs.h"
#include "nodes/measure_mesh.h"
#include "nodes/scale_atlas.h"
#include "nodes/simulate_muscles.h"
#include "nodes/static_trial_landmarks.h"
#include "nodes/wrap_muscles.h"
#include "worklists/landmark_task.h"
#include "worklists/outline_review_task.h"

namespace mmm::nodes {

workflow::NodeRegistry make_node_registry() {
  workflow::NodeRegistry registry;
  registry.add<LoadMesh>();
  registry.add<DecimateMesh>();
  registry.add<MeasureMesh>();
  registry.add<LoadRadiographs>();
  registry.add<worklists::LandmarkStation>();
  registry.add<worklists::OutlineReviewStation>();
  registry.add<LandmarkReport>();
  registry.add<ImportMarkups>();
  registry.add<StaticTrialLandmarks>();
  registry.add<ScaleAtlas>();
  registry.add<FitBoneOutlines>();
  registry.add<FuseMotion>();
  registry.add<BuildHulls>();
  registry.add<BuildMuscleLattice>();
  registry.add<WrapMuscles>();
  registry.add<SimulateMuscles>();
  registry.add<DecomposeFibres>();
  // A DICOM file given to a study is stored de-identified (PS3.15 Annex E):
  // its pixels and geometry, the SOP Instance UID only as a hash.
  registry.add_file_importer({"DICOM de-identification",
                              [](std::string_view head) { return image::looks_like_dicom(head); },
                              [](std::string_view bytes, const std::filesystem::path& origin) {
                                return image::deidentified_radiograph_text(
                                    image::read_dicom_radiograph(bytes, origin));
                              }});
  // A folder of DICOM files (a series, or an exam with both views) is stored
  // as its images de-identified, without the folder's file names.
  registry.add_folder_importer(
      {"DICOM series de-identification",
       [](const std::filesystem::path& folder) { return image::folder_holds_dicom(folder); },
       [](const std::filesystem::path& folder) {
         return image::deidentified_series_text(image::read_dicom_folder(folder));
       }});
  return registry;
}

}  // namespace mmm::nodes
