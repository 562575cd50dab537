// ArtifactStore sharing its blobs with a pool (a cohort's shared store):
// a blob the pool has is linked, not written; a new blob is published; a
// study that wrote a blob the pool already had ends up linked to the
// pool's file; and a pool emptied under the writers loses nothing.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/test_data.h"
#include "workflow/store/artifact_store.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;

struct FileIdentity {
  dev_t device = 0;
  ino_t inode = 0;
  nlink_t links = 0;
  bool operator==(const FileIdentity& other) const {
    return device == other.device && inode == other.inode;
  }
};

FileIdentity file_identity(const fs::path& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return {info.st_dev, info.st_ino, info.st_nlink};
}

class ArtifactStorePoolTest : public ::testing::Test {
 protected:
  ArtifactStore study(const std::string& name) {
    ArtifactStore store(scratch_ / name / "artifacts");
    store.share_with(pool_.root());
    return store;
  }
  test::ScratchDir scratch_{"store-pool"};
  ArtifactStore pool_{scratch_ / ".mmm-store"};
};

TEST_F(ArtifactStorePoolTest, TheSecondStudyLinksWhatTheFirstWrote) {
  ArtifactStore a = study("a");
  ArtifactStore b = study("b");
  const std::string atlas(100'000, 'x');
  const std::string hash = a.put(atlas);
  EXPECT_TRUE(pool_.contains(hash));
  EXPECT_EQ(b.put(atlas), hash);
  const FileIdentity in_pool = file_identity(pool_.path_of(hash));
  EXPECT_EQ(file_identity(a.path_of(hash)), in_pool);
  EXPECT_EQ(file_identity(b.path_of(hash)), in_pool);
  EXPECT_EQ(in_pool.links, 3U);
  EXPECT_EQ(b.get(hash), atlas);
  // A blob of one study only is still published for the next.
  const std::string own = b.put("only b's");
  EXPECT_EQ(file_identity(pool_.path_of(own)).links, 2U);
}

TEST_F(ArtifactStorePoolTest, AFileCopiedInIsReplacedByThePoolsLink) {
  ArtifactStore a = study("a");
  ArtifactStore b = study("b");
  const fs::path file = test::write_file(scratch_ / "trial.trc", std::string(50'000, 't'));
  const std::string hash = a.put_file(file);
  EXPECT_EQ(b.put_file(file), hash);  // copied, then swapped for the pool's file
  EXPECT_EQ(file_identity(b.path_of(hash)), file_identity(pool_.path_of(hash)));
  EXPECT_EQ(file_identity(pool_.path_of(hash)).links, 3U);
  EXPECT_EQ(b.get(hash), std::string(50'000, 't'));
  // No temporary is left behind.
  for (const auto& entry : fs::directory_iterator(b.root())) {
    EXPECT_FALSE(entry.path().filename().string().starts_with(".tmp-")) << entry.path();
  }
}

TEST_F(ArtifactStorePoolTest, AStoreWithoutAPoolKeepsItsOwnFiles) {
  ArtifactStore alone(scratch_ / "alone" / "artifacts");
  const std::string hash = alone.put("bytes");
  EXPECT_FALSE(pool_.contains(hash));
  EXPECT_EQ(file_identity(alone.path_of(hash)).links, 1U);
}

// Writers of eight studies put the same and their own blobs while a
// collector keeps removing every pool blob no study links (st_nlink 1), as
// `mmm gc` does: each study ends with all its blobs, intact.
TEST_F(ArtifactStorePoolTest, ACollectorRacingTheWritersLosesNothing) {
  constexpr int kStudies = 8;
  constexpr int kBlobs = 40;
  std::atomic<bool> stop{false};
  std::thread collector([&] {
    while (!stop) {
      std::error_code error;
      for (const auto& shard : fs::directory_iterator(pool_.root(), error)) {
        if (!shard.is_directory()) continue;
        for (const auto& blob : fs::directory_iterator(shard.path(), error)) {
          struct stat info {};
          if (::stat(blob.path().c_str(), &info) == 0 && info.st_nlink == 1) {
            ::unlink(blob.path().c_str());
          }
        }
      }
    }
  });
  std::vector<std::vector<std::string>> hashes(kStudies);
  std::vector<std::thread> writers;
  writers.reserve(kStudies);
  for (int s = 0; s < kStudies; ++s) {
    writers.emplace_back([&, s] {
      ArtifactStore store = study("s" + std::to_string(s));
      for (int k = 0; k < kBlobs; ++k) {
        hashes[static_cast<std::size_t>(s)].push_back(
            store.put("shared blob " + std::to_string(k % 10) + std::string(4096, 'p')));
        hashes[static_cast<std::size_t>(s)].push_back(
            store.put("blob " + std::to_string(k) + " of study " + std::to_string(s)));
      }
    });
  }
  for (std::thread& writer : writers) writer.join();
  stop = true;
  collector.join();
  for (int s = 0; s < kStudies; ++s) {
    const ArtifactStore store = study("s" + std::to_string(s));
    for (const std::string& hash : hashes[static_cast<std::size_t>(s)]) {
      EXPECT_TRUE(store.verify(hash)) << "study " << s << " lost " << hash;
    }
  }
}

}  // namespace
}  // namespace mmm::workflow
