#include "workflow/store/artifact_store.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "tests/support/test_data.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;

// Deterministic pseudo-random bytes (no two blocks of a large blob alike).
std::string pattern_bytes(std::size_t size, std::uint32_t seed) {
  std::string bytes(size, '\0');
  std::uint32_t state = seed * 2654435761U + 1U;
  for (char& byte : bytes) {
    state = state * 1664525U + 1013904223U;
    byte = static_cast<char>(state >> 24);
  }
  return bytes;
}

// Names directly in `dir` that start with ".tmp-".
std::vector<fs::path> temporaries(const fs::path& dir) {
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().starts_with(".tmp-")) found.push_back(entry.path());
  }
  return found;
}

// Every blob under its final name in the store: "<2 hex>/<62 hex>" -> hash.
std::vector<std::string> final_blobs(const fs::path& root) {
  std::vector<std::string> hashes;
  for (const auto& shard : fs::directory_iterator(root)) {
    if (!shard.is_directory()) continue;
    for (const auto& blob : fs::directory_iterator(shard.path())) {
      hashes.push_back(shard.path().filename().string() + blob.path().filename().string());
    }
  }
  return hashes;
}

// Runs `body` in a forked child that exits 0 on success, 1 on an exception.
pid_t fork_child(const std::function<void()>& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int code = 0;
    try {
      body();
    } catch (...) {
      code = 1;
    }
    ::_exit(code);
  }
  return pid;
}

int wait_status(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return status;
}

ino_t inode_of(const fs::path& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return info.st_ino;
}

TEST(ArtifactStoreTest, PutThenGetRoundTrips) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir / "store");
  EXPECT_TRUE(fs::is_directory(dir / "store"));
  const std::string bytes = "femur.stl bytes\0with a zero"s;
  const std::string hash = store.put(bytes);
  EXPECT_EQ(hash, hash::sha256_hex(bytes));
  EXPECT_EQ(store.path_of(hash), dir / "store" / hash.substr(0, 2) / hash.substr(2));
  EXPECT_EQ(ArtifactStore::relative_path_of(hash), fs::path(hash.substr(0, 2)) / hash.substr(2));
  EXPECT_TRUE(store.contains(hash));
  EXPECT_TRUE(store.verify(hash));
  EXPECT_EQ(store.get(hash), bytes);
  EXPECT_TRUE(temporaries(store.root()).empty());
}

TEST(ArtifactStoreTest, EmptyBlobIsStored) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir.path());
  const std::string hash = store.put("");
  EXPECT_EQ(hash, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(store.get(hash), "");
}

TEST(ArtifactStoreTest, ExistingBlobIsNotRewritten) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir.path());
  const std::string hash = store.put("same bytes");
  const ino_t before = inode_of(store.path_of(hash));
  EXPECT_EQ(store.put("same bytes"), hash);
  // A rewrite would have renamed a new file (new inode) over the old one.
  EXPECT_EQ(inode_of(store.path_of(hash)), before);
  EXPECT_TRUE(temporaries(store.root()).empty());
}

TEST(ArtifactStoreTest, PutFileEqualsPutOfTheBytes) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir / "store");
  // Larger than the 1 MiB copy block and not a multiple of it.
  const std::string bytes = pattern_bytes(2 * 1024 * 1024 + 77, 1);
  const auto source = test::write_file(dir / "mesh.bin", bytes);
  const std::string hash = store.put_file(source);
  EXPECT_EQ(hash, hash::sha256_hex(bytes));
  EXPECT_EQ(store.get(hash), bytes);
  // Storing it again (from a file or from memory) keeps the one blob.
  const ino_t before = inode_of(store.path_of(hash));
  EXPECT_EQ(store.put_file(source), hash);
  EXPECT_EQ(store.put(bytes), hash);
  EXPECT_EQ(inode_of(store.path_of(hash)), before);
  EXPECT_TRUE(temporaries(store.root()).empty());
  EXPECT_EQ(final_blobs(store.root()).size(), 1U);
}

TEST(ArtifactStoreTest, PutFileOfMissingSourceThrowsIoErrorWithPath) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir / "store");
  const auto missing = dir / "missing.bin";
  try {
    (void)store.put_file(missing);
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), missing);
  }
  EXPECT_TRUE(temporaries(store.root()).empty());
}

TEST(ArtifactStoreTest, CorruptedBlobIsReportedWithBothHashes) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir.path());
  const std::string hash = store.put("landmarks: 12 points");
  const fs::path path = store.path_of(hash);
  // Flip one byte in place (same size), as a disk error would.
  fs::permissions(path, fs::perms::owner_write, fs::perm_options::add);
  test::write_file(path, "landmarks: 13 points");
  const std::string actual = hash::sha256_hex("landmarks: 13 points");
  EXPECT_TRUE(store.contains(hash));
  EXPECT_FALSE(store.verify(hash));
  try {
    (void)store.get(hash);
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.path(), path);
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(hash), std::string::npos) << message;
    EXPECT_NE(message.find(actual), std::string::npos) << message;
    EXPECT_NE(message.find("re-run"), std::string::npos) << message;
  }
}

TEST(ArtifactStoreTest, TruncatedBlobIsReplacedByTheNextPut) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir.path());
  const std::string bytes = pattern_bytes(4096, 2);
  const std::string hash = store.put(bytes);
  fs::permissions(store.path_of(hash), fs::perms::owner_write, fs::perm_options::add);
  fs::resize_file(store.path_of(hash), 100);
  EXPECT_FALSE(store.verify(hash));
  EXPECT_EQ(store.put(bytes), hash);
  EXPECT_TRUE(store.verify(hash));
}

TEST(ArtifactStoreTest, MissingBlobThrowsIoError) {
  const test::ScratchDir dir("artifacts");
  const ArtifactStore store(dir.path());
  const std::string hash = hash::sha256_hex("never stored");
  EXPECT_FALSE(store.contains(hash));
  EXPECT_FALSE(store.verify(hash));
  try {
    (void)store.get(hash);
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), store.path_of(hash));
    EXPECT_NE(std::string(error.what()).find("missing"), std::string::npos) << error.what();
  }
}

TEST(ArtifactStoreTest, InvalidHashThrowsInvalidInputError) {
  const test::ScratchDir dir("artifacts");
  const ArtifactStore store(dir.path());
  const std::string valid = hash::sha256_hex("x");
  std::string upper = valid;
  upper[0] = 'A';
  upper[1] = 'B';
  for (const std::string& bad : {std::string(), valid.substr(1), valid + "0", upper,
                                 std::string(64, 'g'), std::string("../") + valid.substr(3)}) {
    EXPECT_FALSE(ArtifactStore::is_valid_hash(bad)) << bad;
    EXPECT_THROW((void)store.contains(bad), InvalidInputError) << bad;
    EXPECT_THROW((void)store.path_of(bad), InvalidInputError) << bad;
    EXPECT_THROW((void)store.get(bad), InvalidInputError) << bad;
    EXPECT_THROW((void)store.verify(bad), InvalidInputError) << bad;
  }
  EXPECT_TRUE(ArtifactStore::is_valid_hash(valid));
}

TEST(ArtifactStoreTest, RootThatIsAFileThrowsIoError) {
  const test::ScratchDir dir("artifacts");
  const auto file = test::write_file(dir / "not_a_folder", "x");
  EXPECT_THROW(ArtifactStore{file}, IoError);
}

TEST(ArtifactStoreTest, MovedStoreFolderKeepsEveryBlob) {
  const test::ScratchDir dir("artifacts");
  std::vector<std::string> hashes;
  {
    ArtifactStore store(dir / "study_a" / "artifacts");
    for (std::uint32_t i = 0; i < 5; ++i) hashes.push_back(store.put(pattern_bytes(1000, i)));
  }
  fs::rename(dir / "study_a", dir / "study_b");
  const ArtifactStore moved(dir / "study_b" / "artifacts");
  for (std::uint32_t i = 0; i < 5; ++i) EXPECT_EQ(moved.get(hashes[i]), pattern_bytes(1000, i));
}

TEST(ArtifactStoreTest, ConcurrentThreadsPutSameAndDifferentContent) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir.path());
  constexpr int kThreads = 8;
  constexpr int kRounds = 20;
  std::vector<std::thread> threads;
  threads.reserve(kThreads);
  std::vector<int> failures(kThreads, 0);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&store, &failures, t] {
      for (int round = 0; round < kRounds; ++round) {
        // Shared content (all threads race on the same four names) and content
        // unique to this thread and round.
        const std::string shared =
            pattern_bytes(std::size_t{64} << 10, static_cast<std::uint32_t>(round % 4));
        const std::string own =
            pattern_bytes(1000, static_cast<std::uint32_t>(100 + t * 100 + round));
        if (store.put(shared) != hash::sha256_hex(shared)) ++failures[t];
        if (store.put(own) != hash::sha256_hex(own)) ++failures[t];
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(failures[t], 0) << "thread " << t;
  const auto blobs = final_blobs(store.root());
  EXPECT_EQ(blobs.size(), 4U + kThreads * kRounds);
  for (const auto& hash : blobs) EXPECT_TRUE(store.verify(hash)) << hash;
  EXPECT_TRUE(temporaries(store.root()).empty());
}

TEST(ArtifactStoreTest, ConcurrentProcessesPutTheSameContent) {
  const test::ScratchDir dir("artifacts");
  const fs::path root = dir / "store";
  const std::string shared = pattern_bytes(std::size_t{3} << 20, 7);
  std::vector<pid_t> children;
  children.reserve(4);
  for (int child = 0; child < 4; ++child) {
    children.push_back(fork_child([&root, &shared, child] {
      ArtifactStore store(root);
      for (int round = 0; round < 5; ++round) {
        if (store.put(shared) != hash::sha256_hex(shared)) ::_exit(2);
        (void)store.put(pattern_bytes(5000, static_cast<std::uint32_t>(child)));
      }
    }));
  }
  for (const pid_t pid : children) {
    ASSERT_GT(pid, 0);
    const int status = wait_status(pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
  }
  const ArtifactStore store(root);
  EXPECT_EQ(store.get(hash::sha256_hex(shared)), shared);
  const auto blobs = final_blobs(root);
  EXPECT_EQ(blobs.size(), 5U);
  for (const auto& hash : blobs) EXPECT_TRUE(store.verify(hash)) << hash;
  EXPECT_TRUE(temporaries(root).empty());
}

// Checks the crash invariant: every blob under a final name is complete.
void expect_every_final_blob_intact(const ArtifactStore& store) {
  for (const auto& hash : final_blobs(store.root())) {
    EXPECT_TRUE(store.verify(hash)) << "incomplete blob under its final name: " << hash;
    EXPECT_NO_THROW((void)store.get(hash)) << hash;
  }
}

TEST(ArtifactStoreTest, SigkilledWriterLeavesNoIncompleteBlob) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir / "store");
  const std::string earlier = store.put("written before the crash");
  const pid_t child = fork_child([root = store.root()] {
    ArtifactStore child_store(root);
    (void)child_store.put(pattern_bytes(std::size_t{200} << 20, 3));
  });
  ASSERT_GT(child, 0);
  // Kill the writer once it has started writing its temporary file (the
  // 200 MB take far longer to write and sync than the 50 ms before the kill),
  // or right away if it never gets that far within 60 s.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < give_up) {
    const auto temps = temporaries(store.root());
    if (!temps.empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  const int status = wait_status(child);
  EXPECT_TRUE(WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) == 0));

  expect_every_final_blob_intact(store);
  EXPECT_TRUE(store.verify(earlier));
  const std::size_t leftovers = temporaries(store.root()).size();
  EXPECT_EQ(store.remove_temporaries(), leftovers);
  EXPECT_TRUE(temporaries(store.root()).empty());
  expect_every_final_blob_intact(store);
}

// Deterministic variant: the writer streams from a FIFO that the test feeds,
// so it is certainly killed in the middle of its blob (blocked on a read with
// 8 MiB written to its temporary file).
TEST(ArtifactStoreTest, SigkilledStreamingWriterLeavesOnlyATemporary) {
  const test::ScratchDir dir("artifacts");
  ArtifactStore store(dir / "store");
  const fs::path fifo = dir / "source.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const pid_t child = fork_child([root = store.root(), fifo] {
    ArtifactStore child_store(root);
    (void)child_store.put_file(fifo);
  });
  ASSERT_GT(child, 0);
  const int feed = ::open(fifo.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(feed, 0);
  const std::string piece = pattern_bytes(1 << 20, 4);
  for (int i = 0; i < 8; ++i) {
    std::string_view rest(piece);
    while (!rest.empty()) {
      const ssize_t wrote = ::write(feed, rest.data(), rest.size());
      ASSERT_GT(wrote, 0);
      rest.remove_prefix(static_cast<std::size_t>(wrote));
    }
  }
  // The writer has consumed the data once the temporary holds all 8 MiB (the
  // FIFO buffer is only 64 KiB); wait for that so the kill lands mid-blob.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::uintmax_t written = 0;
  while (written < (std::uintmax_t{8} << 20) && std::chrono::steady_clock::now() < give_up) {
    for (const auto& temp : temporaries(store.root())) {
      std::error_code ignored;
      written = std::max<std::uintmax_t>(written, fs::file_size(temp, ignored));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  const int status = wait_status(child);
  ::close(feed);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;

  EXPECT_TRUE(final_blobs(store.root()).empty());
  ASSERT_EQ(temporaries(store.root()).size(), 1U);
  EXPECT_EQ(store.remove_temporaries(), 1U);
  EXPECT_TRUE(temporaries(store.root()).empty());
  // The store works normally afterwards.
  EXPECT_EQ(store.get(store.put("after the crash")), "after the crash");
}

// A temporary whose writer is alive (it holds the flock) is not deleted; once
// the writer is gone it is.
TEST(ArtifactStoreTest, RemoveTemporariesSkipsLiveWriters) {
  const test::ScratchDir dir("artifacts");
  const ArtifactStore store(dir.path());
  const auto live = test::write_file(dir / ".tmp-live01", "partial");
  const auto dead = test::write_file(dir / ".tmp-dead01", "partial");
  const int fd = ::open(live.c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  EXPECT_EQ(store.remove_temporaries(), 1U);
  EXPECT_TRUE(fs::exists(live));
  EXPECT_FALSE(fs::exists(dead));
  ::close(fd);
  EXPECT_EQ(store.remove_temporaries(), 1U);
  EXPECT_FALSE(fs::exists(live));
}

}  // namespace
}  // namespace mmm::workflow
