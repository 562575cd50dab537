#include "core/mesh/io/stl.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// STL loses the vertex numbering: the welded result numbers vertices in
// first-occurrence order. Checks that `read` is `original` up to that
// renumbering: same faces in the same order, a one-to-one vertex map, and
// corner positions equal within `tolerance`.
void expect_same_surface(const IndexedMesh& original, const IndexedMesh& read, double tolerance) {
  ASSERT_EQ(read.num_faces(), original.num_faces());
  ASSERT_EQ(read.num_vertices(), original.num_vertices());
  std::vector<int> to_read(static_cast<std::size_t>(original.num_vertices()), -1);
  for (Eigen::Index f = 0; f < original.num_faces(); ++f) {
    for (Eigen::Index j = 0; j < 3; ++j) {
      const int o = original.F(f, j);
      const int r = read.F(f, j);
      int& mapped = to_read[static_cast<std::size_t>(o)];
      if (mapped < 0) mapped = r;
      ASSERT_EQ(mapped, r) << "face " << f << " corner " << j << " breaks the vertex map";
      ASSERT_LE((read.V.row(r) - original.V.row(o)).norm(), tolerance) << "vertex " << o;
    }
  }
  const std::set<int> distinct(to_read.begin(), to_read.end());
  EXPECT_EQ(static_cast<Eigen::Index>(distinct.size()), original.num_vertices());
}

// make_torus(3, 1, ...) has coordinates up to 4 in magnitude; float32 keeps
// 24 bits, so rounding moves a coordinate by at most 4 * 2^-24 = 2.4e-7 and a
// point by at most sqrt(3) times that.
constexpr double kFloatTolerance = 5e-7;

TEST(StlTest, BinaryRoundTripKeepsTopologyAndFloatPrecision) {
  test::ScratchDir scratch("stl");
  const IndexedMesh torus = make_torus(3.0, 1.0, 32, 16);
  write_stl(torus, scratch / "torus.stl");
  EXPECT_EQ(std::filesystem::file_size(scratch / "torus.stl"),
            84U + 50U * static_cast<std::uintmax_t>(torus.num_faces()));
  expect_same_surface(torus, read_stl(scratch / "torus.stl"), kFloatTolerance);
}

TEST(StlTest, AsciiRoundTripKeepsTopologyAndFloatPrecision) {
  test::ScratchDir scratch("stl");
  const IndexedMesh torus = make_torus(3.0, 1.0, 32, 16);
  write_stl(torus, scratch / "torus.stl", {.ascii = true});
  EXPECT_EQ(test::read_text(scratch / "torus.stl").substr(0, 5), "solid");
  expect_same_surface(torus, read_stl(scratch / "torus.stl"), kFloatTolerance);
}

TEST(StlTest, AsciiAndBinaryGiveTheSameFloats) {
  test::ScratchDir scratch("stl");
  const IndexedMesh torus = make_torus(3.0, 1.0, 12, 8);
  write_stl(torus, scratch / "binary.stl");
  write_stl(torus, scratch / "ascii.stl", {.ascii = true});
  const IndexedMesh binary = read_stl(scratch / "binary.stl");
  const IndexedMesh ascii = read_stl(scratch / "ascii.stl");
  EXPECT_EQ(binary.F, ascii.F);
  // ASCII holds the shortest text of each float, read back as a double: it
  // differs from the float itself by less than half a float ulp (2.4e-7 here).
  EXPECT_LE((binary.V - ascii.V).cwiseAbs().maxCoeff(), 2.4e-7);
  EXPECT_EQ(binary.V.cast<float>(), ascii.V.cast<float>());
}

TEST(StlTest, WeldsBoxCornersIntoEightVertices) {
  test::ScratchDir scratch("stl");
  const IndexedMesh box = make_box(Eigen::Vector3d(-1, -2, -3), Eigen::Vector3d(1, 2, 3));
  write_stl(box, scratch / "box.stl");
  const IndexedMesh read = read_stl(scratch / "box.stl");
  EXPECT_EQ(read.num_vertices(), 8);
  // Box corners are small integers: float32 holds them exactly.
  expect_same_surface(box, read, 0.0);
}

TEST(StlTest, MinusZeroWeldsWithPlusZero) {
  test::ScratchDir scratch("stl");
  const auto path = test::write_file(scratch / "zero.stl",
                                     "solid zero\n"
                                     "facet normal 0 0 1\n outer loop\n"
                                     "  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n"
                                     " endloop\nendfacet\n"
                                     "facet normal 0 0 -1\n outer loop\n"
                                     "  vertex -0 0 0\n  vertex 0 1 0\n  vertex 0 0 -1\n"
                                     " endloop\nendfacet\n"
                                     "endsolid zero\n");
  const IndexedMesh read = read_stl(path);
  EXPECT_EQ(read.num_faces(), 2);
  EXPECT_EQ(read.num_vertices(), 4);
  EXPECT_EQ(read.F(1, 0), read.F(0, 0));
}

TEST(StlTest, BinaryWhoseHeaderStartsWithSolidIsReadAsBinary) {
  test::ScratchDir scratch("stl");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  write_stl(box, scratch / "box.stl");
  std::string bytes = test::read_text(scratch / "box.stl");
  bytes.replace(0, 12, "solid header");
  const auto path = test::write_file(scratch / "solid_header.stl", bytes);
  EXPECT_EQ(read_stl(path).num_faces(), 12);
}

TEST(StlTest, TruncatedBinaryReportsAnnouncedAndActualSizes) {
  test::ScratchDir scratch("stl");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  write_stl(box, scratch / "box.stl");
  const std::string bytes = test::read_text(scratch / "box.stl");
  const auto path = test::write_file(scratch / "cut.stl", bytes.substr(0, 600));
  EXPECT_THAT([&] { read_stl(path); },
              ThrowsMessage<IoError>(
                  HasSubstr("truncated binary STL: header announces 12 triangles (expects 684 "
                            "bytes) but the file has 600 bytes")));
}

TEST(StlTest, NanCoordinateNamesTriangleAndVertex) {
  test::ScratchDir scratch("stl");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  write_stl(box, scratch / "box.stl");
  std::string bytes = test::read_text(scratch / "box.stl");
  // Triangle 3, vertex 1, y coordinate: record start + normal + one corner + x.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  constexpr std::size_t kOffset = 84 + 50 * 3 + 12 + 12 + 4;
  std::memcpy(bytes.data() + kOffset, &nan, sizeof(nan));
  const auto path = test::write_file(scratch / "nan.stl", bytes);
  EXPECT_THAT([&] { read_stl(path); },
              ThrowsMessage<IoError>(HasSubstr("triangle 3 vertex 1 has a non-finite coordinate")));
}

TEST(StlTest, AsciiNanCoordinateNamesLineTriangleAndVertex) {
  test::ScratchDir scratch("stl");
  const auto path = test::write_file(scratch / "nan.stl",
                                     "solid s\nfacet normal 0 0 1\nouter loop\n"
                                     "vertex 0 0 0\nvertex 1 nan 0\nvertex 0 1 0\n"
                                     "endloop\nendfacet\nendsolid s\n");
  EXPECT_THAT(
      [&] { read_stl(path); },
      ThrowsMessage<IoError>(HasSubstr("line 5: triangle 0 vertex 1 has a non-finite coordinate")));
}

TEST(StlTest, AsciiSyntaxErrorNamesTheLine) {
  test::ScratchDir scratch("stl");
  const auto path = test::write_file(scratch / "bad.stl",
                                     "solid s\nfacet normal 0 0 1\nouter loop\n"
                                     "vertex 0 0 0\nvertex 1 0\nvertex 0 1 0\n"
                                     "endloop\nendfacet\nendsolid s\n");
  EXPECT_THAT([&] { read_stl(path); },
              ThrowsMessage<IoError>(HasSubstr("line 6: ASCII STL expects a coordinate, got "
                                               "'vertex'")));
}

TEST(StlTest, WritingRejectsMeshWithoutFaces) {
  test::ScratchDir scratch("stl");
  IndexedMesh empty;
  empty.V = Eigen::MatrixX3d::Zero(3, 3);
  EXPECT_THAT([&] { write_stl(empty, scratch / "empty.stl"); },
              ThrowsMessage<InvalidInputError>(HasSubstr("the mesh has no triangles")));
  EXPECT_FALSE(std::filesystem::exists(scratch / "empty.stl"));
}

// Counts "endfacet" keywords: the number of facets of an ASCII STL, found
// independently of the reader.
std::size_t count_ascii_facets(const std::string& text) {
  std::size_t count = 0;
  for (std::size_t pos = text.find("endfacet"); pos != std::string::npos;
       pos = text.find("endfacet", pos + 8)) {
    ++count;
  }
  return count;
}

TEST(StlTest, EveryVhfSurfaceLoadsWelded) {
  int files = 0;
  int ascii_files = 0;
  for (const char* side : {"Left", "Right"}) {
    for (const auto& entry : std::filesystem::directory_iterator(test::data_dir() / "vhf" / side)) {
      if (entry.path().extension() != ".stl") continue;
      SCOPED_TRACE(entry.path().string());
      ++files;
      const IndexedMesh mesh = read_stl(entry.path());
      ASSERT_GT(mesh.num_faces(), 0);
      // Welding shares corners: a closed triangle mesh has about half as many
      // vertices as faces, an unwelded one three times as many.
      EXPECT_LT(mesh.num_vertices(), mesh.num_faces());
      const std::string bytes = test::read_text(entry.path());
      if (bytes.compare(0, 5, "solid") == 0 && bytes.find('\0') == std::string::npos) {
        ++ascii_files;
        EXPECT_EQ(static_cast<std::size_t>(mesh.num_faces()), count_ascii_facets(bytes));
      } else {
        EXPECT_EQ(static_cast<std::uintmax_t>(mesh.num_faces()), (entry.file_size() - 84) / 50);
      }
    }
  }
  EXPECT_GE(files, 30);       // 3 left + 31 right surfaces in the shared copy
  EXPECT_EQ(ascii_files, 1);  // BicepsFemorisShortHead
}

}  // namespace
}  // namespace mmm::mesh
