// A radiograph written as DICOM (dicom_write.h) reads back with its samples,
// window and geometry, and views_from_dicom makes of it the system's views.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_views.h"
#include "core/image/dicom_write.h"
#include "core/image/projection.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

DicomExport export_of(const std::string& position, std::array<std::string, 2> orientation) {
  DicomExport e;
  e.view_position = position;
  e.patient_orientation = std::move(orientation);
  e.row_pitch_mm = 2.0;
  e.column_pitch_mm = 2.0;
  e.patient_name = "NOBODY^TEST";
  e.patient_id = "T-1";
  e.patient_birth_date = "19700101";
  e.study_date = "20260101";
  e.sop_instance_uid = "2.25.12345";
  e.window_centre = 21000;
  e.window_width = 9000;
  return e;
}

TEST(DicomViewsTest, WrittenRadiographsCalibrateToTheSystemsViews) {
  for (const auto model : {ProjectionModel::kPinhole, ProjectionModel::kSlotScanning}) {
    BiplanarOptions options;
    options.model = model;
    options.detector_pixel_pitch_mm = 2.0;
    options.field_width_mm = 300;
    options.field_height_mm = 800;
    const auto views = make_biplanar_views(options);
    std::array<DicomRadiograph, 2> read;
    for (std::size_t k = 0; k < 2; ++k) {
      GrayImage16 image(views[k].width, views[k].height);
      std::mt19937 rng(static_cast<unsigned>(k + 1));
      // Not the full range: unsigned 16-bit samples are kept as they are.
      for (std::uint16_t& sample : image.pixels) {
        sample = static_cast<std::uint16_t>(1000 + rng() % 50000);
      }
      DicomExport e = k == 0 ? export_of("AP", {"L", "F"}) : export_of("LL", {"A", "F"});
      e.sop_instance_uid += std::to_string(k);
      const std::string bytes = dicom_radiograph_bytes(image, e);
      read[k] = read_dicom_radiograph(bytes, "written.dcm");
      EXPECT_EQ(read[k].image.pixels, image.pixels);
      EXPECT_EQ(read[k].window.centre, 21000);
      EXPECT_EQ(read[k].window.width, 9000);
    }
    const DicomPairGeometry geometry =
        views_from_dicom({read.data(), "frontal.dcm"}, {read.data() + 1, "lateral.dcm"}, model);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t k = 0; k < 2; ++k) {
      EXPECT_FALSE(geometry.mirrored[k]);
      for (int i = 0; i < 20; ++i) {
        const Eigen::Vector3d X(100 * unit(rng), 100 * unit(rng), 350 * unit(rng));
        EXPECT_LT((project(geometry.views[k], X) - project(views[k], X)).norm(), 1e-6);
      }
    }
  }
}

TEST(DicomViewsTest, AMalformedUidIsRefused) {
  DicomExport e = export_of("AP", {"L", "F"});
  e.sop_instance_uid = "DOE^JOHN";
  EXPECT_THAT([&] { dicom_radiograph_bytes(GrayImage16(4, 4), e); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("digits and dots")));
}

}  // namespace
}  // namespace mmm::image
