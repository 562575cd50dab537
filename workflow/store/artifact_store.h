#pragma once
// Content-addressed, crash-safe store of artifacts (the bytes produced by
// workflow nodes) inside a study folder.
//
// A blob is stored once, under the SHA-256 of its bytes:
//   <root>/<first 2 hex digits>/<remaining 62 hex digits>
// so equal outputs share one file and a hash recorded in the study database is
// enough to find and check the bytes. Nothing absolute is recorded: every blob
// is addressed relative to the root, so moving the study folder loses nothing.
//
// Crash safety (SIGKILL or power loss at any instant): a blob is written to a
// unique temporary file `<root>/.tmp-<random>`, fsync'ed, renamed to its final
// name and the folder holding that name is fsync'ed (in Durability::kDeferred
// mode the two fsyncs are replaced by one sync_all() for many blobs, see
// there). rename(2) within one file
// system atomically makes the name point at the complete file, so a blob under
// its final name is always complete; a writer that dies leaves at most a
// `.tmp-*` file, which remove_temporaries() deletes.
//
// Concurrency: put() and put_file() may run at the same time from several
// threads and processes on one root. Each writer has its own temporary file;
// two writers of the same content both rename onto the same name, and since
// rename atomically replaces the target with identical complete bytes, readers
// see either the one or the other file, never a mix. Writers of different
// content touch different names. Shard folders are created with mkdir, which
// tolerates the other writer having created them first. Every writer holds an
// flock(2) on its temporary file while it is alive; remove_temporaries() skips
// locked ones, so it deletes only the leftovers of dead writers and may also
// run concurrently.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace mmm::workflow {

// When a written blob is flushed to disk.
enum class Durability {
  // put() returns only when the blob and its name are on disk (fsync of the
  // file and of its folder): safe against power loss at once. The default.
  kSyncEachWrite,
  // put() leaves flushing to the operating system; the caller calls
  // sync_all() before it records anything that refers to the new blobs. A
  // process crash loses nothing (the kernel holds the data); after a power
  // loss a blob not yet synced may be empty or short, which put() detects
  // (size, and content when a blob of the right size is met again) and
  // rewrites, and no record refers to it. One syncfs(2) for many
  // blobs instead of two fsync(2) per blob: what makes a run of many small
  // nodes fast.
  kDeferred,
};

// Sharing (a cohort's studies under one root, shared_store.h): a store may
// share its blobs with a pool, another store folder of the same layout. A
// blob the pool has is not written again: the study's name for it becomes a
// hard link to the pool's file (link(2) is atomic: the name appears complete
// or not at all). A blob written by the study is linked into the pool for
// the next study; if another study put the same blob there first, the
// study's copy is replaced by a link to the pool's (rename over it). So
// identical artifacts across the studies of a root take their size once,
// while every study folder still holds all its blobs as ordinary files: it
// can be copied, moved, read and verified alone. Whatever fails in sharing
// (the pool on another file system, a link limit, a blob the pool's garbage
// collection just removed) falls back to the study's own copy: sharing never
// loses or fails a write.
//
// Every member taking a hash throws InvalidInputError when it is not 64
// lowercase hex digits. One object may be shared by threads (it holds only the
// root path).
class ArtifactStore {
 public:
  // Opens the store in `root`, creating the folder (and its parents) if
  // missing. Throws IoError when it cannot be created or is not a folder.
  explicit ArtifactStore(std::filesystem::path root);

  [[nodiscard]] const std::filesystem::path& root() const { return root_; }

  // Shares blobs with the store folder `pool` (see above). Set it before
  // sharing the store between threads.
  void share_with(std::filesystem::path pool) { pool_ = std::move(pool); }
  [[nodiscard]] const std::optional<std::filesystem::path>& pool() const { return pool_; }

  // Stores `bytes` and returns their SHA-256 (64 lowercase hex digits). A blob
  // already present with the right size is not rewritten (same hash, same
  // bytes); one whose size is wrong (damaged on disk) is replaced. Throws
  // IoError on a write failure (disk full, permissions), leaving no blob.
  std::string put(std::string_view bytes);

  // Stores the content of the file `source`, hashing while copying (one pass,
  // constant memory). Same guarantees and return value as put(). Throws
  // IoError naming `source` when it cannot be read.
  std::string put_file(const std::filesystem::path& source);

  // Whether a blob with this hash exists (its content is not checked).
  [[nodiscard]] bool contains(const std::string& hash) const;

  // Absolute location of the blob: root() / relative_path_of(hash). The blob
  // need not exist.
  [[nodiscard]] std::filesystem::path path_of(const std::string& hash) const;

  // Location of the blob relative to the root: "<2 hex>/<62 hex>".
  [[nodiscard]] static std::filesystem::path relative_path_of(const std::string& hash);

  // How put() and put_file() flush (see Durability). Set it before sharing
  // the store between threads.
  void set_durability(Durability durability) { durability_ = durability; }
  [[nodiscard]] Durability durability() const { return durability_; }

  // Flushes everything written so far to disk (syncfs(2) of the store's file
  // system). Throws IoError when the kernel reports a write error.
  void sync_all() const;

  // Reads the blob and checks its SHA-256. Throws IoError naming the path when
  // the blob is missing or unreadable, and when its content does not match the
  // hash (a corrupted artifact: the message gives both hashes and the hint to
  // re-run the node that produced it).
  [[nodiscard]] std::string get(const std::string& hash) const;

  // Whether the blob exists and its content hashes to `hash` (streams the
  // file; never throws for a missing or damaged blob).
  [[nodiscard]] bool verify(const std::string& hash) const;

  // Deletes the `.tmp-*` files left by writers that died (crash, SIGKILL);
  // files of writers still running are skipped. Returns how many were deleted.
  std::size_t remove_temporaries() const;

  // Whether `hash` is 64 lowercase hexadecimal digits.
  [[nodiscard]] static bool is_valid_hash(std::string_view hash);

 private:
  [[nodiscard]] bool trust_existing(const std::string& hash) const;
  // Links the pool's blob into this store; false when the pool has none of
  // that size (or it cannot be linked).
  bool adopt_from_pool(const std::string& hash, std::size_t size) const;
  // Links this store's new blob into the pool, or, when the pool has it
  // already, makes this store's name a link to the pool's file.
  void publish_to_pool(const std::string& hash, std::size_t size) const;

  std::filesystem::path root_;
  std::optional<std::filesystem::path> pool_;
  Durability durability_ = Durability::kSyncEachWrite;
};

}  // namespace mmm::workflow
