#include "core/base64.h"

#include <array>
#include <cstdint>

#include "core/errors.h"

namespace mmm {
namespace {

constexpr std::string_view kAlphabet =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// Value of each byte in the alphabet, -1 for the others.
constexpr std::array<int, 256> decoding_table() {
  std::array<int, 256> table{};
  for (int& value : table) value = -1;
  for (std::size_t i = 0; i < kAlphabet.size(); ++i) {
    table[static_cast<unsigned char>(kAlphabet[i])] = static_cast<int>(i);
  }
  return table;
}

constexpr std::array<int, 256> kDecoding = decoding_table();

}  // namespace

std::string base64_encode(std::string_view bytes) {
  std::string text;
  text.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t group =
        static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16U |
        static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8U |
        static_cast<unsigned char>(bytes[i + 2]);
    text += kAlphabet[(group >> 18U) & 63U];
    text += kAlphabet[(group >> 12U) & 63U];
    text += kAlphabet[(group >> 6U) & 63U];
    text += kAlphabet[group & 63U];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t group = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16U;
    if (rest == 2)
      group |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8U;
    text += kAlphabet[(group >> 18U) & 63U];
    text += kAlphabet[(group >> 12U) & 63U];
    text += rest == 2 ? kAlphabet[(group >> 6U) & 63U] : '=';
    text += '=';
  }
  return text;
}

std::string base64_decode(std::string_view text, std::string_view what) {
  if (text.size() % 4 != 0) {
    throw InvalidInputError(std::string(what) + ": base64 text of " + std::to_string(text.size()) +
                            " characters is not a multiple of 4 long (truncated?)");
  }
  std::string bytes;
  bytes.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    std::uint32_t group = 0;
    int padding = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=' && last && k >= 2 && (k == 3 || text[i + 3] == '=')) {
        ++padding;
        group <<= 6U;
        continue;
      }
      const int value = kDecoding[static_cast<unsigned char>(c)];
      if (value < 0 || padding > 0) {
        throw InvalidInputError(std::string(what) + ": invalid base64 character at offset " +
                                std::to_string(i + k));
      }
      group = group << 6U | static_cast<std::uint32_t>(value);
    }
    bytes += static_cast<char>((group >> 16U) & 255U);
    if (padding < 2) bytes += static_cast<char>((group >> 8U) & 255U);
    if (padding < 1) bytes += static_cast<char>(group & 255U);
  }
  return bytes;
}

}  // namespace mmm
