#include "core/directory_bundle.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Bytes that would break a naive line-based reader: NUL, line breaks, a
// line that looks like the closing "end", and every byte value.
std::string awkward_bytes() {
  std::string bytes("\0\nend\n\r\n", 8);
  for (int i = 0; i < 256; ++i) bytes += static_cast<char>(i);
  return bytes + "\n12 fake/header\n";
}

// A small atlas-shaped tree with nested folders, binary, empty and hidden
// files, and a file named like the closing line.
void make_tree(const fs::path& root) {
  test::write_file(root / "atlas.yaml", "mmm_atlas: 1\nname: tiny\n");
  test::write_file(root / "meshes/femur_r/full.ply", awkward_bytes());
  test::write_file(root / "meshes/femur_r/lod1.ply", "ply\nformat binary_little_endian 1.0\n");
  test::write_file(root / "meshes/tibia_r/lod2.ply", "");
  test::write_file(root / ".hidden", "x");
  test::write_file(root / "end", "end\n");
  fs::create_directories(root / "empty/folder");
}

// Every path below `dir`, relative, sorted: folders end with '/'.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> paths;
  if (!fs::exists(dir)) return paths;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    std::string relative = entry.path().lexically_relative(dir).generic_string();
    if (entry.is_directory() && !entry.is_symlink()) relative += "/";
    paths.push_back(relative);
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(DirectoryBundleTest, WritesTheDocumentedFormat) {
  const test::ScratchDir scratch("bundle-format");
  test::write_file(scratch / "b.txt", "hi\n");
  test::write_file(scratch / "a/c", "");
  EXPECT_EQ(pack_directory(scratch.path()), "mmm-bundle 1\n0 a/c\n3 b.txt\nhi\nend\n");
}

TEST(DirectoryBundleTest, AnEmptyFolderIsJustTheFirstAndLastLine) {
  const test::ScratchDir scratch("bundle-empty");
  fs::create_directories(scratch / "in/only/folders");
  const std::string bundle = pack_directory(scratch / "in");
  EXPECT_EQ(bundle, "mmm-bundle 1\nend\n");
  unpack_directory(bundle, scratch / "out", "empty");
  EXPECT_TRUE(fs::is_directory(scratch / "out"));
  EXPECT_TRUE(listing(scratch / "out").empty());
}

TEST(DirectoryBundleTest, RoundTripRestoresEveryFileByteForByte) {
  const test::ScratchDir scratch("bundle-roundtrip");
  make_tree(scratch / "in");
  const std::string bundle = pack_directory(scratch / "in");
  unpack_directory(bundle, scratch / "out", "atlas");

  EXPECT_THAT(listing(scratch / "out"),
              ElementsAre(".hidden", "atlas.yaml", "end", "meshes/", "meshes/femur_r/",
                          "meshes/femur_r/full.ply", "meshes/femur_r/lod1.ply", "meshes/tibia_r/",
                          "meshes/tibia_r/lod2.ply"));
  EXPECT_EQ(test::read_text(scratch / "out/meshes/femur_r/full.ply"), awkward_bytes());
  EXPECT_EQ(test::read_text(scratch / "out/meshes/tibia_r/lod2.ply"), "");
  EXPECT_EQ(test::read_text(scratch / "out/end"), "end\n");
  // Packing the copy gives the same bytes: nothing was lost or added.
  EXPECT_EQ(pack_directory(scratch / "out"), bundle);
}

TEST(DirectoryBundleTest, ListsAndExtractsSingleFiles) {
  const test::ScratchDir scratch("bundle-files");
  make_tree(scratch.path());
  const std::string bundle = pack_directory(scratch.path());
  EXPECT_THAT(bundle_file_names(bundle, "atlas"),
              ElementsAre(".hidden", "atlas.yaml", "end", "meshes/femur_r/full.ply",
                          "meshes/femur_r/lod1.ply", "meshes/tibia_r/lod2.ply"));
  EXPECT_EQ(bundle_file(bundle, "meshes/femur_r/full.ply", "atlas"), awkward_bytes());
  EXPECT_EQ(bundle_file(bundle, "meshes/tibia_r/lod2.ply", "atlas"), "");
  try {
    (void)bundle_file(bundle, "atlas.yml", "study input 'atlas'");
    FAIL() << "no error";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("study input 'atlas'"));
    EXPECT_THAT(error.what(), HasSubstr("no file 'atlas.yml'"));
    EXPECT_THAT(error.what(), HasSubstr("did you mean 'atlas.yaml'"));
  }
}

TEST(DirectoryBundleTest, SameContentGivesSameBytesWhateverTheHistory) {
  const test::ScratchDir scratch("bundle-determinism");
  make_tree(scratch / "first");
  // The same files created in the opposite order, with other times and modes.
  const fs::path second = scratch / "second";
  fs::create_directories(second / "empty/folder");
  test::write_file(second / "end", "end\n");
  test::write_file(second / ".hidden", "x");
  test::write_file(second / "meshes/tibia_r/lod2.ply", "");
  test::write_file(second / "meshes/femur_r/lod1.ply", "ply\nformat binary_little_endian 1.0\n");
  test::write_file(second / "meshes/femur_r/full.ply", awkward_bytes());
  test::write_file(second / "atlas.yaml", "mmm_atlas: 1\nname: tiny\n");
  fs::last_write_time(second / "atlas.yaml",
                      fs::last_write_time(second / "atlas.yaml") - std::chrono::hours(48));
  fs::permissions(second / ".hidden", fs::perms::owner_read);

  EXPECT_EQ(pack_directory(scratch / "first"), pack_directory(second));
}

TEST(DirectoryBundleTest, FollowsLinksToFilesInsideTheFolder) {
  const test::ScratchDir scratch("bundle-link-inside");
  test::write_file(scratch / "in/meshes/real.ply", "bytes");
  fs::create_symlink("meshes/real.ply", scratch / "in/alias.ply");
  EXPECT_EQ(bundle_file(pack_directory(scratch / "in"), "alias.ply", "t"), "bytes");
}

TEST(DirectoryBundleTest, PackingRefusesWhatItCannotRecordFaithfully) {
  const test::ScratchDir scratch("bundle-pack-errors");
  test::write_file(scratch / "outside.txt", "secret");
  test::write_file(scratch / "plain_file", "x");
  const auto expect_io_error = [](const fs::path& dir, const std::string& fragment) {
    try {
      (void)pack_directory(dir);
      ADD_FAILURE() << "no error for " << dir;
    } catch (const IoError& error) {
      EXPECT_THAT(error.what(), HasSubstr(fragment));
    }
  };
  expect_io_error(scratch / "missing", "no such folder");
  expect_io_error(scratch / "plain_file", "is not a folder");

  test::write_file(scratch / "out_link/a.txt", "a");
  fs::create_symlink(scratch / "outside.txt", scratch / "out_link/leak.txt");
  expect_io_error(scratch / "out_link", "outside the folder");

  fs::create_directories(scratch / "dangling");
  fs::create_symlink("nowhere.txt", scratch / "dangling/broken.txt");
  expect_io_error(scratch / "dangling", "broken.txt");

  fs::create_directories(scratch / "folder_link/sub");
  fs::create_directory_symlink(".", scratch / "folder_link/sub/loop");
  expect_io_error(scratch / "folder_link", "link to a folder");

  test::write_file(scratch / "backslash/a\\b", "x");
  expect_io_error(scratch / "backslash", "backslash");
}

// ---- malformed bundles ------------------------------------------------------

class MalformedBundleTest : public ::testing::Test {
 protected:
  // Unpacking `bundle` fails with InvalidInputError naming the bundle and
  // containing `fragment`, and nothing at all appears in the scratch folder
  // (the target folder's parent).
  void expect_rejected(const std::string& bundle, const std::string& fragment) {
    SCOPED_TRACE(::testing::PrintToString(bundle));
    try {
      unpack_directory(bundle, scratch_ / "box/out", "test bundle");
      ADD_FAILURE() << "no error";
    } catch (const InvalidInputError& error) {
      EXPECT_THAT(error.what(), HasSubstr("test bundle"));
      EXPECT_THAT(error.what(), HasSubstr(fragment));
    }
    EXPECT_THROW((void)bundle_file_names(bundle, "test bundle"), InvalidInputError);
    EXPECT_TRUE(listing(scratch_.path()).empty());
  }

  test::ScratchDir scratch_{"bundle-malformed"};
};

TEST_F(MalformedBundleTest, EveryTruncationIsRejected) {
  const test::ScratchDir source("bundle-truncation");
  test::write_file(source / "a.txt", "first\n");
  test::write_file(source / "b/c.bin", std::string("\0\n\0", 3));
  test::write_file(source / "d", "");
  const std::string bundle = pack_directory(source.path());
  for (std::size_t length = 0; length < bundle.size(); ++length) {
    expect_rejected(bundle.substr(0, length), "");
  }
  // A few cuts with the reason they give.
  expect_rejected("mmm-bun", "no line break");
  expect_rejected("mmm-bundle 1\n",
                  "entry 1 at byte offset 13: the bundle ends without its "
                  "closing 'end' line");
  expect_rejected("mmm-bundle 1\n6 a.txt\nfir", "6 bytes runs past the end of the bundle (3 bytes");
  expect_rejected("mmm-bundle 1\n6 a.txt\nfirst\n", "entry 2 at byte offset 27");
  expect_rejected("mmm-bundle 1\nen", "without its closing 'end' line");
}

TEST_F(MalformedBundleTest, PathsThatLeaveTheTargetAreRejected) {
  expect_rejected("mmm-bundle 1\n1 ../x\nxend\n", "unsafe path '../x'");
  expect_rejected("mmm-bundle 1\n1 a/../../x\nxend\n", "'..' component");
  expect_rejected("mmm-bundle 1\n1 /abs\nxend\n", "absolute");
  expect_rejected("mmm-bundle 1\n1 a//b\nxend\n", "empty component");
  expect_rejected("mmm-bundle 1\n1 a/\nxend\n", "empty component");
  expect_rejected("mmm-bundle 1\n1 a/./b\nxend\n", "'.' component");
  expect_rejected("mmm-bundle 1\n1 ..\\x\nxend\n", "backslash");
  expect_rejected("mmm-bundle 1\n1 \nxend\n", "empty");
  expect_rejected(std::string("mmm-bundle 1\n1 a\0b\nxend\n", 24), "control character");
}

TEST_F(MalformedBundleTest, RepeatedOrMisplacedPathsAreRejected) {
  expect_rejected("mmm-bundle 1\n1 a\nx1 a\nyend\n", "entry 2 at byte offset 18: repeats the path");
  expect_rejected("mmm-bundle 1\n1 b\nx1 a\nyend\n", "paths must be in bytewise order");
  expect_rejected("mmm-bundle 1\n1 a\nx1 a-b\ny1 a/b\nzend\n", "needs 'a' to be a folder");
}

TEST_F(MalformedBundleTest, BadFirstLinesHeadersAndEndingsAreRejected) {
  expect_rejected("", "no line break");
  expect_rejected("mmm-bundel 1\nend\n", "first line: expected 'mmm-bundle 1'");
  expect_rejected("mmm-bundle 2\nend\n", "unsupported format version '2'");
  expect_rejected("mmm-bundle 1\r\nend\n", "expected 'mmm-bundle 1'");
  expect_rejected("mmm-bundle 1\nabc\nend\n", "malformed header line 'abc'");
  expect_rejected("mmm-bundle 1\n-1 a\nend\n", "malformed size '-1'");
  expect_rejected("mmm-bundle 1\n01 a\nxend\n", "malformed size '01'");
  expect_rejected("mmm-bundle 1\n1x a\nxend\n", "malformed size");
  expect_rejected("mmm-bundle 1\n99999999999999999999999 a\nend\n", "too large");
  expect_rejected("mmm-bundle 1\n18446744073709551615 a\nend\n", "runs past the end");
  expect_rejected("mmm-bundle 1\nend\nx", "1 byte(s) follow the closing 'end' line");
  expect_rejected("mmm-bundle 1\nend\n\n", "follow the closing 'end' line");
  expect_rejected("mmm-bundle 1\n1 a\nxEND\n", "entry 2 at byte offset 18: malformed header line");
}

TEST(DirectoryBundleTest, UnpackingNeverWritesThroughALinkInTheTarget) {
  const test::ScratchDir scratch("bundle-target-link");
  fs::create_directories(scratch / "elsewhere");
  fs::create_directories(scratch / "target");
  fs::create_directory_symlink(scratch / "elsewhere", scratch / "target/meshes");
  EXPECT_THROW(unpack_directory("mmm-bundle 1\n1 meshes/x\nxend\n", scratch / "target", "t"),
               IoError);
  EXPECT_TRUE(listing(scratch / "elsewhere").empty());
}

}  // namespace
}  // namespace mmm
