#pragma once
// SHA-256 message digest (NIST FIPS 180-4), computed by OpenSSL's EVP
// interface (the SHA extensions of the processor when it has them). Used to
// name content-addressed artifacts, to check that a stored file still holds
// the bytes it was written with, and for the audit trail's hash chain.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

// OpenSSL's digest context (EVP_MD_CTX), kept out of this header.
struct evp_md_ctx_st;

namespace mmm::hash {

// 32-byte SHA-256 digest.
using Sha256Digest = std::array<std::uint8_t, 32>;

// Incremental SHA-256: feed the message with update() in pieces of any size,
// then call finish() once for the digest. finish() resets the object to the
// empty message, so it can hash the next message right away.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;

  // Appends bytes to the message.
  void update(std::string_view bytes);

  // Digest of everything passed to update() since construction or the last
  // finish(); resets the state to that of a new object.
  [[nodiscard]] Sha256Digest finish();

 private:
  struct ContextDeleter {
    void operator()(evp_md_ctx_st* context) const;
  };
  std::unique_ptr<evp_md_ctx_st, ContextDeleter> context_;
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
