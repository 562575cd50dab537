#include "core/image/dicom_radiograph.h"

#include <gdcmDataElement.h>
#include <gdcmImage.h>
#include <gdcmImageChangeTransferSyntax.h>
#include <gdcmImageReader.h>
#include <gdcmImageWriter.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
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

constexpr const char* kExplicitLittleEndian = "1.2.840.10008.1.2.1";
constexpr const char* kDxForPresentation = "1.2.840.10008.5.1.4.1.1.1.1";

DicomRadiograph read_fixture(const std::string& name) {
  return read_dicom_radiograph(fx::fixture(name));
}

// The expected 16-bit image: each modality value mapped as DicomValueMap says.
GrayImage16 expected_image(const std::function<double(int, int)>& value, const DicomValueMap& map) {
  GrayImage16 image(fx::kWidth, fx::kHeight);
  for (int y = 0; y < fx::kHeight; ++y) {
    for (int x = 0; x < fx::kWidth; ++x) {
      const double s = std::round((value(x, y) - map.value_min) * map.scale);
      image.at(x, y) = static_cast<std::uint16_t>(map.inverted ? 65535.0 - s : s);
    }
  }
  return image;
}

// The percentile window, computed by sorting (the reader uses a histogram).
DicomWindow sorted_percentile_window(const GrayImage16& image) {
  std::vector<std::uint16_t> sorted = image.pixels;
  std::sort(sorted.begin(), sorted.end());
  const auto last = static_cast<double>(sorted.size() - 1);
  const double low = sorted[static_cast<std::size_t>(std::floor(0.005 * last))];
  const double high = sorted[static_cast<std::size_t>(std::ceil(0.995 * last))];
  return {(low + high) / 2.0, high - low, DicomWindowSource::kPercentiles};
}

// Spacings: DS strings parse to the nearest double, so equality is exact;
// derived ones (divided by a magnification) get 1e-12 for the rounding.
void expect_spacing(const std::optional<PixelSpacingMm>& got, double row, double column) {
  ASSERT_TRUE(got.has_value());
  EXPECT_NEAR((*got)[0], row, 1e-12);
  EXPECT_NEAR((*got)[1], column, 1e-12);
}

// --- well-formed fixtures ---

TEST(DicomRadiographTest, LooksLikeDicom) {
  EXPECT_TRUE(looks_like_dicom(test::read_text(fx::fixture("dx_mono2_16bit.dcm"))));
  EXPECT_TRUE(looks_like_dicom(test::read_text(fx::fixture("implicit_no_preamble.dcm"))));
  EXPECT_FALSE(looks_like_dicom(test::read_text(fx::fixture("not_dicom.txt"))));
  EXPECT_FALSE(looks_like_dicom(""));
  EXPECT_FALSE(looks_like_dicom(std::string("\x08\x00", 2)));  // too short for an element
}

TEST(DicomRadiographTest, Dx16BitMonochrome2KeepsValuesAndGeometry) {
  const DicomRadiograph r = read_fixture("dx_mono2_16bit.dcm");
  EXPECT_EQ(r.image.width, fx::kWidth);
  EXPECT_EQ(r.image.height, fx::kHeight);
  EXPECT_EQ(r.columns, fx::kWidth);
  EXPECT_EQ(r.rows, fx::kHeight);
  EXPECT_EQ(r.modality, "DX");
  EXPECT_EQ(r.sop_class_uid, kDxForPresentation);
  EXPECT_EQ(r.transfer_syntax_uid, kExplicitLittleEndian);
  EXPECT_EQ(r.photometric_interpretation, "MONOCHROME2");
  EXPECT_EQ(r.bits_stored, 16);
  EXPECT_FALSE(r.pixel_signed);
  EXPECT_EQ(r.sop_instance_uid_sha256, hash::sha256_hex(fx::sop_instance_uid(1)));
  // The values span 0..65535, so the map is the identity and every sample
  // is the stored value.
  EXPECT_EQ(r.value_map, (DicomValueMap{0.0, 1.0, false}));
  for (int y = 0; y < fx::kHeight; ++y) {
    for (int x = 0; x < fx::kWidth; ++x) {
      ASSERT_EQ(r.image.at(x, y), fx::dx16_value(x, y)) << "pixel " << x << ", " << y;
    }
  }
  EXPECT_EQ(r.window, (DicomWindow{30000.0, 40000.0, DicomWindowSource::kFile}));
  expect_spacing(r.imager_pixel_spacing, 0.15, 0.125);
  EXPECT_FALSE(r.pixel_spacing.has_value());
  EXPECT_EQ(r.magnification_factor, 1.25);
  EXPECT_EQ(r.distance_source_to_detector_mm, 1500.0);
  EXPECT_EQ(r.distance_source_to_patient_mm, 1200.0);
  EXPECT_EQ(r.view_position, "AP");
  EXPECT_EQ(r.patient_orientation, (std::array<std::string, 2>{"L", "F"}));
  EXPECT_EQ(r.image_laterality, "U");
  EXPECT_FALSE(r.pixel_spacing_calibration_type.has_value());
}

TEST(DicomRadiographTest, RleLosslessDecodesToTheSameImage) {
  const DicomRadiograph native = read_fixture("dx_mono2_16bit.dcm");
  const DicomRadiograph rle = read_fixture("dx_rle.dcm");
  EXPECT_EQ(rle.transfer_syntax_uid, "1.2.840.10008.1.2.5");
  EXPECT_EQ(rle.image.pixels, native.image.pixels);
  EXPECT_EQ(rle.window, native.window);
  EXPECT_EQ(rle.value_map, native.value_map);
  EXPECT_EQ(rle.sop_instance_uid_sha256, hash::sha256_hex(fx::sop_instance_uid(2)));
}

TEST(DicomRadiographTest, CrMonochrome1IsInverted) {
  const DicomRadiograph r = read_fixture("cr_mono1_12bit.dcm");
  EXPECT_EQ(r.modality, "CR");
  EXPECT_EQ(r.photometric_interpretation, "MONOCHROME1");
  EXPECT_EQ(r.bits_stored, 12);
  EXPECT_EQ(r.value_map, (DicomValueMap{0.0, 65535.0 / 4095.0, true}));
  // MONOCHROME1: the lowest stored value is the brightest.
  EXPECT_EQ(r.image.at(0, 0), 65535);
  EXPECT_EQ(r.image.at(fx::kWidth - 1, fx::kHeight - 1), 0);
  EXPECT_EQ(r.image.pixels, expected_image(fx::cr12_value, r.value_map).pixels);
  // 12 bits onto 16: every stored value keeps its own sample (exact map).
  for (int v = 0; v < 4095; ++v) {
    const double s0 = std::round(v * r.value_map.scale);
    const double s1 = std::round((v + 1) * r.value_map.scale);
    ASSERT_LT(s0, s1);
  }
  EXPECT_EQ(r.window, sorted_percentile_window(r.image));
  expect_spacing(r.imager_pixel_spacing, 0.1, 0.1);
  expect_spacing(r.pixel_spacing, 0.1, 0.1);
  EXPECT_EQ(r.view_position, "LL");
  EXPECT_EQ(r.patient_orientation, (std::array<std::string, 2>{"A", "F"}));
  EXPECT_FALSE(r.image_laterality.has_value());
}

TEST(DicomRadiographTest, SecondaryCapture8Bit) {
  const DicomRadiograph r = read_fixture("sc_8bit.dcm");
  EXPECT_EQ(r.modality, "OT");
  EXPECT_EQ(r.sop_class_uid, "1.2.840.10008.5.1.4.1.1.7");
  EXPECT_EQ(r.bits_stored, 8);
  const double max = fx::sc8_value(fx::kWidth - 1, fx::kHeight - 1);  // 236
  EXPECT_EQ(r.value_map, (DicomValueMap{0.0, 65535.0 / max, false}));
  EXPECT_EQ(r.image.pixels, expected_image(fx::sc8_value, r.value_map).pixels);
  EXPECT_EQ(r.window, sorted_percentile_window(r.image));
  expect_spacing(r.pixel_spacing, 0.5, 0.5);
  EXPECT_FALSE(r.imager_pixel_spacing.has_value());
}

TEST(DicomRadiographTest, RescaleAndFirstOfSeveralWindows) {
  const DicomRadiograph r = read_fixture("dx_rescale_windows.dcm");
  EXPECT_TRUE(r.pixel_signed);
  EXPECT_EQ(r.rescale_slope, 0.5);
  EXPECT_EQ(r.rescale_intercept, -100.0);
  // Stored -1000..3250 -> values -600..1525.
  const double scale = 65535.0 / 2125.0;
  EXPECT_EQ(r.value_map, (DicomValueMap{-600.0, scale, false}));
  const auto value = [](int x, int y) { return fx::signed_value(x, y) * 0.5 - 100.0; };
  EXPECT_EQ(r.image.pixels, expected_image(value, r.value_map).pixels);
  // Window 500 / 1000 in modality units (the first of 500\800 and 1000\2000).
  EXPECT_EQ(r.window.source, DicomWindowSource::kFile);
  EXPECT_DOUBLE_EQ(r.window.centre, (500.0 + 600.0) * scale);
  EXPECT_DOUBLE_EQ(r.window.width, 1000.0 * scale);
  EXPECT_EQ(r.pixel_spacing_calibration_type, "GEOMETRY");
  EXPECT_EQ(r.view_position, "PA");
  EXPECT_EQ(r.patient_orientation, (std::array<std::string, 2>{"R", "F"}));
}

TEST(DicomRadiographTest, ImplicitVrWithoutPreamble) {
  const DicomRadiograph r = read_fixture("implicit_no_preamble.dcm");
  EXPECT_EQ(r.transfer_syntax_uid, "1.2.840.10008.1.2");
  EXPECT_EQ(r.modality, "CR");
  EXPECT_EQ(r.bits_stored, 10);
  const double max = fx::implicit_value(fx::kWidth - 1, fx::kHeight - 1);
  EXPECT_EQ(r.value_map, (DicomValueMap{0.0, 65535.0 / max, false}));
  EXPECT_EQ(r.image.pixels, expected_image(fx::implicit_value, r.value_map).pixels);
  EXPECT_EQ(r.sop_instance_uid_sha256, hash::sha256_hex(fx::sop_instance_uid(6)));
  EXPECT_FALSE(r.imager_pixel_spacing.has_value());
  EXPECT_FALSE(r.pixel_spacing.has_value());
}

TEST(DicomRadiographTest, BytesAndPathReadTheSame) {
  const auto path = fx::fixture("cr_mono1_12bit.dcm");
  EXPECT_EQ(read_dicom_radiograph(test::read_text(path), path), read_dicom_radiograph(path));
}

// --- spacing ---

TEST(DicomSpacingTest, ImagerPixelSpacingOnlyIsTheDetectorPlane) {
  const RadiographSpacing s = radiograph_spacing(read_fixture("dx_mono2_16bit.dcm"));
  EXPECT_EQ(s.meaning, SpacingMeaning::kDetector);
  expect_spacing(s.detector_mm, 0.15, 0.125);
  // Divided by the Estimated Radiographic Magnification Factor 1.25.
  expect_spacing(s.patient_mm, 0.12, 0.1);
  EXPECT_EQ(s.magnification, 1.25);
  EXPECT_THAT(s.explanation, HasSubstr("Imager Pixel Spacing (0018,1164)"));
}

TEST(DicomSpacingTest, PixelSpacingEqualToImagerIsNotCalibrated) {
  const RadiographSpacing s = radiograph_spacing(read_fixture("cr_mono1_12bit.dcm"));
  EXPECT_EQ(s.meaning, SpacingMeaning::kDetector);
  expect_spacing(s.detector_mm, 0.1, 0.1);
  EXPECT_FALSE(s.patient_mm.has_value());  // no magnification, no distances
  EXPECT_FALSE(s.magnification.has_value());
  EXPECT_THAT(s.explanation, HasSubstr("not calibrated"));
}

TEST(DicomSpacingTest, CalibratedPixelSpacingIsThePatientPlane) {
  const RadiographSpacing s = radiograph_spacing(read_fixture("dx_rescale_windows.dcm"));
  EXPECT_EQ(s.meaning, SpacingMeaning::kCalibratedToPatient);
  expect_spacing(s.detector_mm, 0.2, 0.2);
  expect_spacing(s.patient_mm, 0.16, 0.16);
  EXPECT_EQ(s.magnification, 1.25);
  EXPECT_THAT(s.explanation, HasSubstr("GEOMETRY"));
}

TEST(DicomSpacingTest, PixelSpacingAloneHasNoKnownPlane) {
  const RadiographSpacing s = radiograph_spacing(read_fixture("sc_8bit.dcm"));
  EXPECT_EQ(s.meaning, SpacingMeaning::kUnknownPlane);
  EXPECT_FALSE(s.detector_mm.has_value());
  EXPECT_FALSE(s.patient_mm.has_value());
}

TEST(DicomSpacingTest, MagnificationFromSourceDistances) {
  DicomRadiograph r;
  r.imager_pixel_spacing = PixelSpacingMm{0.3, 0.3};
  r.distance_source_to_detector_mm = 1500.0;
  r.distance_source_to_patient_mm = 1000.0;
  const RadiographSpacing s = radiograph_spacing(r);
  EXPECT_EQ(s.meaning, SpacingMeaning::kDetector);
  EXPECT_DOUBLE_EQ(*s.magnification, 1.5);
  expect_spacing(s.patient_mm, 0.2, 0.2);
  EXPECT_EQ(radiograph_spacing(DicomRadiograph{}).meaning, SpacingMeaning::kNone);
}

// --- malformed files: each refused, naming the file and the attribute ---

void expect_refused(const std::string& name, const std::vector<std::string>& fragments) {
  const auto path = fx::fixture(name);
  try {
    (void)read_dicom_radiograph(path);
    ADD_FAILURE() << name << " was accepted";
  } catch (const IoError& error) {
    const std::string message = error.what();
    EXPECT_THAT(message, HasSubstr(name));
    for (const std::string& fragment : fragments) EXPECT_THAT(message, HasSubstr(fragment));
  }
}

TEST(DicomRadiographTest, MalformedFilesAreRefused) {
  expect_refused("truncated.dcm", {"truncated", "Pixel Data (7FE0,0010)"});
  expect_refused("no_pixel_data.dcm", {"Pixel Data (7FE0,0010)", "missing"});
  expect_refused("bogus_transfer_syntax.dcm",
                 {"Transfer Syntax UID (0002,0010)", "1.2.3.4.5.6.7.8.9", "gdcmconv"});
  expect_refused("not_dicom.txt", {"not a DICOM file"});
  expect_refused("rgb.dcm", {"Samples per Pixel (0028,0002) is 3", "'RGB'", "grayscale"});
  expect_refused("zero_rows.dcm", {"Rows (0028,0010) is 0"});
  expect_refused("too_many_rows.dcm", {"Rows (0028,0010) is 20001", "20000"});
  expect_refused("bad_spacing_text.dcm", {"Imager Pixel Spacing (0018,1164)", "'abc'"});
  expect_refused("bad_spacing_zero.dcm", {"Imager Pixel Spacing (0018,1164)", "> 0"});
}

TEST(DicomRadiographTest, EveryTruncationIsRefused) {
  const std::string whole = test::read_text(fx::fixture("dx_mono2_16bit.dcm"));
  // Every cut inside the header, and a cut every few bytes of the pixels.
  for (std::size_t size = 0; size < whole.size(); size += size < 1200 ? 1 : 61) {
    EXPECT_THROW((void)read_dicom_radiograph(std::string_view(whole).substr(0, size), "cut.dcm"),
                 IoError)
        << "cut at " << size << " of " << whole.size() << " bytes";
  }
}

// Sequences nested 40 deep (implicit VR, undefined lengths): refused by the
// structure check before GDCM, which recurses once per level, sees them.
TEST(DicomRadiographTest, DeeplyNestedSequencesAreRefused) {
  std::string bytes;
  for (int level = 0; level < 40; ++level) {
    bytes += std::string("\x08\x00\x40\x11\xff\xff\xff\xff", 8);  // (0008,1140) SQ
    bytes += std::string("\xfe\xff\x00\xe0\xff\xff\xff\xff", 8);  // item
  }
  try {
    (void)read_dicom_radiograph(bytes, "nested.dcm");
    ADD_FAILURE() << "accepted";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("nested.dcm"), HasSubstr("nest deeper")));
  }
}

TEST(DicomRadiographTest, FileAboveTheLimitIsRefusedBeforeReading) {
  const test::ScratchDir dir("dicom");
  const auto path = dir / "huge.dcm";
  test::write_file(path, "x");
  std::filesystem::resize_file(path, kDicomMaxFileBytes + 1);  // sparse: no disk used
  try {
    (void)read_dicom_radiograph(path);
    ADD_FAILURE() << "accepted";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("huge.dcm"), HasSubstr("512")));
  }
  EXPECT_THROW((void)read_dicom_radiograph(dir / "missing.dcm"), IoError);
}

// --- files written by GDCM itself ---

struct GdcmImageSpec {
  int width = 37;  // odd sizes: no row-alignment luck
  int height = 23;
  std::string sop_class = kDxForPresentation;
  double row_spacing = 0.25;
  double column_spacing = 0.125;
};

std::vector<std::uint16_t> gdcm_test_pixels(const GdcmImageSpec& spec) {
  std::vector<std::uint16_t> pixels(static_cast<std::size_t>(spec.width * spec.height));
  for (int y = 0; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x) {
      // Full 0..65535 range (identity map) with structure in every bit.
      pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(spec.width) +
             static_cast<std::size_t>(x)] =
          static_cast<std::uint16_t>((x * 1777 + y * 4099) % 65536);
    }
  }
  pixels.front() = 0;
  pixels.back() = 65535;
  return pixels;
}

void put_string(gdcm::DataSet& data_set, std::uint16_t group, std::uint16_t element, gdcm::VR vr,
                std::string value) {
  if (value.size() % 2 != 0) value.push_back(vr == gdcm::VR::UI ? '\0' : ' ');
  gdcm::DataElement item(gdcm::Tag(group, element));
  item.SetVR(vr);
  item.SetByteValue(value.data(), static_cast<std::uint32_t>(value.size()));
  data_set.Replace(item);
}

// A 16-bit MONOCHROME2 image written by gdcm::ImageWriter, optionally
// transcoded by gdcm::ImageChangeTransferSyntax.
std::string write_with_gdcm(
    const GdcmImageSpec& spec,
    const gdcm::TransferSyntax& syntax = gdcm::TransferSyntax::ExplicitVRLittleEndian) {
  gdcm::ImageWriter writer;
  gdcm::Image& image = writer.GetImage();
  image.SetNumberOfDimensions(2);
  image.SetDimension(0, static_cast<unsigned int>(spec.width));
  image.SetDimension(1, static_cast<unsigned int>(spec.height));
  image.SetPixelFormat(gdcm::PixelFormat::UINT16);
  image.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
  image.SetTransferSyntax(gdcm::TransferSyntax::ExplicitVRLittleEndian);
  const std::vector<std::uint16_t> pixels = gdcm_test_pixels(spec);
  gdcm::DataElement pixel_data(gdcm::Tag(0x7FE0, 0x0010));
  pixel_data.SetVR(gdcm::VR::OW);
  pixel_data.SetByteValue(reinterpret_cast<const char*>(pixels.data()),
                          static_cast<std::uint32_t>(pixels.size() * 2));
  image.SetDataElement(pixel_data);

  gdcm::DataSet& data_set = writer.GetFile().GetDataSet();
  put_string(data_set, 0x0008, 0x0016, gdcm::VR::UI, spec.sop_class);
  put_string(data_set, 0x0008, 0x0018, gdcm::VR::UI, "1.2.826.0.1.3680043.8.498.7731.99");
  put_string(data_set, 0x0008, 0x0060, gdcm::VR::CS, "DX");
  // GDCM writes the image's spacing (x = column spacing first) into Imager
  // Pixel Spacing (row\\column) for a DX image, replacing what is set here.
  image.SetSpacing(0, spec.column_spacing);
  image.SetSpacing(1, spec.row_spacing);

  if (syntax != gdcm::TransferSyntax::ExplicitVRLittleEndian) {
    gdcm::ImageChangeTransferSyntax change;
    change.SetTransferSyntax(syntax);
    change.SetInput(image);
    if (!change.Change()) {
      ADD_FAILURE() << "GDCM could not encode " << syntax;
      return {};
    }
    writer.SetImage(change.GetOutput());
  }
  std::ostringstream out;
  writer.SetStream(out);
  if (!writer.Write()) ADD_FAILURE() << "gdcm::ImageWriter failed";
  return out.str();
}

TEST(DicomGdcmWriteTest, RoundTripKeepsPixelsAndSpacing) {
  const GdcmImageSpec spec;
  const DicomRadiograph r = read_dicom_radiograph(write_with_gdcm(spec), "gdcm.dcm");
  EXPECT_EQ(r.image.width, spec.width);
  EXPECT_EQ(r.image.height, spec.height);
  EXPECT_EQ(r.value_map, (DicomValueMap{0.0, 1.0, false}));
  EXPECT_EQ(r.image.pixels, gdcm_test_pixels(spec));
  expect_spacing(r.imager_pixel_spacing, 0.25, 0.125);
  EXPECT_EQ(r.sop_instance_uid_sha256, hash::sha256_hex("1.2.826.0.1.3680043.8.498.7731.99"));
}

// Lossless codecs of the Debian build (CharLS for JPEG-LS, OpenJPEG for JPEG
// 2000): decoded back, the pixels are exactly the ones encoded.
TEST(DicomGdcmWriteTest, JpegLsLosslessIsExact) {
  const GdcmImageSpec spec;
  const std::string bytes = write_with_gdcm(spec, gdcm::TransferSyntax::JPEGLSLossless);
  const DicomRadiograph r = read_dicom_radiograph(bytes, "jpegls.dcm");
  EXPECT_EQ(r.transfer_syntax_uid, "1.2.840.10008.1.2.4.80");
  EXPECT_EQ(r.image.pixels, gdcm_test_pixels(spec));
}

TEST(DicomGdcmWriteTest, Jpeg2000LosslessIsExact) {
  const GdcmImageSpec spec;
  const std::string bytes = write_with_gdcm(spec, gdcm::TransferSyntax::JPEG2000Lossless);
  const DicomRadiograph r = read_dicom_radiograph(bytes, "j2k.dcm");
  EXPECT_EQ(r.transfer_syntax_uid, "1.2.840.10008.1.2.4.90");
  EXPECT_EQ(r.image.pixels, gdcm_test_pixels(spec));
}

TEST(DicomGdcmWriteTest, OtherSopClassesAreRefused) {
  GdcmImageSpec spec;
  spec.sop_class = "1.2.840.10008.5.1.4.1.1.2";  // CT Image Storage
  try {
    (void)read_dicom_radiograph(write_with_gdcm(spec), "ct.dcm");
    ADD_FAILURE() << "accepted";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("ct.dcm"), HasSubstr("SOP Class UID (0008,0016)"),
                                    HasSubstr("CT Image Storage")));
  }
}

// Imager Pixel Spacing "0.15\\0.125" of the DX fixture replaced by another
// value of the same length: each one refused, naming the attribute.
TEST(DicomRadiographTest, SpacingIsParsedStrictly) {
  const std::string original = test::read_text(fx::fixture("dx_mono2_16bit.dcm"));
  const std::string spacing = "0.15\\0.125";
  ASSERT_EQ(original.find(spacing), original.rfind(spacing));
  for (const std::string bad :
       {"0.15\\inf  ", "0.15      ", "-0.15\\0.12", "0.15\\1e999", "0.15\\0x1p2", "0.15\\ \\ 1 "}) {
    ASSERT_EQ(bad.size(), spacing.size());
    std::string bytes = original;
    bytes.replace(bytes.find(spacing), spacing.size(), bad);
    try {
      (void)read_dicom_radiograph(bytes, "patched.dcm");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const IoError& error) {
      EXPECT_THAT(error.what(),
                  AllOf(HasSubstr("patched.dcm"), HasSubstr("Imager Pixel Spacing (0018,1164)")))
          << bad;
    }
  }
}

}  // namespace
}  // namespace mmm::image

namespace mmm::image {
namespace {

// Found by the fuzzer: Columns (0028,0011) with VR SS instead of US makes
// Debian's GDCM fail an assertion, which used to abort the whole process.
// The trial decoding in a child process turns that into an error.
TEST(DicomRadiographTest, AFileThatMakesGdcmAbortIsRefusedAndThisProcessLives) {
  const std::filesystem::path file =
      test::source_dir() / "fuzz" / "regressions" / "dicom" / "columns_with_vr_ss.dcm";
  try {
    (void)read_dicom_radiograph(file);
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), file);
    EXPECT_THAT(error.what(), ::testing::HasSubstr("could not be decoded: the DICOM library "
                                                   "crashed (SIGABRT"));
    EXPECT_THAT(error.what(), ::testing::HasSubstr("hint: export the image again"));
  }
  // And a good file still reads, in this process, after that.
  EXPECT_EQ(read_dicom_radiograph(test::dicom::fixture("dx_mono2_16bit.dcm")).columns,
            test::dicom::kWidth);
}

}  // namespace
}  // namespace mmm::image
