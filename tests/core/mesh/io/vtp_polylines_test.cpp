#include "core/mesh/io/vtp_polylines.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/vtp.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Two fibres sharing their origin point 0 and an action line of 4 points;
// point 7 belongs to no line. Coordinates that short decimal text would round
// (1/3, pi, a denormal), so that exact equality proves full precision.
Polylines make_fibres() {
  Polylines polylines;
  polylines.points.resize(8, 3);
  polylines.points << 0.0, 0.0, 0.0,   //
      1.0 / 3.0, 2.0 / 3.0, 1e-300,    //
      -12.5, 3.1415926535897931, 7.0,  //
      10.0, 20.0, 30.0,                //
      0.1, 0.2, 0.3,                   //
      -1e17, 5.0e-324, 42.0,           //
      2.0, 2.0, 2.0,                   //
      9.0, 9.0, 9.0;
  polylines.lines = {{0, 1, 2}, {0, 3}, {4, 5, 6, 1}};
  return polylines;
}

// Numbers of a DataArray's text, parsed independently of the reader.
std::vector<double> array_values(const tinyxml2::XMLElement& array) {
  std::vector<double> values;
  std::istringstream text(array.GetText() != nullptr ? array.GetText() : "");
  for (std::string token; text >> token;) values.push_back(std::stod(token));
  return values;
}

TEST(VtpPolylinesTest, RoundTripIsExact) {
  test::ScratchDir scratch("vtp-polylines");
  const Polylines fibres = make_fibres();
  write_vtp_polylines(fibres, scratch / "fibres.vtp");
  const Polylines read = read_vtp_polylines(scratch / "fibres.vtp");
  // Shortest round-trip text: every double comes back bit for bit.
  EXPECT_EQ(read.points, fibres.points);
  EXPECT_EQ(read.lines, fibres.lines);
}

TEST(VtpPolylinesTest, ArraysAppearAsPointAndCellData) {
  test::ScratchDir scratch("vtp-polylines");
  const Polylines fibres = make_fibres();
  VtpArrays arrays;
  arrays.point_scalars.emplace_back("activation", Eigen::VectorXd::LinSpaced(8, 0.0, 1.0));
  arrays.point_scalars.emplace_back("strain", Eigen::VectorXd::Constant(8, 1.0 / 3.0));
  arrays.cell_scalars.emplace_back("fibre<id>", Eigen::VectorXd::LinSpaced(3, 0.0, 2.0));
  write_vtp_polylines(fibres, scratch / "fibres.vtp", arrays);

  const std::string text = test::read_text(scratch / "fibres.vtp");
  EXPECT_THAT(text, HasSubstr("<VTKFile type=\"PolyData\" version=\"1.0\" "
                              "byte_order=\"LittleEndian\" header_type=\"UInt64\">"));
  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.Parse(text.c_str()), tinyxml2::XML_SUCCESS);
  const auto* piece =
      document.RootElement()->FirstChildElement("PolyData")->FirstChildElement("Piece");
  ASSERT_NE(piece, nullptr);
  EXPECT_EQ(piece->IntAttribute("NumberOfPoints"), 8);
  EXPECT_EQ(piece->IntAttribute("NumberOfLines"), 3);
  EXPECT_EQ(piece->IntAttribute("NumberOfPolys"), 0);

  const auto* point_data = piece->FirstChildElement("PointData");
  ASSERT_NE(point_data, nullptr);
  EXPECT_STREQ(point_data->Attribute("Scalars"), "activation");
  int point_arrays = 0;
  for (const auto* array = point_data->FirstChildElement("DataArray"); array != nullptr;
       array = array->NextSiblingElement("DataArray"), ++point_arrays) {
    EXPECT_EQ(array_values(*array).size(), 8U) << array->Attribute("Name");
  }
  EXPECT_EQ(point_arrays, 2);

  const auto* cell_data = piece->FirstChildElement("CellData");
  ASSERT_NE(cell_data, nullptr);
  const auto* cell_array = cell_data->FirstChildElement("DataArray");
  ASSERT_NE(cell_array, nullptr);
  EXPECT_STREQ(cell_array->Attribute("Name"), "fibre<id>");  // escaped in the file, intact here
  EXPECT_EQ(array_values(*cell_array), (std::vector<double>{0.0, 1.0, 2.0}));

  // VTK's layout: one end offset per line, connectivity in line order.
  const auto* lines = piece->FirstChildElement("Lines");
  ASSERT_NE(lines, nullptr);
  const auto* connectivity = lines->FirstChildElement("DataArray");
  const auto* offsets = connectivity->NextSiblingElement("DataArray");
  EXPECT_STREQ(connectivity->Attribute("Name"), "connectivity");
  EXPECT_EQ(array_values(*connectivity), (std::vector<double>{0, 1, 2, 0, 3, 4, 5, 6, 1}));
  EXPECT_STREQ(offsets->Attribute("Name"), "offsets");
  EXPECT_EQ(array_values(*offsets), (std::vector<double>{3, 5, 9}));
  EXPECT_EQ(read_vtp_polylines(scratch / "fibres.vtp").lines, fibres.lines);
}

// Each bad input names what is wrong and leaves no file behind.
void expect_invalid_polylines(const Polylines& polylines, const VtpArrays& arrays,
                              const std::string& message) {
  test::ScratchDir scratch("vtp-polylines");
  EXPECT_THAT([&] { write_vtp_polylines(polylines, scratch / "bad.vtp", arrays); },
              ThrowsMessage<InvalidInputError>(HasSubstr(message)));
  EXPECT_FALSE(std::filesystem::exists(scratch / "bad.vtp"));
}

TEST(VtpPolylinesTest, LineOfOnePointIsInvalidInput) {
  Polylines fibres = make_fibres();
  fibres.lines[1] = {3};
  expect_invalid_polylines(fibres, {}, "line 1 has 1 point(s); a polyline needs at least 2");
}

TEST(VtpPolylinesTest, IndexOutOfRangeIsInvalidInput) {
  Polylines fibres = make_fibres();
  fibres.lines[2].push_back(8);
  expect_invalid_polylines(fibres, {}, "line 2 refers to point 8 but there are 8 points");
  fibres.lines[2].back() = -1;
  expect_invalid_polylines(fibres, {}, "line 2 refers to point -1");
}

TEST(VtpPolylinesTest, NonFiniteCoordinateIsInvalidInput) {
  Polylines fibres = make_fibres();
  fibres.points(5, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_invalid_polylines(fibres, {}, "point 5 has a non-finite coordinate");
}

TEST(VtpPolylinesTest, NoLinesIsInvalidInput) {
  Polylines fibres = make_fibres();
  fibres.lines.clear();
  expect_invalid_polylines(fibres, {}, "there are no polylines");
}

TEST(VtpPolylinesTest, ArrayLengthMismatchIsInvalidInput) {
  const Polylines fibres = make_fibres();
  VtpArrays per_point;
  per_point.point_scalars.emplace_back("strain", Eigen::VectorXd::Ones(3));
  expect_invalid_polylines(
      fibres, per_point,
      "point array 'strain' has 3 values but the polylines have 8 points (one value "
      "per point)");
  VtpArrays per_line;
  per_line.cell_scalars.emplace_back("force", Eigen::VectorXd::Ones(8));
  expect_invalid_polylines(
      fibres, per_line,
      "cell array 'force' has 8 values but the polylines have 3 lines (one value "
      "per line)");
}

std::string two_piece_lines_vtp(const std::string& second_offsets) {
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "<PolyData>\n"
         "<Piece NumberOfPoints=\"3\" NumberOfLines=\"1\">\n"
         "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n"
         "0 0 0  1 0 0  2 0 0</DataArray></Points>\n"
         "<Lines><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2"
         "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3</DataArray>"
         "</Lines>\n"
         "</Piece>\n"
         "<Piece NumberOfPoints=\"2\" NumberOfLines=\"2\">\n"
         "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
         "0 1 0  0 2 0</DataArray></Points>\n"
         "<Lines><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 1 0"
         "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">" +
         second_offsets +
         "</DataArray></Lines>\n"
         "</Piece>\n"
         "</PolyData>\n"
         "</VTKFile>\n";
}

TEST(VtpPolylinesTest, PiecesAreConcatenatedAndLeadingZeroOffsetAccepted) {
  test::ScratchDir scratch("vtp-polylines");
  // VTK 9's in-memory offsets start with 0; files from older writers do not.
  const auto path = test::write_file(scratch / "pieces.vtp", two_piece_lines_vtp("0 2 4"));
  const Polylines read = read_vtp_polylines(path);
  ASSERT_EQ(read.points.rows(), 5);
  EXPECT_EQ(read.points.row(4), Eigen::RowVector3d(0, 2, 0));
  // Second piece's indices shifted by the 3 points of the first.
  EXPECT_EQ(read.lines, (std::vector<std::vector<int>>{{0, 1, 2}, {3, 4}, {4, 3}}));
}

TEST(VtpPolylinesTest, LineOfOnePointInFileIsIoError) {
  test::ScratchDir scratch("vtp-polylines");
  const auto path = test::write_file(scratch / "short.vtp", two_piece_lines_vtp("1 4"));
  EXPECT_THAT([&] { read_vtp_polylines(path); },
              ThrowsMessage<IoError>(HasSubstr(
                  "Piece 1 Lines cell 0 has 1 points (offsets must increase by at least 2)")));
}

TEST(VtpPolylinesTest, SurfaceFileHasNoPolylines) {
  test::ScratchDir scratch("vtp-polylines");
  write_vtp(make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), scratch / "box.vtp");
  EXPECT_THAT([&] { read_vtp_polylines(scratch / "box.vtp"); },
              ThrowsMessage<IoError>(HasSubstr("contains no polylines")));
  // ... and a polyline file is no surface.
  write_vtp_polylines(make_fibres(), scratch / "fibres.vtp");
  EXPECT_THAT([&] { read_vtp(scratch / "fibres.vtp"); },
              ThrowsMessage<IoError>(HasSubstr("contains no triangles")));
}

TEST(VtpPolylinesTest, MissingFileIsIoErrorNamingThePath) {
  test::ScratchDir scratch("vtp-polylines");
  EXPECT_THAT([&] { read_vtp_polylines(scratch / "absent.vtp"); },
              ThrowsMessage<IoError>(HasSubstr("absent.vtp: no such file")));
}

}  // namespace
}  // namespace mmm::mesh
