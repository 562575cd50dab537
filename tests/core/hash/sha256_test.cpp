#include "core/hash/sha256.h"

#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::hash {
namespace {

// Test vectors of the NIST "SHA-2 examples" (csrc.nist.gov, SHA256.pdf and
// the short/long message set): the exact digests, no tolerance.
TEST(Sha256Test, EmptyMessage) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256Test, Abc) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256Test, Nist448BitMessage) {
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256Test, Nist896BitMessage) {
  EXPECT_EQ(sha256_hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnop"
                       "jklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
}

TEST(Sha256Test, OneMillionA) {
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// A 200-byte message with every byte value pattern, split in two at every
// offset, and in many small irregular pieces: each must equal the one-shot
// digest, which exercises the partial-block buffer and both padding cases.
std::string two_hundred_bytes() {
  std::string message(200, '\0');
  for (std::size_t i = 0; i < message.size(); ++i) {
    message[i] = static_cast<char>((i * 37 + 11) % 256);
  }
  return message;
}

TEST(Sha256Test, SplitAtEveryOffsetEqualsOneShot) {
  const std::string message = two_hundred_bytes();
  const std::string expected = sha256_hex(message);
  const std::string_view view(message);
  for (std::size_t split = 0; split <= message.size(); ++split) {
    Sha256 hasher;
    hasher.update(view.substr(0, split));
    hasher.update(view.substr(split));
    EXPECT_EQ(to_hex(hasher.finish()), expected) << "split at " << split;
  }
}

TEST(Sha256Test, ByteByByteEqualsOneShot) {
  const std::string message = two_hundred_bytes();
  Sha256 hasher;
  for (const char byte : message) hasher.update(std::string_view(&byte, 1));
  EXPECT_EQ(to_hex(hasher.finish()), sha256_hex(message));
}

// Every message length 0..200 around the 55/56/64-byte padding boundaries:
// a prefix hashed in one go and in 3-byte pieces agree.
TEST(Sha256Test, EveryLengthAgreesAcrossPieceSizes) {
  const std::string message = two_hundred_bytes();
  for (std::size_t length = 0; length <= message.size(); ++length) {
    const std::string_view prefix = std::string_view(message).substr(0, length);
    Sha256 hasher;
    for (std::size_t at = 0; at < length; at += 3) hasher.update(prefix.substr(at, 3));
    EXPECT_EQ(to_hex(hasher.finish()), sha256_hex(prefix)) << "length " << length;
  }
}

TEST(Sha256Test, FinishResetsForTheNextMessage) {
  Sha256 hasher;
  hasher.update("some earlier message");
  (void)hasher.finish();
  hasher.update("abc");
  EXPECT_EQ(to_hex(hasher.finish()),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256Test, FileHashEqualsStringHash) {
  const test::ScratchDir dir("sha256");
  // Larger than the 1 MiB read block and not a multiple of it or of 64.
  std::string content(3 * 1024 * 1024 + 123, '\0');
  for (std::size_t i = 0; i < content.size(); ++i) {
    content[i] = static_cast<char>((i * 2654435761U) >> 13);
  }
  const auto path = test::write_file(dir / "blob.bin", content);
  EXPECT_EQ(sha256_file_hex(path), sha256_hex(content));
  const auto empty = test::write_file(dir / "empty.bin", "");
  EXPECT_EQ(sha256_file_hex(empty), sha256_hex(""));
}

TEST(Sha256Test, UnreadableFileThrowsIoErrorWithPath) {
  const test::ScratchDir dir("sha256");
  const auto missing = dir / "missing.bin";
  try {
    (void)sha256_file_hex(missing);
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), missing);
    EXPECT_NE(std::string(error.what()).find(missing.string()), std::string::npos);
  }
  // A directory opens but cannot be read.
  EXPECT_THROW((void)sha256_file_hex(dir.path()), IoError);
}

}  // namespace
}  // namespace mmm::hash
