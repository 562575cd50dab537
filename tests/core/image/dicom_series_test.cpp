// Radiographs given as a folder of DICOM files (core/image/dicom_series.h):
// the bounded walk, the de-identified series document and the choice of a
// view's image by View Position.

#include "core/image/dicom_series.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/image/dicom_write.h"
#include "tests/core/image/dicom_fixtures.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A small DX file written by mmm's own writer.
std::string dx_bytes(const std::string& position, int uid_number, std::uint16_t level) {
  GrayImage16 image(8, 6);
  for (std::size_t k = 0; k < image.pixels.size(); ++k) {
    image.pixels[k] = static_cast<std::uint16_t>(level + k);
  }
  DicomExport options;
  options.view_position = position;
  options.patient_orientation = position == "AP" ? std::array<std::string, 2>{"L", "F"}
                                                 : std::array<std::string, 2>{"A", "F"};
  options.patient_name = "ROE^RICHARD^SERIES";
  options.patient_id = "PID-SERIES-1";
  options.patient_birth_date = "19500101";
  options.study_date = "20250102";
  options.sop_instance_uid = "1.2.826.0.1.3680043.8.498.99." + std::to_string(uid_number);
  return dicom_radiograph_bytes(image, options);
}

class DicomSeriesTest : public ::testing::Test {
 protected:
  // An exam as a PACS exports it: one folder per series, an index, a note.
  DicomSeriesTest() {
    test::write_file(exam_ / "ROE_RICHARD" / "SERIES_2" / "IM0001.dcm", dx_bytes("LL", 2, 2000));
    test::write_file(exam_ / "ROE_RICHARD" / "SERIES_1" / "IM0001.dcm", dx_bytes("AP", 1, 1000));
    test::write_file(exam_ / "DICOMDIR", dx_bytes("AP", 9, 9000));  // an index is no image
    test::write_file(exam_ / "README.txt", "exported by a viewer\n");
  }

  test::ScratchDir scratch_{"dicom-series"};
  fs::path exam_ = scratch_ / "exam";
};

TEST_F(DicomSeriesTest, AnExamFolderGivesItsImagesInPathOrder) {
  EXPECT_TRUE(folder_holds_dicom(exam_));
  const std::vector<DicomRadiograph> images = read_dicom_folder(exam_);
  ASSERT_EQ(images.size(), 2U);
  EXPECT_EQ(images[0].view_position, "AP");
  EXPECT_EQ(images[0].image.pixels[0], 1000);
  EXPECT_EQ(images[1].view_position, "LL");
  EXPECT_EQ(choose_view_image(images, "frontal", exam_).index, 0U);
  EXPECT_EQ(choose_view_image(images, "lateral", exam_).index, 1U);
  EXPECT_THAT(choose_view_image(images, "lateral", exam_).reason,
              HasSubstr("image 2 of 2, View Position LL"));
}

TEST_F(DicomSeriesTest, TheSameImageTwiceCountsOnce) {
  test::write_file(exam_ / "copy" / "IM0001.dcm", dx_bytes("AP", 1, 1000));
  EXPECT_EQ(read_dicom_folder(exam_).size(), 2U);
}

TEST_F(DicomSeriesTest, AFolderOfOneImageGivesItForEitherView) {
  const std::vector<DicomRadiograph> images = read_dicom_folder(exam_ / "ROE_RICHARD" / "SERIES_2");
  ASSERT_EQ(images.size(), 1U);
  EXPECT_EQ(choose_view_image(images, "frontal", exam_).index, 0U);
}

TEST_F(DicomSeriesTest, AnAmbiguousChoiceListsTheImages) {
  test::write_file(exam_ / "ROE_RICHARD" / "SERIES_3" / "IM0001.dcm", dx_bytes("PA", 3, 3000));
  const std::vector<DicomRadiograph> images = read_dicom_folder(exam_);
  ASSERT_EQ(images.size(), 3U);
  try {
    (void)choose_view_image(images, "frontal", "exam");
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("holds 3 radiographs and 2 with a View Position"));
    EXPECT_THAT(error.what(), HasSubstr("image 3: 8 x 6, View Position (0018,5101) 'PA'"));
    EXPECT_THAT(error.what(), HasSubstr("hint: give that view's file"));
  }
  EXPECT_THROW((void)choose_view_image(images, "oblique", "exam"), IoError);
}

TEST_F(DicomSeriesTest, ABrokenDicomFileInTheFolderIsNamed) {
  const fs::path broken = exam_ / "ROE_RICHARD" / "SERIES_1" / "IM0002.dcm";
  fs::copy_file(test::dicom::fixture("truncated.dcm"), broken);
  try {
    (void)read_dicom_folder(exam_);
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), broken);
  }
}

TEST_F(DicomSeriesTest, FoldersWithoutDicomOrBeyondTheBoundsAreRefused) {
  const fs::path empty = scratch_ / "empty";
  test::write_file(empty / "notes.txt", "no images here");
  EXPECT_FALSE(folder_holds_dicom(empty));
  EXPECT_FALSE(folder_holds_dicom(scratch_ / "missing"));
  EXPECT_THAT([&] { (void)read_dicom_folder(empty); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("holds no DICOM file")));

  fs::path deep = scratch_ / "deep";
  for (int level = 0; level <= kDicomFolderMaxDepth; ++level) deep /= "d";
  test::write_file(deep / "IM0001.dcm", dx_bytes("AP", 4, 4000));
  EXPECT_THAT([&] { (void)read_dicom_folder(scratch_ / "deep"); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("folders deep")));
  EXPECT_FALSE(folder_holds_dicom(scratch_ / "deep")) << "the look is bounded too";

  const fs::path many = scratch_ / "many";
  for (std::size_t k = 0; k <= kDicomFolderMaxImages; ++k) {
    test::write_file(many / ("IM" + std::to_string(1000 + k) + ".dcm"),
                     dx_bytes("AP", static_cast<int>(100 + k), 100));
  }
  EXPECT_THAT([&] { (void)read_dicom_folder(many); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("more than 32 DICOM files")));
}

TEST_F(DicomSeriesTest, TheSeriesDocumentKeepsImagesAndNothingThatIdentifies) {
  const std::vector<DicomRadiograph> images = read_dicom_folder(exam_);
  const std::string text = deidentified_series_text(images);
  EXPECT_TRUE(is_deidentified_series(text));
  for (const char* identifying :
       {"ROE^RICHARD", "ROE_RICHARD", "PID-SERIES-1", "19500101", "20250102", "SERIES_1", "IM0001",
        "1.2.826.0.1.3680043.8.498.99.1"}) {
    EXPECT_EQ(text.find(identifying), std::string::npos) << identifying;
  }
  EXPECT_EQ(deidentified_series_from_text(text, "stored"), images);
}

TEST_F(DicomSeriesTest, AMalformedSeriesDocumentNamesTheField) {
  const std::string good = deidentified_series_text(read_dicom_folder(exam_));
  auto message = [](const std::string& text) {
    try {
      (void)deidentified_series_from_text(text, "stored.json");
    } catch (const IoError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("{"), HasSubstr("is not a de-identified series"));
  EXPECT_THAT(message("[]"), HasSubstr("must be a JSON object"));
  EXPECT_THAT(message(R"({"format":"mmm-deidentified-radiograph-series","images":[],"version":1})"),
              HasSubstr("field 'images' must be an array of 1 to 32"));
  EXPECT_THAT(
      message(R"({"format":"mmm-deidentified-radiograph-series","images":[{}],"version":2})"),
      HasSubstr("field 'version' must be 1"));
  EXPECT_THAT(message(R"({"format":"x","images":[{}],"version":1})"), HasSubstr("field 'format'"));
  EXPECT_THAT(
      message(
          R"({"format":"mmm-deidentified-radiograph-series","images":[{}],"version":1,"name":"x"})"),
      HasSubstr("unknown field 'name'"));
  EXPECT_THAT(
      message(R"({"format":"mmm-deidentified-radiograph-series","images":[{}],"version":1})"),
      HasSubstr("stored.json (image 1)"));
  std::string tampered = good;
  tampered.replace(tampered.find("\"rows\":6"), 8, "\"rows\":7");
  EXPECT_THAT(message(tampered), HasSubstr("(image 1)"));
  EXPECT_FALSE(is_deidentified_series(R"({"format":"mmm-deidentified-radiograph"})"));
}

}  // namespace
}  // namespace mmm::image
