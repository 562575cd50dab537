#include "core/base64.h"

#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"

namespace mmm {
namespace {

TEST(Base64Test, EncodesTheRfc4648TestVectors) {
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foo"), "Zm9v");
  EXPECT_EQ(base64_encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64_encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
}

TEST(Base64Test, EveryByteValueRoundTrips) {
  std::string bytes;
  for (int i = 0; i < 256 * 3 + 1; ++i) bytes += static_cast<char>(i * 37 % 256);
  for (std::size_t n = 0; n < 7; ++n) {
    const std::string part = bytes.substr(0, bytes.size() - n);
    EXPECT_EQ(base64_decode(base64_encode(part), "test"), part);
  }
}

TEST(Base64Test, MalformedTextIsRejectedWithItsOffset) {
  EXPECT_THROW((void)base64_decode("Zm9", "image"), InvalidInputError);
  try {
    (void)base64_decode("Zm9v*mFy", "views[0].image");
    FAIL() << "no error";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("views[0].image"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("offset 4"), std::string::npos);
  }
  EXPECT_THROW((void)base64_decode("Zg=v", "x"), InvalidInputError);
  EXPECT_THROW((void)base64_decode("Zg==Zg==", "x"), InvalidInputError);
}

}  // namespace
}  // namespace mmm
