#pragma once
// SHA-256 message digest (NIST FIPS 180-4, section 6.2), written from the
// standard. Used to name content-addressed artifacts and to check that a
// stored file still holds the bytes it was written with.
//
// The idea: pad the message to a multiple of 64 bytes (a 1 bit, zeros, then
// the message length in bits as a big-endian 64-bit number) and feed each
// 64-byte block through the compression function, which expands the block to
// 64 words (message schedule) and mixes them into eight 32-bit state words over
// 64 rounds. The digest is the final state, big-endian.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace mmm::hash {

// 32-byte SHA-256 digest.
using Sha256Digest = std::array<std::uint8_t, 32>;

// Incremental SHA-256: feed the message with update() in pieces of any size,
// then call finish() once for the digest. finish() resets the object to the
// empty message, so it can hash the next message right away.
class Sha256 {
 public:
  Sha256();

  // Appends bytes to the message.
  void update(std::string_view bytes);

  // Digest of everything passed to update() since construction or the last
  // finish(); resets the state to that of a new object.
  [[nodiscard]] Sha256Digest finish();

 private:
  // Mixes `block_count` consecutive 64-byte blocks into state_.
  void compress(const std::uint8_t* blocks, std::size_t block_count);
  void reset();

  std::array<std::uint32_t, 8> state_{};
  std::array<std::uint8_t, 64> buffer_{};  // pending bytes of an incomplete block
  std::size_t buffered_ = 0;               // number of valid bytes in buffer_
  std::uint64_t length_ = 0;               // message length so far (bytes)
};

// 64 lowercase hexadecimal characters of a digest.
std::string to_hex(const Sha256Digest& digest);

// Lowercase hex SHA-256 of a byte string.
std::string sha256_hex(std::string_view bytes);

// Lowercase hex SHA-256 of a file's content, read in 1 MiB blocks (constant
// memory whatever the file size). Throws IoError naming the path when the file
// cannot be opened or read (missing, permission, directory).
std::string sha256_file_hex(const std::filesystem::path& path);

}  // namespace mmm::hash
