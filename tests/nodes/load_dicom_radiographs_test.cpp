// load_radiographs with DICOM radiographs: calibrated from their geometry
// attributes (pinhole and slot-scanning), their window and SOP Instance UID
// hash carried, incomplete geometry refused naming the attribute, and a
// study that never stores what identifies the patient.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "core/errors.h"
#include "core/image/deidentified_radiograph.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_series.h"
#include "core/image/dicom_write.h"
#include "core/image/projection.h"
#include "core/image/radiograph_pair.h"
#include "nodes/load_radiographs.h"
#include "nodes/registry.h"
#include "tests/core/image/dicom_fixtures.h"
#include "tests/nodes/node_harness.h"
#include "tests/support/test_data.h"
#include "workflow/study/study.h"

namespace mmm::nodes {
namespace {

using ::testing::HasSubstr;
using workflow::PortType;

constexpr double kSid = 1700.0;
constexpr double kSod = 1300.0;
constexpr double kPitch = 4.0;  // detector mm: small images

// The reference pair: make_biplanar_views with the same distances, pitch and
// field, the isocentre at the origin.
std::array<image::RadiographView, 2> reference_views(image::ProjectionModel model) {
  image::BiplanarOptions options;
  options.source_to_detector_mm = kSid;
  options.source_to_isocentre_mm = kSod;
  options.detector_pixel_pitch_mm = kPitch;
  options.field_width_mm = 300;
  options.field_height_mm = 900;
  options.model = model;
  return image::make_biplanar_views(options);
}

// A DICOM radiograph of a view's size with the geometry of that system.
image::DicomRadiograph dicom_of(const image::RadiographView& view, const std::string& position,
                                int seed) {
  image::DicomRadiograph dicom;
  dicom.image = image::GrayImage16(view.width, view.height);
  std::mt19937 rng(static_cast<unsigned>(seed));
  for (std::uint16_t& sample : dicom.image.pixels)
    sample = static_cast<std::uint16_t>(rng() % 60000);
  dicom.rows = view.height;
  dicom.columns = view.width;
  dicom.modality = "DX";
  dicom.sop_class_uid = "1.2.840.10008.5.1.4.1.1.1.1";
  dicom.transfer_syntax_uid = "1.2.840.10008.1.2.1";
  dicom.photometric_interpretation = "MONOCHROME2";
  dicom.sop_instance_uid_sha256 = std::string(63, 'a') + std::to_string(seed % 10);
  dicom.window = {20000.0, 30000.0, image::DicomWindowSource::kFile};
  dicom.imager_pixel_spacing = image::PixelSpacingMm{kPitch, kPitch};
  dicom.distance_source_to_detector_mm = kSid;
  dicom.distance_source_to_patient_mm = kSod;
  dicom.view_position = position;
  return dicom;
}

image::RadiographPair run_node(test::NodeHarness& harness, const image::DicomRadiograph& frontal,
                               const image::DicomRadiograph& lateral, const std::string& model) {
  const auto outputs = harness.run<LoadRadiographs>(
      {{"frontal", harness.add(PortType::kFile, image::deidentified_radiograph_text(frontal))},
       {"lateral", harness.add(PortType::kFile, image::deidentified_radiograph_text(lateral))}},
      {{"model", model}});
  return image::radiograph_pair_from_json_text(mmm::test::read_text(outputs.at("radiographs").path),
                                               "output");
}

TEST(LoadDicomRadiographsTest, GeometryFromTheAttributesIsTheSystemsOwn) {
  for (const auto model :
       {image::ProjectionModel::kPinhole, image::ProjectionModel::kSlotScanning}) {
    const auto reference = reference_views(model);
    test::NodeHarness harness;
    const image::RadiographPair pair =
        run_node(harness, dicom_of(reference[0], "AP", 1), dicom_of(reference[1], "LL", 2),
                 image::projection_model_name(model));
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t k = 0; k < 2; ++k) {
      const image::RadiographView& view = pair.views[k].view;
      EXPECT_EQ(view.model, model);
      EXPECT_NEAR(view.pixel_spacing_mm, reference[k].pixel_spacing_mm, 1e-12);
      for (int i = 0; i < 20; ++i) {
        const Eigen::Vector3d X(100 * unit(rng), 100 * unit(rng), 400 * unit(rng));
        EXPECT_LT((image::project(view, X) - image::project(reference[k], X)).norm(), 1e-6)
            << view.name;
      }
      const image::ImageOrigin& origin = pair.origins.at(view.name + ".png");
      EXPECT_EQ(origin.window_centre, 20000.0);
      EXPECT_EQ(origin.window_width, 30000.0);
      EXPECT_EQ(origin.sop_instance_uid_sha256.size(), 64U);
    }
  }
}

TEST(LoadDicomRadiographsTest, AnImageSeenFromTheDetectorSideIsMirrored) {
  const auto reference = reference_views(image::ProjectionModel::kPinhole);
  image::DicomRadiograph frontal = dicom_of(reference[0], "AP", 1);
  frontal.patient_orientation = std::array<std::string, 2>{"R", "F"};
  test::NodeHarness harness;
  const image::RadiographPair pair =
      run_node(harness, frontal, dicom_of(reference[1], "LL", 2), "pinhole");
  const Eigen::Vector3d X(40, 10, 100);
  EXPECT_LT((image::project(pair.views[0].view, X) - image::project(reference[0], X)).norm(), 1e-6);
  const image::GrayImage16 stored = pair.image("frontal");
  EXPECT_EQ(stored.at(0, 5), frontal.image.at(frontal.image.width - 1, 5));
}

TEST(LoadDicomRadiographsTest, IncompleteGeometryIsRefusedNamingTheAttribute) {
  const auto reference = reference_views(image::ProjectionModel::kPinhole);
  image::DicomRadiograph frontal = dicom_of(reference[0], "AP", 1);
  frontal.distance_source_to_detector_mm.reset();
  test::NodeHarness harness;
  try {
    run_node(harness, frontal, dicom_of(reference[1], "LL", 2), "pinhole");
    FAIL() << "a radiograph without its distance was calibrated";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("Distance Source to Detector (0018,1110)"));
    EXPECT_THAT(error.what(), HasSubstr("calibration"));
  }
  image::DicomRadiograph lateral = dicom_of(reference[1], "AP", 2);
  try {
    run_node(harness, dicom_of(reference[0], "AP", 1), lateral, "pinhole");
    FAIL() << "two frontal views were calibrated as a pair";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("View Position (0018,5101)"));
  }
}

TEST(LoadDicomRadiographsTest, AnInconsistentPairIsRefused) {
  const auto reference = reference_views(image::ProjectionModel::kSlotScanning);
  test::NodeHarness harness;
  // The same image as both views.
  const image::DicomRadiograph frontal = dicom_of(reference[0], "AP", 1);
  image::DicomRadiograph copy = dicom_of(reference[1], "LL", 1);
  copy.sop_instance_uid_sha256 = frontal.sop_instance_uid_sha256;
  EXPECT_THAT([&] { run_node(harness, frontal, copy, "slot-scanning"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("is the same image as")));
  // A lateral view of another scan: other rows.
  image::DicomRadiograph other = dicom_of(reference[1], "LL", 2);
  other.imager_pixel_spacing = image::PixelSpacingMm{2 * kPitch, kPitch};
  EXPECT_THAT([&] { run_node(harness, frontal, other, "slot-scanning"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("for one slot scan")));
}

// Every file of a folder, read whole, concatenated.
std::string folder_bytes(const std::filesystem::path& dir) {
  std::string all;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    all += text.str();
  }
  return all;
}

TEST(LoadDicomRadiographsTest, AStudyGivenDicomStoresNothingThatIdentifiesThePatient) {
  const std::filesystem::path dicom = mmm::test::dicom::fixture("dx_mono2_16bit.dcm");
  const mmm::test::ScratchDir root("dicom-study");
  // The fixture's 64 x 48 pixels with a calibration sidecar of that size.
  image::BiplanarOptions options;
  options.detector_pixel_pitch_mm = 4.0;
  auto views = image::make_biplanar_views(options);
  std::vector<image::RadiographFile> files;
  for (image::RadiographView& view : views) {
    const double sx = static_cast<double>(mmm::test::dicom::kWidth) / view.width;
    const double sy = static_cast<double>(mmm::test::dicom::kHeight) / view.height;
    view.P.row(0) *= sx;
    view.P.row(1) *= sy;
    view.width = mmm::test::dicom::kWidth;
    view.height = mmm::test::dicom::kHeight;
    files.push_back({view, view.name + ".png"});
  }
  image::write_view_sidecar(root.path() / "views.json", files);
  const std::filesystem::path workflow_file =
      mmm::test::write_file(root.path() / "wf.yaml", R"yaml(mmm_workflow: 1
name: dicom
inputs:
  calibration: {type: File}
  frontal: {type: File}
  lateral: {type: File}
nodes:
  - {id: radiographs, type: load_radiographs, inputs: {calibration: study.calibration, frontal: study.frontal, lateral: study.lateral}}
)yaml");
  const workflow::NodeRegistry registry = make_node_registry();
  const std::filesystem::path dir = root.path() / "study";
  workflow::Study::create(dir,
                          {workflow_file,
                           {{"calibration", (root.path() / "views.json").string()},
                            {"frontal", dicom.string()},
                            {"lateral", dicom.string()}},
                           {"test", "test"}},
                          registry);
  const std::string stored = folder_bytes(dir);
  EXPECT_THAT(stored, HasSubstr("mmm-deidentified-radiograph"));
  for (const std::string& identifying : mmm::test::dicom::kIdentifyingStrings) {
    EXPECT_EQ(stored.find(identifying), std::string::npos) << identifying;
  }
  EXPECT_EQ(stored.find(mmm::test::dicom::sop_instance_uid(1)), std::string::npos);

  // What the study stored is what the node reads: the fixture's pixels and
  // window, the UID as its hash.
  const image::DicomRadiograph original = image::read_dicom_radiograph(dicom);
  test::NodeHarness harness;
  const auto stored_text = image::deidentified_radiograph_text(original);
  const auto outputs = harness.run<LoadRadiographs>(
      {{"calibration", harness.add_file(PortType::kFile, root.path() / "views.json")},
       {"frontal", harness.add(PortType::kFile, stored_text)},
       {"lateral", harness.add(PortType::kFile, stored_text)}});
  const image::RadiographPair pair = image::radiograph_pair_from_json_text(
      mmm::test::read_text(outputs.at("radiographs").path), "output");
  EXPECT_EQ(pair.image("frontal").pixels, original.image.pixels);
  EXPECT_EQ(pair.origins.at("frontal.png").sop_instance_uid_sha256,
            original.sop_instance_uid_sha256);
}

// A DX file of a reference view, written by mmm's writer, with an identity.
std::string dicom_file_of(const image::RadiographView& view, bool frontal, int seed) {
  const image::DicomRadiograph dicom = dicom_of(view, frontal ? "AP" : "LL", seed);
  image::DicomExport options;
  options.view_position = frontal ? "AP" : "LL";
  options.patient_orientation =
      frontal ? std::array<std::string, 2>{"L", "F"} : std::array<std::string, 2>{"A", "F"};
  options.row_pitch_mm = kPitch;
  options.column_pitch_mm = kPitch;
  options.source_to_detector_mm = kSid;
  options.source_to_patient_mm = kSod;
  options.patient_name = "ROE^JANET^SERIES";
  options.patient_id = "PID-SERIES-77";
  options.patient_birth_date = "19610704";
  options.study_date = "20251111";
  options.sop_instance_uid = "2.25.77" + std::to_string(seed);
  return image::dicom_radiograph_bytes(dicom.image, options);
}

// An exam exported as one folder per series (named after the patient, as
// exports often are), given for both views: each view finds its own image,
// the pair is the one the two files give, and nothing of the identity or of
// the folder names is stored.
TEST(LoadDicomRadiographsTest, AnExamFolderGivesBothViewsAndIsStoredDeidentified) {
  const mmm::test::ScratchDir root("dicom-exam");
  const auto reference = reference_views(image::ProjectionModel::kSlotScanning);
  const std::filesystem::path exam = root.path() / "ROE_JANET_EXAM";
  const std::string frontal_bytes = dicom_file_of(reference[0], true, 1);
  const std::string lateral_bytes = dicom_file_of(reference[1], false, 2);
  mmm::test::write_file(exam / "SERIES_LAT" / "IM0001.dcm", lateral_bytes);
  mmm::test::write_file(exam / "SERIES_AP" / "IM0001.dcm", frontal_bytes);
  mmm::test::write_file(exam / "DICOMDIR", "index");
  const std::filesystem::path workflow_file =
      mmm::test::write_file(root.path() / "wf.yaml", R"yaml(mmm_workflow: 1
name: dicom_exam
inputs:
  frontal: {type: File}
  lateral: {type: File}
nodes:
  - {id: radiographs, type: load_radiographs, params: {model: slot-scanning}, inputs: {frontal: study.frontal, lateral: study.lateral}}
)yaml");
  const workflow::NodeRegistry registry = make_node_registry();
  const std::filesystem::path dir = root.path() / "study";
  workflow::Study study = workflow::Study::create(
      dir, {workflow_file, {{"frontal", exam.string()}, {"lateral", exam.string()}}, {"t", "t"}},
      registry);
  const std::string stored = folder_bytes(dir);
  for (const char* identifying : {"ROE^JANET", "ROE_JANET", "PID-SERIES-77", "19610704", "20251111",
                                  "SERIES_AP", "IM0001", "2.25.771"}) {
    const std::size_t at = stored.find(identifying);
    EXPECT_EQ(at, std::string::npos)
        << identifying << " in: " << stored.substr(at < 80 ? 0 : at - 80, 160);
  }
  const std::string series = study.artifacts().get(study.inputs().at("frontal").hash);
  EXPECT_TRUE(image::is_deidentified_series(series));

  test::NodeHarness from_folder;
  const auto folder_out =
      from_folder.run<LoadRadiographs>({{"frontal", from_folder.add(PortType::kFile, series)},
                                        {"lateral", from_folder.add(PortType::kFile, series)}},
                                       {{"model", "slot-scanning"}});
  test::NodeHarness from_files;
  const auto files_out =
      from_files.run<LoadRadiographs>({{"frontal", from_files.add(PortType::kFile, frontal_bytes)},
                                       {"lateral", from_files.add(PortType::kFile, lateral_bytes)}},
                                      {{"model", "slot-scanning"}});
  EXPECT_EQ(mmm::test::read_text(folder_out.at("radiographs").path),
            mmm::test::read_text(files_out.at("radiographs").path));
  const image::RadiographPair pair = image::radiograph_pair_from_json_text(
      mmm::test::read_text(folder_out.at("radiographs").path), "output");
  const Eigen::Vector3d X(30, -20, 150);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_LT((image::project(pair.views[k].view, X) - image::project(reference[k], X)).norm(),
              1e-6);
  }
}

TEST(LoadDicomRadiographsTest, AFolderWithoutTheViewNamesWhatItHolds) {
  const auto reference = reference_views(image::ProjectionModel::kPinhole);
  const std::string series = image::deidentified_series_text(
      {dicom_of(reference[0], "AP", 1), dicom_of(reference[0], "PA", 3)});
  test::NodeHarness harness;
  EXPECT_THAT(
      [&] {
        (void)harness.run<LoadRadiographs>({{"frontal", harness.add(PortType::kFile, series)},
                                            {"lateral", harness.add(PortType::kFile, series)}});
      },
      ::testing::ThrowsMessage<IoError>(HasSubstr("with a View Position (0018,5101) of AP or PA")));
}

}  // namespace
}  // namespace mmm::nodes
