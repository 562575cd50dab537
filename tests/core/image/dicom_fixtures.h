#pragma once
// The synthetic DICOM radiographs written by
// tests/fixtures/dicom/make_dicom_fixtures.py (into <build>/fixtures/dicom
// when mmm_core_tests is built), and the pixel formulas they hold: the
// formulas are repeated here from the script, so that a test compares what
// the reader returns with values computed independently of it.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "tests/support/test_data.h"

namespace mmm::test::dicom {

inline constexpr int kWidth = 64;
inline constexpr int kHeight = 48;

// The folder of the fixtures; fails the test (never skips) when missing.
inline std::filesystem::path fixture(const std::string& name) {
  const std::filesystem::path dir = binary_dir() / "fixtures" / "dicom";
  std::filesystem::path path = dir / name;
  if (!std::filesystem::exists(path)) {
    ADD_FAILURE() << path << " is missing: build the mmm_dicom_fixtures target (part of "
                  << "mmm_core_tests; it needs python3-pydicom)";
  }
  return path;
}

// SOP Instance UIDs of the well-formed fixtures (SOP_INSTANCE_UIDS).
inline std::string sop_instance_uid(int number) {
  return "1.2.826.0.1.3680043.8.498.7731." + std::to_string(number);
}

// Attribute values that identify someone, present in every well-formed
// fixture, which a de-identified copy must not contain.
inline const std::array<std::string, 12> kIdentifyingStrings = {
    "DOE^JANE^FIXTURE", "PID-7731-FIXTURE", "19450317",         "20240229",
    "FIXTURE GENERAL",  "1 FIXTURE ROAD",   "REFERRER^FIXTURE", "OPERATOR^FIXTURE",
    "ACC-7731-FIXTURE", "SN-7731-FIXTURE",  "ST-7731-FIXTURE",  "FIXTURE"};

inline int dx16_value(int x, int y) {
  if (x == 0 && y == 0) return 0;
  if (x == kWidth - 1 && y == kHeight - 1) return 65535;
  int value = 1000 + 500 * x + 100 * y;
  if ((x - 40) * (x - 40) + (y - 20) * (y - 20) <= 100) value += 20000;
  return value;
}
inline int cr12_value(int x, int y) {
  return x == kWidth - 1 && y == kHeight - 1 ? 4095 : 40 * x + 30 * y;
}
inline int sc8_value(int x, int y) { return 3 * x + y; }
inline int signed_value(int x, int y) { return -1000 + 60 * x + 10 * y; }
inline int implicit_value(int x, int y) { return 10 * x + 5 * y; }

}  // namespace mmm::test::dicom
