// The structural walk of dicom_structure.h: a loop over element headers with
// an explicit stack of open sequences and items, never a recursion.

#include "core/image/dicom_structure.h"

#include <gdcmTransferSyntax.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::image::detail {

namespace fs = std::filesystem;

namespace {

constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFFU;
constexpr std::size_t kNoEnd = static_cast<std::size_t>(-1);

enum class FrameKind { kSequence, kItem, kFragments };

struct Frame {
  FrameKind kind;
  std::size_t end;  // kNoEnd: undefined length, closed by a delimiter
};

std::string tag_text(std::uint16_t group, std::uint16_t element) {
  constexpr std::string_view kDigits = "0123456789ABCDEF";
  std::string out = "(gggg,eeee)";
  for (int i = 0; i < 4; ++i) {
    const auto shift = static_cast<unsigned>(12 - 4 * i);
    const auto at = static_cast<std::size_t>(i);
    out[1 + at] = kDigits[(group >> shift) & 0xFU];
    out[6 + at] = kDigits[(element >> shift) & 0xFU];
  }
  if (group == 0x7FE0 && element == 0x0010) return "Pixel Data " + out;
  return "the element " + out;
}

// The value representations of PS3.5 6.2; the first group have a 4-byte
// length after two reserved bytes in explicit VR (PS3.5 7.1.2).
constexpr std::array<std::string_view, 13> kLongVrs = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                       "SV", "UC", "UN", "UR", "UT", "UV"};
constexpr std::array<std::string_view, 21> kShortVrs = {"AE", "AS", "AT", "CS", "DA", "DS", "DT",
                                                        "FL", "FD", "IS", "LO", "LT", "PN", "SH",
                                                        "SL", "SS", "ST", "TM", "UI", "UL", "US"};

bool contains(const auto& list, std::string_view vr) {
  return std::ranges::any_of(list, [vr](std::string_view item) { return item == vr; });
}

class Walker {
 public:
  Walker(std::string_view bytes, const fs::path& source) : bytes_(bytes), source_(source) {}

  void run() {
    if (bytes_.size() >= 132 && bytes_.substr(128, 4) == "DICM") offset_ = 132;
    walk_meta();
    walk_data_set();
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const { throw IoError(source_, problem); }

  [[noreturn]] void truncated(const std::string& what, std::size_t need) const {
    fail("is truncated: " + what + " needs " + std::to_string(need) + " bytes at offset " +
         std::to_string(offset_) + ", " + std::to_string(bytes_.size() - offset_) +
         " remain (the copy was cut short; fetch the file again)");
  }

  void need(std::size_t count, const std::string& what) const {
    if (bytes_.size() - offset_ < count) truncated(what, count);
  }

  [[nodiscard]] std::uint16_t u16(std::size_t at) const {
    const auto a = static_cast<std::uint8_t>(bytes_[at]);
    const auto b = static_cast<std::uint8_t>(bytes_[at + 1]);
    return big_endian_ ? static_cast<std::uint16_t>((a << 8U) | b)
                       : static_cast<std::uint16_t>(a | (b << 8U));
  }
  [[nodiscard]] std::uint32_t u32(std::size_t at) const {
    const std::uint32_t low = u16(at);
    const std::uint32_t high = u16(at + 2);
    return big_endian_ ? (low << 16U) | high : low | (high << 16U);
  }

  // Group 0002, always explicit VR little endian; finds the transfer syntax.
  void walk_meta() {
    std::string syntax;
    bool has_meta = false;
    std::optional<std::size_t> group_end;  // from (0002,0000)
    while (bytes_.size() - offset_ >= 2 && u16(offset_) == 0x0002) {
      has_meta = true;
      need(8, "a file meta element header");
      const std::uint16_t element = u16(offset_ + 2);
      const std::string_view vr = bytes_.substr(offset_ + 4, 2);
      std::size_t header = 8;
      std::size_t length = u16(offset_ + 6);
      if (contains(kLongVrs, vr)) {
        need(12, "the header of " + tag_text(0x0002, element));
        header = 12;
        length = u32(offset_ + 8);
      } else if (!contains(kShortVrs, vr)) {
        fail("file meta information: " + tag_text(0x0002, element) +
             " has no valid explicit VR: the file is corrupt");
      }
      if (length == kUndefinedLength) {
        fail("file meta information: " + tag_text(0x0002, element) +
             " has an undefined length: the file is corrupt");
      }
      need(header + length, "the value of " + tag_text(0x0002, element));
      if (element == 0x0010) syntax = std::string(bytes_.substr(offset_ + header, length));
      if (element == 0x0000 && length == 4) {
        group_end = offset_ + header + length + u32(offset_ + header);
      }
      offset_ += header + length;
    }
    // GDCM aborts on a meta group shorter than its group length says, and on
    // a file that ends after the meta group: both are cut-short copies.
    if (group_end && offset_ != *group_end) {
      fail(
          "is truncated or corrupt: File Meta Information Group Length (0002,0000) says the "
          "meta information ends at byte " +
          std::to_string(*group_end) + ", it ends at " + std::to_string(offset_));
    }
    if (has_meta && syntax.empty()) {
      fail(
          "Transfer Syntax UID (0002,0010) is missing from the file meta information (a "
          "truncated or corrupt file)");
    }
    if (offset_ == bytes_.size()) {
      fail(
          "is truncated: it ends before its data set (only the preamble or the file meta "
          "information is there; fetch the file again)");
    }
    while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    if (!syntax.empty() &&
        gdcm::TransferSyntax::GetTSType(syntax.c_str()) == gdcm::TransferSyntax::TS_END) {
      fail("Transfer Syntax UID (0002,0010) '" + syntax +
           "' is not a transfer syntax this reader (GDCM 3.0) can decode; convert the file to "
           "explicit VR little endian (e.g. `gdcmconv --raw in.dcm out.dcm`, or DCMTK's "
           "`dcmconv +te`) and load that");
    }
    if (syntax == "1.2.840.10008.1.2.1.99") {
      fail(
          "Transfer Syntax UID (0002,0010) is deflated explicit VR little endian, which this "
          "reader does not accept; convert the file (e.g. `gdcmconv --raw in.dcm out.dcm`)");
    }
    big_endian_ = syntax == "1.2.840.10008.1.2.2";
    if (syntax.empty()) {
      // A bare data set: explicit when the bytes after the first tag are a VR.
      explicit_vr_ =
          bytes_.size() - offset_ >= 6 && (contains(kLongVrs, bytes_.substr(offset_ + 4, 2)) ||
                                           contains(kShortVrs, bytes_.substr(offset_ + 4, 2)));
    } else {
      explicit_vr_ = syntax != "1.2.840.10008.1.2";
    }
  }

  void walk_data_set() {
    std::vector<Frame> open;
    while (true) {
      // Close the defined-length frames that end here.
      while (!open.empty() && open.back().end == offset_) open.pop_back();
      if (offset_ == bytes_.size()) break;
      if (!open.empty() && open.back().end != kNoEnd && offset_ > open.back().end) {
        fail("an element runs past the end of its sequence or item at offset " +
             std::to_string(offset_) + ": the file is corrupt");
      }
      need(8, "an element header");
      const std::uint16_t group = u16(offset_);
      const std::uint16_t element = u16(offset_ + 2);
      const std::string tag = tag_text(group, element);
      const bool in_fragments = !open.empty() && open.back().kind == FrameKind::kFragments;
      if (group == 0xFFFE) {
        const std::uint32_t length = u32(offset_ + 4);
        offset_ += 8;
        if (element == 0xE000) {  // item
          if (open.empty() || open.back().kind == FrameKind::kItem) {
            fail("an item " + tag + " outside a sequence: the file is corrupt");
          }
          if (length == kUndefinedLength) {
            if (in_fragments) fail("a Pixel Data fragment of undefined length: corrupt");
            push(open, {FrameKind::kItem, kNoEnd});
          } else {
            check_value(length, open, "an item");
            if (in_fragments) {
              offset_ += length;  // a fragment of compressed pixels: skipped
            } else if (length > 0) {
              push(open, {FrameKind::kItem, offset_ + length});
            }
          }
        } else if (element == 0xE00D || element == 0xE0DD) {  // item / sequence delimiter
          const bool item = element == 0xE00D;
          if (open.empty() || open.back().end != kNoEnd ||
              (open.back().kind == FrameKind::kItem) != item) {
            fail("a delimiter " + tag + " that closes nothing: the file is corrupt");
          }
          open.pop_back();
        } else {
          fail("an unknown element " + tag + " of group FFFE: the file is corrupt");
        }
        continue;
      }
      if (in_fragments) {
        fail(tag +
             " inside the Pixel Data (7FE0,0010) fragments, where only items may be: "
             "the file is corrupt");
      }
      std::size_t header = 8;
      std::uint32_t length = u32(offset_ + 4);
      bool sequence = false;
      if (explicit_vr_) {
        const std::string_view vr = bytes_.substr(offset_ + 4, 2);
        if (contains(kLongVrs, vr)) {
          need(12, "the header of " + tag);
          header = 12;
          length = u32(offset_ + 8);
          sequence = vr == "SQ";
        } else if (contains(kShortVrs, vr)) {
          length = u16(offset_ + 6);
        } else {
          fail(tag + " has no valid explicit VR: the file is corrupt");
        }
      }
      offset_ += header;
      if (length == kUndefinedLength) {
        const bool pixels = group == 0x7FE0 && element == 0x0010;
        push(open, {pixels ? FrameKind::kFragments : FrameKind::kSequence, kNoEnd});
        continue;
      }
      check_value(length, open, "the value of " + tag);
      if (sequence && length > 0) {
        push(open, {FrameKind::kSequence, offset_ + length});
      } else {
        offset_ += length;
      }
    }
    if (!open.empty()) {
      fail("is truncated: it ends inside " +
           std::string(open.back().kind == FrameKind::kFragments
                           ? "the Pixel Data (7FE0,0010) fragments"
                           : "a sequence") +
           " (the copy was cut short; fetch the file again)");
    }
  }

  void check_value(std::uint32_t length, const std::vector<Frame>& open, const std::string& what) {
    need(length, what);
    if (!open.empty() && open.back().end != kNoEnd && offset_ + length > open.back().end) {
      fail(what + " runs past the end of its sequence or item: the file is corrupt");
    }
  }

  void push(std::vector<Frame>& open, Frame frame) const {
    if (open.size() >= kDicomMaxNesting * 2) {  // a sequence and its item per level
      fail("sequences nest deeper than " + std::to_string(kDicomMaxNesting) +
           " levels: refused (a radiograph needs two or three)");
    }
    open.push_back(frame);
  }

  std::string_view bytes_;
  const fs::path& source_;
  std::size_t offset_ = 0;
  bool explicit_vr_ = true;
  bool big_endian_ = false;
};

}  // namespace

void check_dicom_structure(std::string_view bytes, const fs::path& source) {
  Walker(bytes, source).run();
}

}  // namespace mmm::image::detail
