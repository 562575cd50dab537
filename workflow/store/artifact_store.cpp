#include "workflow/store/artifact_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "workflow/fault_injection.h"
#include "workflow/store/errno_text.h"

namespace mmm::workflow {
namespace {

constexpr std::string_view kTempPrefix = ".tmp-";
constexpr std::size_t kHashLength = 64;
constexpr std::size_t kCopyChunk = std::size_t{1} << 20;
// Blobs are immutable once stored: read-only for everyone.
constexpr mode_t kBlobMode = 0444;

using detail::errno_text;

// Owns a POSIX file descriptor.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd(Fd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Fd& operator=(Fd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

void write_all(int fd, std::string_view bytes, const std::filesystem::path& path) {
  while (!bytes.empty()) {
    const ssize_t wrote = ::write(fd, bytes.data(), bytes.size());
    if (wrote < 0) {
      if (errno == EINTR) continue;
      throw IoError(path, "cannot write artifact data: " + errno_text(errno) +
                              "; check free disk space and permissions of the study folder");
    }
    bytes.remove_prefix(static_cast<std::size_t>(wrote));
  }
}

// Reads up to buffer.size() bytes (fewer only at the end of the file).
std::size_t read_some(int fd, std::vector<char>& buffer, const std::filesystem::path& path) {
  while (true) {
    const ssize_t got = ::read(fd, buffer.data(), buffer.size());
    if (got >= 0) return static_cast<std::size_t>(got);
    if (errno != EINTR) throw IoError(path, "cannot read: " + errno_text(errno));
  }
}

// Makes the entries of a folder (names created, renamed) durable.
void fsync_directory(const std::filesystem::path& dir) {
  const Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!fd.valid()) throw IoError(dir, "cannot open folder to sync it: " + errno_text(errno));
  // EINVAL: the file system does not support syncing folders; nothing to do.
  if (::fsync(fd.get()) != 0 && errno != EINVAL) {
    throw IoError(dir, "cannot sync folder: " + errno_text(errno));
  }
}

bool is_regular_file_of_size(const std::filesystem::path& path, std::size_t size) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
         static_cast<std::size_t>(info.st_size) == size;
}

void check_hash(const std::string& hash) {
  if (!ArtifactStore::is_valid_hash(hash)) {
    throw InvalidInputError("artifact hash '" + hash.substr(0, 80) +
                            "' is not a SHA-256: expected 64 lowercase hex digits, got " +
                            std::to_string(hash.size()) + " characters");
  }
}

// A temporary file `<root>/.tmp-XXXXXX` being written by this process, locked
// with flock(2) for as long as it lives so that remove_temporaries() leaves it
// alone. Deleted on destruction unless commit() renamed it into place.
class TempBlob {
 public:
  explicit TempBlob(const std::filesystem::path& root) {
    for (int attempt = 0; attempt < 100; ++attempt) {
      std::string name = (root / (std::string(kTempPrefix) + "XXXXXX")).string();
      Fd fd(::mkostemp(name.data(), O_CLOEXEC));
      if (!fd.valid()) {
        throw IoError(root, "cannot create a temporary artifact file: " + errno_text(errno) +
                                "; check that the study folder is writable");
      }
      while (::flock(fd.get(), LOCK_EX) != 0) {
        if (errno != EINTR) throw IoError(name, "cannot lock: " + errno_text(errno));
      }
      // remove_temporaries() may have deleted the file between mkostemp and
      // flock (it was not locked yet): then start over with a new one.
      struct stat info {};
      if (::fstat(fd.get(), &info) != 0) throw IoError(name, "cannot stat: " + errno_text(errno));
      if (info.st_nlink > 0) {
        fd_ = std::move(fd);
        path_ = name;
        return;
      }
    }
    throw IoError(root, "cannot create a temporary artifact file: it kept being deleted");
  }
  ~TempBlob() {
    if (!committed_) ::unlink(path_.c_str());
  }
  TempBlob(const TempBlob&) = delete;
  TempBlob& operator=(const TempBlob&) = delete;
  TempBlob(TempBlob&&) = delete;
  TempBlob& operator=(TempBlob&&) = delete;

  void write(std::string_view bytes) { write_all(fd_.get(), bytes, path_); }

  // Makes the content durable, then atomically gives it its final name.
  void commit(const std::filesystem::path& root, const std::filesystem::path& final_path,
              bool sync) {
    if (::fchmod(fd_.get(), kBlobMode) != 0) {
      throw IoError(path_, "cannot set permissions: " + errno_text(errno));
    }
    fault_point("artifact.before_sync");
    if (sync && ::fsync(fd_.get()) != 0) {
      throw IoError(path_, "cannot sync artifact data to disk: " + errno_text(errno));
    }
    fault_point("artifact.before_rename");
    const std::filesystem::path shard = final_path.parent_path();
    if (::mkdir(shard.c_str(), 0755) == 0) {
      if (sync) fsync_directory(root);
    } else if (errno != EEXIST) {
      throw IoError(shard, "cannot create artifact folder: " + errno_text(errno));
    }
    if (::rename(path_.c_str(), final_path.c_str()) != 0) {
      throw IoError(final_path, "cannot move the artifact into place from " + path_.string() +
                                    ": " + errno_text(errno));
    }
    committed_ = true;
    fault_point("artifact.after_rename");
    if (sync) fsync_directory(shard);
  }

 private:
  Fd fd_;
  std::filesystem::path path_;
  bool committed_ = false;
};

enum class LinkResult { kLinked, kExists, kFailed };

// Gives the file `from` the new name `to` (link(2)), creating `to`'s shard
// folder. kExists when `to` already names a file; kFailed for any other
// refusal (`from` gone, another file system, too many links).
LinkResult link_name(const std::filesystem::path& from, const std::filesystem::path& to) {
  const std::filesystem::path shard = to.parent_path();
  if (::mkdir(shard.c_str(), 0755) != 0 && errno != EEXIST) return LinkResult::kFailed;
  if (::link(from.c_str(), to.c_str()) == 0) return LinkResult::kLinked;
  return errno == EEXIST ? LinkResult::kExists : LinkResult::kFailed;
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  struct stat first {};
  struct stat second {};
  return ::stat(a.c_str(), &first) == 0 && ::stat(b.c_str(), &second) == 0 &&
         first.st_dev == second.st_dev && first.st_ino == second.st_ino;
}

std::string read_whole_file(const std::filesystem::path& path, const std::string& hash) {
  const Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (!fd.valid()) {
    const int code = errno;
    if (code == ENOENT) {
      throw IoError(path, "artifact " + hash +
                              " is missing from the store; the study should re-run the node "
                              "that produced it");
    }
    throw IoError(path, "cannot open artifact " + hash + ": " + errno_text(code));
  }
  std::string content;
  std::vector<char> chunk(kCopyChunk);
  while (true) {
    const std::size_t got = read_some(fd.get(), chunk, path);
    if (got == 0) break;
    content.append(chunk.data(), got);
  }
  return content;
}

}  // namespace

ArtifactStore::ArtifactStore(std::filesystem::path root) : root_(std::move(root)) {
  std::error_code error;
  std::filesystem::create_directories(root_, error);
  if (!std::filesystem::is_directory(root_)) {
    throw IoError(root_, "cannot create the artifact store folder" +
                             (error ? ": " + error.message() : std::string(": not a folder")));
  }
}

bool ArtifactStore::is_valid_hash(std::string_view hash) {
  return hash.size() == kHashLength && std::ranges::all_of(hash, [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

std::filesystem::path ArtifactStore::relative_path_of(const std::string& hash) {
  check_hash(hash);
  return std::filesystem::path(hash.substr(0, 2)) / hash.substr(2);
}

std::filesystem::path ArtifactStore::path_of(const std::string& hash) const {
  return root_ / relative_path_of(hash);
}

bool ArtifactStore::contains(const std::string& hash) const {
  std::error_code ignored;
  return std::filesystem::is_regular_file(path_of(hash), ignored);
}

std::string ArtifactStore::put(std::string_view bytes) {
  std::string hash = hash::sha256_hex(bytes);
  const std::filesystem::path final_path = path_of(hash);
  if (is_regular_file_of_size(final_path, bytes.size()) && trust_existing(hash)) return hash;
  if (adopt_from_pool(hash, bytes.size())) return hash;
  TempBlob temp(root_);
  // Fault points: a crash half-way through the bytes must leave only a
  // temporary file behind.
  fault_point("artifact.before_write");
  const std::size_t half = bytes.size() / 2;
  temp.write(bytes.substr(0, half));
  fault_point("artifact.mid_write");
  temp.write(bytes.substr(half));
  temp.commit(root_, final_path, durability_ == Durability::kSyncEachWrite);
  publish_to_pool(hash, bytes.size());
  return hash;
}

std::string ArtifactStore::put_file(const std::filesystem::path& source) {
  const Fd in(::open(source.c_str(), O_RDONLY | O_CLOEXEC));
  if (!in.valid()) {
    throw IoError(source, "cannot open to store as an artifact: " + errno_text(errno) +
                              "; check that the file exists and is readable");
  }
  TempBlob temp(root_);
  hash::Sha256 hasher;
  std::vector<char> chunk(kCopyChunk);
  std::size_t size = 0;
  fault_point("artifact.before_write");
  while (true) {
    const std::size_t got = read_some(in.get(), chunk, source);
    if (got == 0) break;
    const std::string_view piece(chunk.data(), got);
    hasher.update(piece);
    temp.write(piece);
    if (size == 0) fault_point("artifact.mid_write");
    size += got;
  }
  std::string hash = hash::to_hex(hasher.finish());
  const std::filesystem::path final_path = path_of(hash);
  // Already stored: the destructor of `temp` deletes the copy.
  if (!is_regular_file_of_size(final_path, size) || !trust_existing(hash)) {
    temp.commit(root_, final_path, durability_ == Durability::kSyncEachWrite);
    publish_to_pool(hash, size);
  }
  return hash;
}

bool ArtifactStore::adopt_from_pool(const std::string& hash, std::size_t size) const {
  if (!pool_) return false;
  const std::filesystem::path shared = *pool_ / relative_path_of(hash);
  if (!is_regular_file_of_size(shared, size)) return false;
  // Deferred writers trust nothing unsynced: the pool's blob too is checked.
  if (durability_ == Durability::kDeferred) {
    try {
      if (hash::sha256_file_hex(shared) != hash) return false;
    } catch (const IoError&) {
      return false;
    }
  }
  const std::filesystem::path final_path = path_of(hash);
  switch (link_name(shared, final_path)) {
    case LinkResult::kLinked:
      if (durability_ == Durability::kSyncEachWrite) fsync_directory(final_path.parent_path());
      return true;
    case LinkResult::kExists:  // another writer of this study put it meanwhile
      return is_regular_file_of_size(final_path, size);
    case LinkResult::kFailed:  // e.g. collected from the pool meanwhile: write it
      return false;
  }
  return false;
}

void ArtifactStore::publish_to_pool(const std::string& hash, std::size_t size) const {
  if (!pool_) return;
  const std::filesystem::path local = path_of(hash);
  const std::filesystem::path shared = *pool_ / relative_path_of(hash);
  const bool sync = durability_ == Durability::kSyncEachWrite;
  switch (link_name(local, shared)) {
    case LinkResult::kLinked:
      if (sync) fsync_directory(shared.parent_path());
      return;
    case LinkResult::kFailed:  // another file system, a link limit: keep the own copy
      return;
    case LinkResult::kExists:
      break;
  }
  // The pool had the blob (another study put it first): let this study's
  // name point at the pool's file and free the copy. A temporary name first,
  // then rename(2) over the study's name: atomic, the name always complete.
  if (same_file(local, shared) || !is_regular_file_of_size(shared, size)) return;
  static std::atomic<unsigned> next_link{0};
  const std::filesystem::path temporary =
      root_ / (std::string(kTempPrefix) + "link-" + hash.substr(0, 16) + "-" +
               std::to_string(::getpid()) + "-" + std::to_string(next_link++));
  ::unlink(temporary.c_str());
  if (::link(shared.c_str(), temporary.c_str()) != 0) return;
  if (::rename(temporary.c_str(), local.c_str()) != 0) {
    ::unlink(temporary.c_str());
    return;
  }
  if (sync) fsync_directory(local.parent_path());
}

std::string ArtifactStore::get(const std::string& hash) const {
  const std::filesystem::path path = path_of(hash);
  std::string content = read_whole_file(path, hash);
  const std::string actual = hash::sha256_hex(content);
  if (actual != hash) {
    throw IoError(path, "corrupted artifact: expected SHA-256 " + hash + ", content hashes to " +
                            actual + " (" + std::to_string(content.size()) +
                            " bytes); the study should re-run the node that produced it");
  }
  return content;
}

bool ArtifactStore::trust_existing(const std::string& hash) const {
  // A blob of the right size is complete unless it may date from before a
  // power loss that hit it unsynced (deferred mode): then check its content.
  return durability_ == Durability::kSyncEachWrite || verify(hash);
}

void ArtifactStore::sync_all() const {
  const Fd fd(::open(root_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!fd.valid() || ::syncfs(fd.get()) != 0) {
    throw IoError(root_, "cannot flush the artifact store to disk: " + errno_text(errno));
  }
}

bool ArtifactStore::verify(const std::string& hash) const {
  const std::filesystem::path path = path_of(hash);
  try {
    return hash::sha256_file_hex(path) == hash;
  } catch (const IoError&) {
    return false;
  }
}

std::size_t ArtifactStore::remove_temporaries() const {
  std::size_t removed = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(root_, error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(kTempPrefix)) continue;
    const Fd fd(::open(entry.path().c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW));
    if (!fd.valid()) continue;  // gone meanwhile (renamed into place) or not a file
    // A live writer holds the lock: leave its file alone.
    if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) continue;
    // Delete the name only if it still refers to the file that is locked: a
    // writer may have renamed it into place since it was listed.
    struct stat locked {};
    struct stat named {};
    if (::fstat(fd.get(), &locked) != 0 || ::lstat(entry.path().c_str(), &named) != 0) continue;
    if (locked.st_dev != named.st_dev || locked.st_ino != named.st_ino) continue;
    if (::unlink(entry.path().c_str()) == 0) ++removed;
  }
  if (error) throw IoError(root_, "cannot list the artifact store: " + error.message());
  return removed;
}

}  // namespace mmm::workflow
