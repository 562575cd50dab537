#pragma once
// A structural check of a DICOM file's bytes before GDCM parses them: every
// element's value must lie inside the file and inside its sequence or item,
// every undefined-length sequence, item and encapsulated Pixel Data must be
// closed, and sequences may not nest deeper than kDicomMaxNesting.
//
// Why: Debian's GDCM is built with assert() enabled, and its reader asserts
// (aborting the whole process) on many truncated files, e.g. one cut inside
// the file meta information (Reader::InternalReadCommon seeks a failed
// stream, then asserts it is good). It also recurses once per nested
// sequence. So a file reaches GDCM only once this walk, which never recurses
// and reads nothing beyond the bytes it is given, has found it whole.
//
//   offset = 132 (after preamble + "DICM") or 0 (bare data set)
//   group 0002 elements: explicit VR little endian; (0002,0010) gives the
//   encoding of the rest: implicit/explicit VR, little/big endian
//   loop: tag; (FFFE,E000/E00D/E0DD) item / delimiters: 4-byte length;
//         else VR (explicit) and a 2- or 4-byte length;
//         SQ and items are entered (a stack of their ends), other values
//         skipped; undefined lengths push a frame closed by a delimiter.
// This is a walk over the structure only: a file that passes may still be
// refused by GDCM, or by read_dicom_radiograph, for what it holds. Not
// handled: an explicit-VR UN element of undefined length (CP-246) is walked as
// if its content were explicit VR and may be refused as corrupt.

#include <cstddef>
#include <filesystem>
#include <string_view>

namespace mmm::image::detail {

inline constexpr std::size_t kDicomMaxNesting = 16;

// Throws IoError naming `source` and the element (tag) at fault: truncated
// ("the element (7FE0,0010) Pixel Data claims 6144 bytes, 2048 remain"), an
// element overrunning its sequence or item, an unknown explicit VR, an
// unclosed sequence or item, nesting deeper than kDicomMaxNesting, a
// Transfer Syntax UID (0002,0010) GDCM does not know (the UID named), or the
// deflated transfer syntax (its bytes cannot be walked without inflating).
void check_dicom_structure(std::string_view bytes, const std::filesystem::path& source);

}  // namespace mmm::image::detail
