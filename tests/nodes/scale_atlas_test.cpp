// Node scale_atlas on the toy leg: the atlas travels as a bundle, the
// patient's atlas comes back whole (readable, every mesh moved), the report
// names residuals and factors, the overlay is a PNG with or without
// radiographs, and bad landmarks fail with their names.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <variant>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/image/png.h"
#include "core/image/projection.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "nodes/scale_atlas.h"
#include "tests/nodes/node_harness.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::nodes {
namespace {

using Eigen::Vector3d;
using workflow::PortType;

landmarks::LandmarkSet shifted_station(const atlas::Atlas& atlas, const Vector3d& shift) {
  landmarks::LandmarkSet set;
  set.source = "test";
  for (const char* name : {"femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"}) {
    set.landmarks.push_back({name, atlas.find_landmark(name)->position + shift, {}, {}});
  }
  return set;
}

// A blank radiograph pair looking at the toy leg.
std::string toy_radiographs(const std::filesystem::path& folder) {
  image::BiplanarOptions options;
  options.isocentre_mm = Vector3d(60, 0, -400);
  options.field_width_mm = 300;
  options.field_height_mm = 1000;
  options.detector_pixel_pitch_mm = 2.0;
  std::vector<image::RadiographFile> files;
  std::map<std::string, std::string> pngs;
  for (const image::RadiographView& view : image::make_biplanar_views(options)) {
    image::GrayImage16 blank(view.width, view.height);
    const std::filesystem::path file = folder / (view.name + ".png");
    image::write_png(blank, file);
    pngs[view.name] = mmm::test::read_text(file);
    files.push_back({view, view.name + ".png"});
  }
  return image::radiograph_pair_to_json_text(
      image::make_radiograph_pair(files, pngs, folder / "views.json"));
}

TEST(ScaleAtlasNodeTest, ReturnsTheWholePatientAtlasAReportAndAnOverlay) {
  test::NodeHarness harness;
  mmm::test::write_toy_leg(harness.folder() / "toy");
  const atlas::Atlas generic = atlas::read_atlas(harness.folder() / "toy");
  const auto atlas_ref = harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"));
  const Vector3d shift(5, -3, 12);
  const auto landmarks_ref =
      harness.add(PortType::kLandmarkSet,
                  landmarks::landmark_set_to_json_text(shifted_station(generic, shift)));
  for (const bool with_radiographs : {false, true}) {
    SCOPED_TRACE(with_radiographs ? "with radiographs" : "without");
    std::map<std::string, workflow::ArtifactRef> inputs = {{"atlas", atlas_ref},
                                                           {"landmarks", landmarks_ref}};
    if (with_radiographs) {
      inputs["radiographs"] =
          harness.add(PortType::kRadiographPair, toy_radiographs(harness.folder()));
    }
    const auto outputs = harness.run<ScaleAtlas>(inputs);
    const std::filesystem::path out = harness.folder() / (with_radiographs ? "out2" : "out1");
    unpack_directory(mmm::test::read_text(outputs.at("atlas").path), out, "output");
    const atlas::Atlas patient = atlas::read_atlas(out);
    // A pure translation of the landmarks moves everything by it.
    EXPECT_LT((patient.markers[0].position - generic.markers[0].position - shift).norm(), 1e-6);
    const mesh::IndexedMesh tibia =
        atlas::load_mesh(out, patient.find_bone("tibia_r")->meshes, "lod1");
    const mesh::IndexedMesh tibia0 =
        atlas::load_mesh(harness.folder() / "toy", generic.find_bone("tibia_r")->meshes, "lod1");
    EXPECT_LT(((tibia.V - tibia0.V).rowwise() - shift.transpose()).rowwise().norm().maxCoeff(),
              1e-6);
    const nlohmann::json report =
        nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
    EXPECT_LT(report["landmark_residual_mm"]["patella_centre_r"].get<double>(), 1e-6);
    EXPECT_EQ(report["bones"].size(), 5U);
    const image::PngContent overlay =
        image::decode_png("overlay", mmm::test::read_text(outputs.at("overlay").path));
    ASSERT_TRUE(std::holds_alternative<image::RgbImage8>(overlay.image));
    EXPECT_GT(std::get<image::RgbImage8>(overlay.image).width, 100);
  }
}

TEST(ScaleAtlasNodeTest, AMissingRequiredLandmarkIsNamed) {
  test::NodeHarness harness;
  mmm::test::write_toy_leg(harness.folder() / "toy");
  const atlas::Atlas generic = atlas::read_atlas(harness.folder() / "toy");
  landmarks::LandmarkSet set = shifted_station(generic, Vector3d::Zero());
  set.landmarks.erase(set.landmarks.begin());
  try {
    harness.run<ScaleAtlas>(
        {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
         {"landmarks",
          harness.add(PortType::kLandmarkSet, landmarks::landmark_set_to_json_text(set))}});
    FAIL() << "no error";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("femoral_head_centre_r"), std::string::npos)
        << error.what();
  }
}

TEST(ScaleAtlasNodeTest, AMalformedAtlasBundleIsRejected) {
  test::NodeHarness harness;
  landmarks::LandmarkSet set;
  set.landmarks.push_back({"femoral_head_centre_r", Vector3d(0, 0, 0), {}, {}});
  EXPECT_THROW(harness.run<ScaleAtlas>(
                   {{"atlas", harness.add(PortType::kAtlas, "not a bundle")},
                    {"landmarks", harness.add(PortType::kLandmarkSet,
                                              landmarks::landmark_set_to_json_text(set))}}),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::nodes
