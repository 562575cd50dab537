#include "core/mesh/io/ply.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Appends value in big-endian byte order, whatever this machine uses.
template <typename T>
void put_big_endian(std::string& out, T value) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), &value, sizeof(T));
  if (std::endian::native == std::endian::little) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

TEST(PlyTest, BinaryRoundTripIsExact) {
  test::ScratchDir scratch("ply");
  const IndexedMesh torus = make_torus(3.0, 1.0, 24, 12);
  write_ply(torus, scratch / "torus.ply");
  EXPECT_THAT(test::read_text(scratch / "torus.ply"), HasSubstr("format binary_little_endian 1.0"));
  const IndexedMesh read = read_ply(scratch / "torus.ply");
  // Doubles stored as doubles: bit-for-bit equal.
  EXPECT_EQ(read.V, torus.V);
  EXPECT_EQ(read.F, torus.F);
}

TEST(PlyTest, AsciiRoundTripIsExact) {
  test::ScratchDir scratch("ply");
  const IndexedMesh torus = make_torus(3.0, 1.0, 24, 12);
  write_ply(torus, scratch / "torus.ply", {.ascii = true});
  EXPECT_THAT(test::read_text(scratch / "torus.ply"), HasSubstr("format ascii 1.0"));
  const IndexedMesh read = read_ply(scratch / "torus.ply");
  // Shortest round-trip text: every double comes back bit for bit.
  EXPECT_EQ(read.V, torus.V);
  EXPECT_EQ(read.F, torus.F);
}

TEST(PlyTest, ReadsHandWrittenBigEndianWithMixedTypesAndExtraElements) {
  std::string bytes =
      "ply\n"
      "format binary_big_endian 1.0\n"
      "comment hand-written: mixed scalar types, lists to skip, an edge element\n"
      "element vertex 5\n"
      "property float x\n"
      "property double y\n"
      "property short z\n"
      "property uchar red\n"
      "property list uchar float texcoord\n"
      "element edge 1\n"
      "property int vertex1\n"
      "property int vertex2\n"
      "element face 2\n"
      "property uchar flags\n"
      "property list ushort uint vertex_index\n"
      "property float quality\n"
      "end_header\n";
  const std::array<std::array<double, 3>, 5> points{
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}}};
  for (const auto& p : points) {
    put_big_endian(bytes, static_cast<float>(p[0]));
    put_big_endian(bytes, p[1]);
    put_big_endian(bytes, static_cast<std::int16_t>(p[2]));
    put_big_endian(bytes, std::uint8_t{200});
    put_big_endian(bytes, std::uint8_t{2});
    put_big_endian(bytes, 0.25F);
    put_big_endian(bytes, 0.75F);
  }
  put_big_endian(bytes, std::int32_t{0});  // the edge
  put_big_endian(bytes, std::int32_t{1});
  // A quad with flags and quality, then a triangle.
  put_big_endian(bytes, std::uint8_t{7});
  put_big_endian(bytes, std::uint16_t{4});
  for (const std::uint32_t index : {0U, 1U, 2U, 3U}) put_big_endian(bytes, index);
  put_big_endian(bytes, 1.5F);
  put_big_endian(bytes, std::uint8_t{0});
  put_big_endian(bytes, std::uint16_t{3});
  for (const std::uint32_t index : {0U, 1U, 4U}) put_big_endian(bytes, index);
  put_big_endian(bytes, 0.0F);

  test::ScratchDir scratch("ply");
  const IndexedMesh mesh = read_ply(test::write_file(scratch / "big.ply", bytes));
  Eigen::MatrixX3d expected_v(5, 3);
  expected_v << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1;
  Eigen::MatrixX3i expected_f(3, 3);
  expected_f << 0, 1, 2, 0, 2, 3, 0, 1, 4;
  EXPECT_EQ(mesh.V, expected_v);  // all values exactly representable
  EXPECT_EQ(mesh.F, expected_f);
}

TEST(PlyTest, ReadsHandWrittenAsciiWithIntegerCoordinatesAndExtraProperties) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "tetra.ply",
                                     "ply\n"
                                     "format ascii 1.0\n"
                                     "comment made by hand\n"
                                     "element vertex 4\n"
                                     "property int x\n"
                                     "property int y\n"
                                     "property int z\n"
                                     "property float confidence\n"
                                     "element face 2\n"
                                     "property list uchar int vertex_indices\n"
                                     "property uchar red\n"
                                     "end_header\n"
                                     "0 0 0 0.9\n"
                                     "1 0 0 0.8\n"
                                     "0 1 0 0.7\n"
                                     "0 0 1 0.6\n"
                                     "3 0 2 1 255\n"
                                     "3 0 1 3 128\n");
  const IndexedMesh mesh = read_ply(path);
  ASSERT_EQ(mesh.num_vertices(), 4);
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.V.row(3), Eigen::RowVector3d(0, 0, 1));
  EXPECT_EQ(mesh.F.row(1), Eigen::RowVector3i(0, 1, 3));
}

TEST(PlyTest, TruncatedBinaryIsReported) {
  test::ScratchDir scratch("ply");
  write_ply(make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), scratch / "box.ply");
  const std::string bytes = test::read_text(scratch / "box.ply");
  const auto path = test::write_file(scratch / "cut.ply", bytes.substr(0, bytes.size() - 6));
  EXPECT_THAT([&] { read_ply(path); }, ThrowsMessage<IoError>(HasSubstr("truncated binary PLY")));
  EXPECT_THAT([&] { read_ply(path); },
              ThrowsMessage<IoError>(HasSubstr("of face 11 (element 'face' announces 12)")));
}

TEST(PlyTest, AsciiValueThatIsNotANumberNamesLineAndProperty) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "bad.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 1\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
  EXPECT_THAT(
      [&] { read_ply(path); },
      ThrowsMessage<IoError>(HasSubstr("line 11: expected a number for property 'y' of vertex 1")));
}

TEST(PlyTest, UnsupportedTypeIsReported) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "bad.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 1\n"
                                     "property int64 x\nend_header\n0\n");
  EXPECT_THAT([&] { read_ply(path); },
              ThrowsMessage<IoError>(HasSubstr("line 4: unknown PLY property type 'int64'")));
}

TEST(PlyTest, FaceWithoutIndexListIsReported) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "bad.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 1\nproperty list uchar int corners\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_THAT([&] { read_ply(path); },
              ThrowsMessage<IoError>(HasSubstr("no list property 'vertex_indices'")));
}

TEST(PlyTest, IndexOutOfRangeIsReported) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "bad.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 2\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 7\n");
  EXPECT_THAT([&] { read_ply(path); },
              ThrowsMessage<IoError>(
                  HasSubstr("face 1 refers to vertex 7 but only 3 vertices are defined")));
}

TEST(PlyTest, NotAPlyFileIsReported) {
  test::ScratchDir scratch("ply");
  const auto path = test::write_file(scratch / "bad.ply", "solid x\nendsolid x\n");
  EXPECT_THAT([&] { read_ply(path); }, ThrowsMessage<IoError>(HasSubstr("not a PLY file")));
}

}  // namespace
}  // namespace mmm::mesh
