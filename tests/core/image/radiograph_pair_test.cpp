#include "core/image/radiograph_pair.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "core/errors.h"
#include "core/image/png.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

namespace fs = std::filesystem;

// A small calibrated pair on disk: views.json, frontal.png, lateral.png,
// each image a gradient so that its content is known.
class RadiographPairTest : public ::testing::Test {
 protected:
  void SetUp() override {
    BiplanarOptions options;
    options.field_width_mm = 40;
    options.field_height_mm = 60;
    options.detector_pixel_pitch_mm = 2.0;
    const std::array<RadiographView, 2> views = make_biplanar_views(options);
    std::vector<RadiographFile> files;
    for (const RadiographView& view : views) {
      GrayImage16 image(view.width, view.height);
      for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        image.pixels[i] = static_cast<std::uint16_t>(i * 7);
      }
      write_png(image, dir_ / (view.name + ".png"));
      files.push_back({view, view.name + ".png"});
    }
    write_view_sidecar(dir_ / "views.json", files);
  }

  test::ScratchDir dir_{"radiograph-pair"};
};

TEST_F(RadiographPairTest, LoadSerialiseAndParseRoundTrip) {
  const RadiographPair pair = load_radiograph_pair(dir_ / "views.json");
  ASSERT_EQ(pair.views.size(), 2U);
  const std::string text = radiograph_pair_to_json_text(pair);
  const RadiographPair back = radiograph_pair_from_json_text(text, "artifact");
  EXPECT_EQ(back.images, pair.images);
  EXPECT_EQ(radiograph_pair_to_json_text(back), text) << "serialisation is canonical";
  EXPECT_TRUE(back.view("lateral").view.P.isApprox(pair.view("lateral").view.P, 0.0));
  const GrayImage16 frontal = back.image("frontal");
  EXPECT_EQ(frontal.width, pair.view("frontal").view.width);
  EXPECT_EQ(frontal.pixels[5], 35);
  EXPECT_EQ(back.image_sha256("frontal").size(), 64U);
  EXPECT_THROW((void)back.view("oblique"), InvalidInputError);
}

TEST_F(RadiographPairTest, AnImageOfTheWrongSizeNamesBothSizes) {
  write_png(GrayImage16(3, 4), dir_ / "lateral.png");
  try {
    (void)load_radiograph_pair(dir_ / "views.json");
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), dir_ / "lateral.png");
    EXPECT_NE(std::string(error.what()).find("3 x 4 pixels"), std::string::npos) << error.what();
  }
}

TEST_F(RadiographPairTest, AMissingImageNamesItsPath) {
  fs::remove(dir_ / "frontal.png");
  try {
    (void)load_radiograph_pair(dir_ / "views.json");
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), dir_ / "frontal.png");
  }
}

TEST_F(RadiographPairTest, ADamagedSerialisationIsRejected) {
  std::string text = radiograph_pair_to_json_text(load_radiograph_pair(dir_ / "views.json"));
  EXPECT_THROW((void)radiograph_pair_from_json_text(text.substr(0, text.size() / 2), "a"), IoError);
  const std::size_t at = text.find("png_base64\":\"") + 20;
  text[at] = text[at] == 'A' ? 'B' : 'A';
  try {
    (void)radiograph_pair_from_json_text(text, "artifact");
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("SHA-256"), std::string::npos) << error.what();
  }
}

TEST_F(RadiographPairTest, ImagesGivenByViewNameAreChecked) {
  const RadiographPair loaded = load_radiograph_pair(dir_ / "views.json");
  std::map<std::string, std::string> by_view = {{"frontal", loaded.images.at("frontal.png")},
                                                {"lateral", loaded.images.at("lateral.png")}};
  const RadiographPair pair = make_radiograph_pair(loaded.views, by_view, "study");
  EXPECT_EQ(pair.images, loaded.images);
  by_view.erase("lateral");
  EXPECT_THROW((void)make_radiograph_pair(loaded.views, by_view, "study"), InvalidInputError);
  write_png(GrayImage16(3, 4), dir_ / "small.png");
  by_view["lateral"] = test::read_text(dir_ / "small.png");  // wrong size for the lateral view
  EXPECT_THROW((void)make_radiograph_pair(loaded.views, by_view, "study"), IoError);
}

}  // namespace
}  // namespace mmm::image
