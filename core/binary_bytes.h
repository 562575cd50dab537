#pragma once
// Little-endian binary encoding for mmm's own artifact formats: a writer that
// appends fixed-width values to a string, and a reader that never reads past
// the end and checks a count against the bytes left before anything of that
// size is allocated (a hostile header cannot make it reserve gigabytes).

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "core/errors.h"

namespace mmm {

static_assert(std::endian::native == std::endian::little,
              "mmm's binary formats are little-endian and written by memcpy");

class BinaryWriter {
 public:
  template <typename T>
  requires std::is_arithmetic_v<T>
  void put(T value) { bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T)); }
  void put_raw(std::string_view raw) { bytes_.append(raw); }
  // A uint32 length and the bytes.
  void put_string(std::string_view text) {
    put(static_cast<std::uint32_t>(text.size()));
    bytes_.append(text);
  }
  [[nodiscard]] std::string take() && { return std::move(bytes_); }
  [[nodiscard]] std::size_t size() const { return bytes_.size(); }

 private:
  std::string bytes_;
};

// Every failure throws InvalidInputError starting with `what` (the artifact
// and its field), so a message names where the file went wrong.
class BinaryReader {
 public:
  BinaryReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  template <typename T>
  requires std::is_arithmetic_v<T> T get(std::string_view field) {
    need(1, sizeof(T), field);
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  // A finite float or double.
  template <typename T>
  requires std::is_floating_point_v<T> T finite(std::string_view field) {
    const T value = get<T>(field);
    if (!std::isfinite(value)) fail(field, "is not a finite number");
    return value;
  }
  std::string_view raw(std::size_t count, std::string_view field) {
    need(count, 1, field);
    const std::string_view out = bytes_.substr(at_, count);
    at_ += count;
    return out;
  }
  // A uint32 length (at most `max_length`) and the bytes.
  std::string string(std::string_view field, std::uint32_t max_length = 256) {
    const auto length = get<std::uint32_t>(field);
    if (length > max_length) fail(field, "is longer than " + std::to_string(max_length) + " bytes");
    return std::string(raw(length, field));
  }
  // A uint32 count of items of at least `item_bytes` each: refused when the
  // bytes left cannot hold that many.
  std::uint32_t count(std::string_view field, std::size_t item_bytes) {
    const auto n = get<std::uint32_t>(field);
    need(n, item_bytes, field);
    return n;
  }
  // Throws unless `count` items of `item_bytes` fit in what is left.
  void need(std::uint64_t count, std::uint64_t item_bytes, std::string_view field) const {
    const std::uint64_t left = bytes_.size() - at_;
    if (item_bytes != 0 && count > left / item_bytes) {
      fail(field, "needs more bytes than the artifact has left (" + std::to_string(left) +
                      "); hint: the file is truncated or not this format");
    }
  }
  [[nodiscard]] bool at_end() const { return at_ == bytes_.size(); }
  [[nodiscard]] std::size_t offset() const { return at_; }
  [[noreturn]] void fail(std::string_view field, const std::string& problem) const {
    throw InvalidInputError(what_ + ": " + std::string(field) + " (byte " + std::to_string(at_) +
                            ") " + problem);
  }

 private:
  std::string_view bytes_;
  std::string what_;
  std::size_t at_ = 0;
};

}  // namespace mmm
