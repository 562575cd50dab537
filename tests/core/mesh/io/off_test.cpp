#include "core/mesh/io/off.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(OffTest, RoundTripIsExact) {
  test::ScratchDir scratch("off");
  const IndexedMesh torus = make_torus(2.5, 0.7, 20, 10);
  write_off(torus, scratch / "torus.off");
  const IndexedMesh read = read_off(scratch / "torus.off");
  // Shortest round-trip text: every double comes back bit for bit.
  EXPECT_EQ(read.V, torus.V);
  EXPECT_EQ(read.F, torus.F);
}

TEST(OffTest, ReadsCommentsColoursAndPolygons) {
  test::ScratchDir scratch("off");
  const auto path = test::write_file(scratch / "pyramid.off",
                                     "COFF\n"
                                     "# a square pyramid, coloured\n"
                                     "5 2 0\n"
                                     "0 0 0 255 0 0 255\n"
                                     "1 0 0 255 0 0 255\n"
                                     "\n"
                                     "1 1 0 255 0 0 255  # a comment after data\n"
                                     "0 1 0 255 0 0 255\n"
                                     "0.5 0.5 1 0 255 0 255\n"
                                     "4 3 2 1 0 0.5 0.5 0.5\n"
                                     "3 0 1 4\n");
  const IndexedMesh mesh = read_off(path);
  ASSERT_EQ(mesh.num_vertices(), 5);
  ASSERT_EQ(mesh.num_faces(), 3);  // the quad fanned into two triangles + one triangle
  Eigen::MatrixX3i expected(3, 3);
  expected << 3, 2, 1,  //
      3, 1, 0,          //
      0, 1, 4;
  EXPECT_EQ(mesh.F, expected);
  EXPECT_EQ(mesh.V.row(4), Eigen::RowVector3d(0.5, 0.5, 1.0));
}

TEST(OffTest, ReadsCountsOnTheKeywordLine) {
  test::ScratchDir scratch("off");
  const auto path =
      test::write_file(scratch / "tri.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_off(path).num_faces(), 1);
}

TEST(OffTest, IndexOutOfRangeNamesLineAndFace) {
  test::ScratchDir scratch("off");
  const auto path = test::write_file(scratch / "bad.off",
                                     "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 8\n");
  EXPECT_THAT([&] { read_off(path); },
              ThrowsMessage<IoError>(
                  HasSubstr("line 8: face 1 refers to vertex 8 but only 4 vertices are defined")));
}

TEST(OffTest, TruncatedFileSaysHowFarItGot) {
  test::ScratchDir scratch("off");
  const auto path = test::write_file(scratch / "cut.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n");
  EXPECT_THAT([&] { read_off(path); },
              ThrowsMessage<IoError>(HasSubstr("ends after 2 of the 4 announced vertices")));
}

TEST(OffTest, MissingCoordinateNamesTheLine) {
  test::ScratchDir scratch("off");
  const auto path =
      test::write_file(scratch / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n");
  EXPECT_THAT([&] { read_off(path); },
              ThrowsMessage<IoError>(HasSubstr("line 4: vertex 1 needs 3 coordinates")));
}

TEST(OffTest, BinaryOffIsRejected) {
  test::ScratchDir scratch("off");
  const auto path = test::write_file(scratch / "binary.off", "OFF BINARY\n\x01\x02");
  EXPECT_THAT([&] { read_off(path); },
              ThrowsMessage<IoError>(HasSubstr("binary OFF is not supported")));
}

TEST(OffTest, OtherFormatIsNotTakenForOff) {
  test::ScratchDir scratch("off");
  const auto path = test::write_file(scratch / "wrong.off", "ply\nformat ascii 1.0\n");
  EXPECT_THAT([&] { read_off(path); },
              ThrowsMessage<IoError>(HasSubstr("line 1: not an OFF file: expected the keyword OFF "
                                               "or the counts line, got 'ply'")));
}

}  // namespace
}  // namespace mmm::mesh
