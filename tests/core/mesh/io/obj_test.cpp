#include "core/mesh/io/obj.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(ObjTest, RoundTripIsExact) {
  test::ScratchDir scratch("obj");
  const IndexedMesh torus = make_torus(3.0, 1.0, 24, 12);
  write_obj(torus, scratch / "torus.obj");
  const IndexedMesh read = read_obj(scratch / "torus.obj");
  // Shortest round-trip text: every double comes back bit for bit.
  EXPECT_EQ(read.V, torus.V);
  EXPECT_EQ(read.F, torus.F);
}

TEST(ObjTest, ReadsSlashFormsNegativeIndicesAndPolygons) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "square.obj",
                                     "# a unit square and a triangle\n"
                                     "mtllib square.mtl\n"
                                     "o square\n"
                                     "v 0 0 0\n"
                                     "v 1 0 0\n"
                                     "v 1 1 0 1.0\n"
                                     "v 0 1 0\n"
                                     "vt 0 0\n"
                                     "vn 0 0 1\n"
                                     "g group\n"
                                     "usemtl skin\n"
                                     "s off\n"
                                     "f 1/1/1 2/1/1 3/1/1\n"
                                     "f -4//-1 -2//-1 -1//-1  # relative indices\n"
                                     "v 0.5 0.5 1\n"
                                     "f 1/1 2/1 5/1 4/1\n");
  const IndexedMesh mesh = read_obj(path);
  ASSERT_EQ(mesh.num_vertices(), 5);
  ASSERT_EQ(mesh.num_faces(), 4);  // two triangles + a quad split in two
  Eigen::MatrixX3i expected(4, 3);
  expected << 0, 1, 2,  //
      0, 2, 3,          // -4, -2, -1 with 4 vertices defined
      0, 1, 4,          // quad 1 2 5 4 fanned from its first corner
      0, 4, 3;
  EXPECT_EQ(mesh.F, expected);
  EXPECT_EQ(mesh.V.row(4), Eigen::RowVector3d(0.5, 0.5, 1.0));
}

TEST(ObjTest, OutOfRangeFaceIndexNamesLineAndVertexCount) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "bad.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                     "f 1 2 3\nf 1 2 9\n");
  EXPECT_THAT([&] { read_obj(path); },
              ThrowsMessage<IoError>(
                  HasSubstr("line 6: face refers to vertex 9 but only 4 vertices are defined")));
}

TEST(ObjTest, NegativeIndexReachingBeforeTheFirstVertexIsReported) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "bad.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n");
  EXPECT_THAT([&] { read_obj(path); },
              ThrowsMessage<IoError>(
                  HasSubstr("line 3: face refers to vertex -3 but only 2 vertices are defined")));
}

TEST(ObjTest, ZeroIndexIsRejected) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  EXPECT_THAT([&] { read_obj(path); },
              ThrowsMessage<IoError>(HasSubstr("line 4: face refers to vertex 0")));
}

TEST(ObjTest, VertexWithTwoCoordinatesIsRejected) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "bad.obj", "v 0 0 0\nv 1 0\n");
  EXPECT_THAT([&] { read_obj(path); },
              ThrowsMessage<IoError>(HasSubstr("line 2: vertex 2 needs 3 coordinates")));
}

TEST(ObjTest, DegenerateFaceIsKept) {
  test::ScratchDir scratch("obj");
  const auto path =
      test::write_file(scratch / "degenerate.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n");
  const IndexedMesh mesh = read_obj(path);
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.F.row(1), Eigen::RowVector3i(0, 0, 1));
}

TEST(ObjTest, VerticesWithoutFacesAreNotAMesh) {
  test::ScratchDir scratch("obj");
  const auto path = test::write_file(scratch / "points.obj", "v 0 0 0\nv 1 0 0\n");
  EXPECT_THAT([&] { read_obj(path); }, ThrowsMessage<IoError>(HasSubstr("contains no triangles")));
}

}  // namespace
}  // namespace mmm::mesh
