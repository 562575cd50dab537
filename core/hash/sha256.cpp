#include "core/hash/sha256.h"

#include <fcntl.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "core/errors.h"

namespace mmm::hash {
namespace {

constexpr std::size_t kFileChunk = std::size_t{1} << 20;

std::string errno_text(int code) {
  return std::error_code(code, std::generic_category()).message();
}

// Closes a POSIX file descriptor on scope exit.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  FileDescriptor(FileDescriptor&&) = delete;
  FileDescriptor& operator=(FileDescriptor&&) = delete;
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

// Throws when OpenSSL cannot do what it is asked (out of memory, or a
// library without SHA-256): nothing the caller could fix.
void check_openssl(int status, const char* what) {
  if (status != 1) {
    throw std::runtime_error(std::string("OpenSSL could not ") + what + " a SHA-256 digest");
  }
}

}  // namespace

void Sha256::ContextDeleter::operator()(evp_md_ctx_st* context) const { EVP_MD_CTX_free(context); }

Sha256::Sha256() : context_(EVP_MD_CTX_new()) {
  if (!context_) throw std::runtime_error("OpenSSL could not allocate a digest context");
  check_openssl(EVP_DigestInit_ex(context_.get(), EVP_sha256(), nullptr), "start");
}

Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(std::string_view bytes) {
  check_openssl(EVP_DigestUpdate(context_.get(), bytes.data(), bytes.size()), "update");
}

Sha256Digest Sha256::finish() {
  Sha256Digest digest{};
  unsigned int length = 0;
  check_openssl(EVP_DigestFinal_ex(context_.get(), digest.data(), &length), "finish");
  check_openssl(length == digest.size() ? 1 : 0, "size");
  check_openssl(EVP_DigestInit_ex(context_.get(), EVP_sha256(), nullptr), "restart");
  return digest;
}

std::string to_hex(const Sha256Digest& digest) {
  constexpr std::string_view kDigits = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * digest.size());
  for (const std::uint8_t byte : digest) {
    hex.push_back(kDigits[byte >> 4]);
    hex.push_back(kDigits[byte & 0x0f]);
  }
  return hex;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 hasher;
  hasher.update(bytes);
  return to_hex(hasher.finish());
}

std::string sha256_file_hex(const std::filesystem::path& path) {
  const FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.get() < 0) {
    throw IoError(path, "cannot open for hashing: " + errno_text(errno) +
                            "; check that the file exists and is readable");
  }
  std::vector<char> chunk(kFileChunk);
  Sha256 hasher;
  while (true) {
    const ssize_t got = ::read(file.get(), chunk.data(), chunk.size());
    if (got < 0) {
      if (errno == EINTR) continue;
      throw IoError(path, "cannot read for hashing: " + errno_text(errno) +
                              "; expected a regular, readable file");
    }
    if (got == 0) break;
    hasher.update(std::string_view(chunk.data(), static_cast<std::size_t>(got)));
  }
  return to_hex(hasher.finish());
}

}  // namespace mmm::hash
