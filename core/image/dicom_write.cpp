#include "core/image/dicom_write.h"

#include <gdcmDataElement.h>
#include <gdcmImage.h>
#include <gdcmImageWriter.h>

#include <algorithm>
#include <cctype>
#include <sstream>
#include <vector>

#include "core/errors.h"

namespace mmm::image {
namespace {

// DICOM values have even lengths: strings are padded with a space, UIDs with
// a NUL (PS3.5 6.2).
void put(gdcm::DataSet& data_set, std::uint16_t group, std::uint16_t element, gdcm::VR vr,
         std::string value) {
  if (value.size() % 2 != 0) value.push_back(vr == gdcm::VR::UI ? '\0' : ' ');
  gdcm::DataElement item(gdcm::Tag(group, element));
  item.SetVR(vr);
  item.SetByteValue(value.data(), static_cast<std::uint32_t>(value.size()));
  data_set.Replace(item);
}

std::string decimal(double value) {
  std::ostringstream text;
  text.precision(10);
  text << value;
  return text.str();
}

}  // namespace

std::string dicom_radiograph_bytes(const GrayImage16& image, const DicomExport& options) {
  if (image.empty()) throw InvalidInputError("dicom_radiograph_bytes: the image is empty");
  for (const double value : {options.row_pitch_mm, options.column_pitch_mm,
                             options.source_to_detector_mm, options.source_to_patient_mm}) {
    if (!(value > 0)) {
      throw InvalidInputError("dicom_radiograph_bytes: pitches and distances must be > 0");
    }
  }
  const std::string& uid = options.sop_instance_uid;
  if (uid.empty() || uid.size() > 64 ||
      !std::ranges::all_of(uid, [](char c) { return c == '.' || std::isdigit(c) != 0; })) {
    throw InvalidInputError("dicom_radiograph_bytes: the SOP Instance UID '" + uid +
                            "' must be digits and dots, at most 64 characters");
  }
  gdcm::ImageWriter writer;
  gdcm::Image& out = writer.GetImage();
  out.SetNumberOfDimensions(2);
  out.SetDimension(0, static_cast<unsigned int>(image.width));
  out.SetDimension(1, static_cast<unsigned int>(image.height));
  out.SetPixelFormat(gdcm::PixelFormat::UINT16);
  out.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
  out.SetTransferSyntax(gdcm::TransferSyntax::ExplicitVRLittleEndian);
  // Little-endian 16-bit samples, row by row.
  std::string samples(image.pixels.size() * 2, '\0');
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    samples[2 * i] = static_cast<char>(image.pixels[i] & 0xFFU);
    samples[2 * i + 1] = static_cast<char>(image.pixels[i] >> 8U);
  }
  gdcm::DataElement pixel_data(gdcm::Tag(0x7FE0, 0x0010));
  pixel_data.SetVR(gdcm::VR::OW);
  pixel_data.SetByteValue(samples.data(), static_cast<std::uint32_t>(samples.size()));
  out.SetDataElement(pixel_data);
  // GDCM writes the spacing (column first) as Imager Pixel Spacing of a DX.
  out.SetSpacing(0, options.column_pitch_mm);
  out.SetSpacing(1, options.row_pitch_mm);

  gdcm::DataSet& data_set = writer.GetFile().GetDataSet();
  put(data_set, 0x0008, 0x0016, gdcm::VR::UI, "1.2.840.10008.5.1.4.1.1.1.1");  // DX presentation
  put(data_set, 0x0008, 0x0018, gdcm::VR::UI, uid);
  put(data_set, 0x0008, 0x0020, gdcm::VR::DA, options.study_date);
  put(data_set, 0x0008, 0x0060, gdcm::VR::CS, "DX");
  put(data_set, 0x0010, 0x0010, gdcm::VR::PN, options.patient_name);
  put(data_set, 0x0010, 0x0020, gdcm::VR::LO, options.patient_id);
  put(data_set, 0x0010, 0x0030, gdcm::VR::DA, options.patient_birth_date);
  put(data_set, 0x0018, 0x1110, gdcm::VR::DS, decimal(options.source_to_detector_mm));
  put(data_set, 0x0018, 0x1111, gdcm::VR::DS, decimal(options.source_to_patient_mm));
  put(data_set, 0x0018, 0x5101, gdcm::VR::CS, options.view_position);
  put(data_set, 0x0020, 0x0020, gdcm::VR::CS,
      options.patient_orientation[0] + "\\" + options.patient_orientation[1]);
  put(data_set, 0x0028, 0x1050, gdcm::VR::DS, decimal(options.window_centre));
  put(data_set, 0x0028, 0x1051, gdcm::VR::DS, decimal(options.window_width));
  std::ostringstream bytes;
  writer.SetStream(bytes);
  if (!writer.Write()) {
    throw IoError("(DICOM in memory)", "GDCM could not write the radiograph");
  }
  return bytes.str();
}

}  // namespace mmm::image
