#include "core/image/deidentified_radiograph.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "tests/core/image/dicom_fixtures.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

namespace fx = test::dicom;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The well-formed fixtures and the number of their SOP Instance UID.
const std::vector<std::pair<std::string, int>> kReadableFixtures = {
    {"dx_mono2_16bit.dcm", 1},     {"dx_rle.dcm", 2},
    {"cr_mono1_12bit.dcm", 3},     {"sc_8bit.dcm", 4},
    {"dx_rescale_windows.dcm", 5}, {"implicit_no_preamble.dcm", 6}};

TEST(DicomDeidentifiedTest, RoundTripIsExact) {
  for (const auto& [name, uid] : kReadableFixtures) {
    const DicomRadiograph original = read_dicom_radiograph(fx::fixture(name));
    const std::string text = deidentified_radiograph_text(original);
    const DicomRadiograph back = deidentified_radiograph_from_text(text, name + ".json");
    EXPECT_EQ(back, original) << name;
    // Written again, the same text (stable for content hashing).
    EXPECT_EQ(deidentified_radiograph_text(back), text) << name;
  }
}

TEST(DicomDeidentifiedTest, NothingIdentifyingSurvives) {
  for (const auto& [name, uid] : kReadableFixtures) {
    // The fixture does carry the identifying values...
    const std::string dicom = test::read_text(fx::fixture(name));
    ASSERT_THAT(dicom, HasSubstr("DOE^JANE^FIXTURE")) << name;
    ASSERT_THAT(dicom, HasSubstr(fx::sop_instance_uid(uid))) << name;
    // ...and the de-identified text none of them, nor the UIDs.
    const std::string text = deidentified_radiograph_text(read_dicom_radiograph(fx::fixture(name)));
    for (const std::string& identifying : fx::kIdentifyingStrings) {
      EXPECT_THAT(text, ::testing::Not(HasSubstr(identifying))) << name;
    }
    EXPECT_THAT(text, ::testing::Not(HasSubstr(fx::sop_instance_uid(uid)))) << name;
    // Study and series UIDs share the fixtures' root.
    EXPECT_THAT(text, ::testing::Not(HasSubstr("1.2.826.0.1.3680043.8.498.7731"))) << name;
    EXPECT_THAT(text, HasSubstr(hash::sha256_hex(fx::sop_instance_uid(uid)))) << name;
  }
}

// Edits one field of a valid document and expects an IoError naming it.
void expect_field_error(const std::function<void(nlohmann::json&)>& edit,
                        const std::string& field) {
  const DicomRadiograph original = read_dicom_radiograph(fx::fixture("cr_mono1_12bit.dcm"));
  nlohmann::json document = nlohmann::json::parse(deidentified_radiograph_text(original));
  edit(document);
  try {
    (void)deidentified_radiograph_from_text(document.dump(), "edited.json");
    ADD_FAILURE() << "accepted an invalid '" << field << "'";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("edited.json"), HasSubstr(field)));
  }
}

TEST(DicomDeidentifiedTest, EachFieldIsChecked) {
  expect_field_error([](auto& d) { d["format"] = "mmm-radiograph-pair"; }, "'format'");
  expect_field_error([](auto& d) { d["version"] = 2; }, "'version'");
  expect_field_error([](auto& d) { d.erase("rows"); }, "'rows' is missing");
  expect_field_error([](auto& d) { d["rows"] = 47; }, "'png_base64'");  // size mismatch
  expect_field_error([](auto& d) { d["columns"] = 0; }, "'columns'");
  expect_field_error([](auto& d) { d["bits_stored"] = 17; }, "'bits_stored'");
  expect_field_error([](auto& d) { d["photometric_interpretation"] = "RGB"; },
                     "'photometric_interpretation'");
  expect_field_error([](auto& d) { d["value_map"]["inverted"] = false; }, "'value_map'");
  expect_field_error([](auto& d) { d["value_map"]["scale"] = 0; }, "'value_map.scale'");
  expect_field_error([](auto& d) { d["window"]["source"] = "guess"; }, "'window.source'");
  expect_field_error([](auto& d) { d["window"]["width"] = -1; }, "'window.width'");
  expect_field_error(
      [](auto& d) {
        d["imager_pixel_spacing_mm"] = {0.1, 0.0};
      },
      "'imager_pixel_spacing_mm'");
  expect_field_error(
      [](auto& d) {
        d["patient_orientation"] = {"L", "X"};
      },
      "'patient_orientation'");
  expect_field_error([](auto& d) { d["image_laterality"] = "left"; }, "'image_laterality'");
  expect_field_error([](auto& d) { d["sop_instance_uid_sha256"] = "1.2.3"; },
                     "'sop_instance_uid_sha256'");
  // A field that is not in the format (e.g. an identifying one added by
  // hand) is refused, not carried along.
  expect_field_error([](auto& d) { d["patient_name"] = "X"; }, "'patient_name'");
  expect_field_error([](auto& d) { d["sha256"] = std::string(64, '0'); }, "'sha256'");
  expect_field_error([](auto& d) { d["png_base64"] = "not base64!"; }, "png_base64");
}

TEST(DicomDeidentifiedTest, NotJsonIsRefused) {
  EXPECT_THROW((void)deidentified_radiograph_from_text("{", "broken.json"), IoError);
  EXPECT_THROW((void)deidentified_radiograph_from_text("[]", "array.json"), IoError);
}

}  // namespace
}  // namespace mmm::image
