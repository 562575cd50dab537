#include "core/mesh/io/vtp.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(VtpTest, RoundTripIsExact) {
  test::ScratchDir scratch("vtp");
  const IndexedMesh torus = make_torus(3.0, 1.0, 24, 12);
  write_vtp(torus, scratch / "torus.vtp");
  const IndexedMesh read = read_vtp(scratch / "torus.vtp");
  // Shortest round-trip text: every double comes back bit for bit.
  EXPECT_EQ(read.V, torus.V);
  EXPECT_EQ(read.F, torus.F);
}

TEST(VtpTest, WritesParaViewHeaderAndScalarArrays) {
  test::ScratchDir scratch("vtp");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 2, 3));
  VtpArrays arrays;
  arrays.point_scalars.emplace_back("height", box.V.col(2));
  arrays.point_scalars.emplace_back("one third", Eigen::VectorXd::Constant(8, 1.0 / 3.0));
  arrays.cell_scalars.emplace_back("face<id>", Eigen::VectorXd::LinSpaced(12, 0, 11));
  write_vtp(box, scratch / "box.vtp", arrays);

  const std::string text = test::read_text(scratch / "box.vtp");
  EXPECT_THAT(text, HasSubstr("<VTKFile type=\"PolyData\" version=\"1.0\" "
                              "byte_order=\"LittleEndian\" header_type=\"UInt64\">"));
  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.Parse(text.c_str()), tinyxml2::XML_SUCCESS);
  const auto* piece =
      document.RootElement()->FirstChildElement("PolyData")->FirstChildElement("Piece");
  ASSERT_NE(piece, nullptr);
  EXPECT_EQ(piece->IntAttribute("NumberOfPoints"), 8);
  EXPECT_EQ(piece->IntAttribute("NumberOfPolys"), 12);

  const auto* point_data = piece->FirstChildElement("PointData");
  ASSERT_NE(point_data, nullptr);
  EXPECT_STREQ(point_data->Attribute("Scalars"), "height");
  const auto* third = point_data->FirstChildElement("DataArray")->NextSiblingElement("DataArray");
  ASSERT_NE(third, nullptr);
  EXPECT_STREQ(third->Attribute("Name"), "one third");
  std::istringstream values(third->GetText());
  int count = 0;
  for (std::string token; values >> token; ++count) {
    // max_digits10-style output: the double 1/3 comes back exactly.
    EXPECT_EQ(std::stod(token), 1.0 / 3.0);
  }
  EXPECT_EQ(count, 8);

  const auto* cell_array = piece->FirstChildElement("CellData")->FirstChildElement("DataArray");
  ASSERT_NE(cell_array, nullptr);
  EXPECT_STREQ(cell_array->Attribute("Name"), "face<id>");  // escaped in the file, intact here

  const auto* polys = piece->FirstChildElement("Polys");
  ASSERT_NE(polys, nullptr);
  EXPECT_STREQ(polys->FirstChildElement("DataArray")->Attribute("type"), "Int64");
  EXPECT_EQ(read_vtp(scratch / "box.vtp").F, box.F);
}

TEST(VtpTest, ArrayLengthMismatchIsInvalidInput) {
  test::ScratchDir scratch("vtp");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  VtpArrays arrays;
  arrays.cell_scalars.emplace_back("area", Eigen::VectorXd::Ones(8));
  EXPECT_THAT([&] { write_vtp(box, scratch / "box.vtp", arrays); },
              ThrowsMessage<InvalidInputError>(
                  HasSubstr("cell array 'area' has 8 values but the mesh has 12 triangles")));
  EXPECT_FALSE(std::filesystem::exists(scratch / "box.vtp"));
}

std::string one_triangle_vtp(const std::string& points_format) {
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <PolyData>\n"
         "    <Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\">\n"
         "      <Points>\n"
         "        <DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"" +
         points_format +
         "\">\n"
         "          0 0 0 1 0 0 0 1 0\n"
         "        </DataArray>\n"
         "      </Points>\n"
         "      <Polys>\n"
         "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2"
         "</DataArray>\n"
         "        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3</DataArray>\n"
         "      </Polys>\n"
         "    </Piece>\n"
         "  </PolyData>\n"
         "</VTKFile>\n";
}

TEST(VtpTest, HandWrittenAsciiTriangleIsRead) {
  test::ScratchDir scratch("vtp");
  const auto path = test::write_file(scratch / "tri.vtp", one_triangle_vtp("ascii"));
  const IndexedMesh mesh = read_vtp(path);
  EXPECT_EQ(mesh.num_vertices(), 3);
  EXPECT_EQ(mesh.F.row(0), Eigen::RowVector3i(0, 1, 2));
}

TEST(VtpTest, BinaryDataArrayIsRejectedWithAHint) {
  test::ScratchDir scratch("vtp");
  const auto path = test::write_file(scratch / "binary.vtp", one_triangle_vtp("binary"));
  EXPECT_THAT([&] { read_vtp(path); }, ThrowsMessage<IoError>(HasSubstr("only ASCII VTP is read")));
  EXPECT_THAT([&] { read_vtp(path); },
              ThrowsMessage<IoError>(HasSubstr("Re-save the file with the ASCII data mode")));
}

TEST(VtpTest, MalformedXmlIsReported) {
  test::ScratchDir scratch("vtp");
  std::string text = one_triangle_vtp("ascii");
  text.erase(text.find("</Points>"), 9);
  const auto path = test::write_file(scratch / "broken.vtp", text);
  EXPECT_THAT([&] { read_vtp(path); }, ThrowsMessage<IoError>(HasSubstr("malformed XML at line")));
}

TEST(VtpTest, PointCountMismatchIsReported) {
  test::ScratchDir scratch("vtp");
  std::string text = one_triangle_vtp("ascii");
  text.replace(text.find("NumberOfPoints=\"3\""), 18, "NumberOfPoints=\"4\"");
  const auto path = test::write_file(scratch / "count.vtp", text);
  EXPECT_THAT([&] { read_vtp(path); },
              ThrowsMessage<IoError>(HasSubstr(
                  "Piece 0 Points DataArray holds 9 numbers, expected 3 x 4 (NumberOfPoints)")));
}

TEST(VtpTest, PiecesAreConcatenatedAndStripsSplit) {
  test::ScratchDir scratch("vtp");
  const auto path = test::write_file(
      scratch / "pieces.vtp",
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      "<PolyData>\n"
      "<Piece NumberOfPoints=\"4\" NumberOfPolys=\"1\">\n"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "0 0 0  1 0 0  1 1 0  0 1 0</DataArray></Points>\n"
      "<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3"
      "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray>"
      "</Polys>\n"
      "</Piece>\n"
      "<Piece NumberOfPoints=\"5\" NumberOfStrips=\"1\">\n"
      "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "0 0 1  1 0 1  0 1 1  1 1 1  0 2 1</DataArray></Points>\n"
      "<Strips><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4"
      "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">5</DataArray>"
      "</Strips>\n"
      "</Piece>\n"
      "</PolyData>\n"
      "</VTKFile>\n");
  const IndexedMesh mesh = read_vtp(path);
  ASSERT_EQ(mesh.num_vertices(), 9);
  Eigen::MatrixX3i expected(5, 3);
  expected << 0, 1, 2,  // quad fanned
      0, 2, 3,          //
      4, 5, 6,          // strip 0 1 2 3 4 of the second piece, shifted by 4,
      6, 5, 7,          // every odd triangle flipped to keep the orientation
      6, 7, 8;
  EXPECT_EQ(mesh.F, expected);
  // All five triangles face +z: the strip split kept one orientation.
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
    EXPECT_GT((b - a).cross(c - a).z(), 0.0) << "triangle " << f;
  }
}

// Triangles a fan split of the Polys gives, computed from the offsets array
// with tinyxml2 directly (independently of read_vtp): sum of (corners - 2).
struct PolysSummary {
  int points = 0;
  int polys = 0;
  int fan_triangles = 0;
};

PolysSummary summarize_polys(const std::filesystem::path& path) {
  tinyxml2::XMLDocument document;
  EXPECT_EQ(document.LoadFile(path.c_str()), tinyxml2::XML_SUCCESS);
  const auto* piece =
      document.RootElement()->FirstChildElement("PolyData")->FirstChildElement("Piece");
  PolysSummary summary;
  summary.points = piece->IntAttribute("NumberOfPoints");
  summary.polys = piece->IntAttribute("NumberOfPolys");
  for (const auto* array = piece->FirstChildElement("Polys")->FirstChildElement("DataArray");
       array != nullptr; array = array->NextSiblingElement("DataArray")) {
    if (std::string(array->Attribute("Name")) != "offsets") continue;
    std::istringstream offsets(array->GetText());
    int previous = 0;
    for (int end = 0; offsets >> end; previous = end) summary.fan_triangles += end - previous - 2;
  }
  return summary;
}

TEST(VtpTest, EveryGait2392GeometryLoads) {
  const std::filesystem::path folder = test::data_dir() / "gait2392" / "Geometry";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".vtp") continue;
    SCOPED_TRACE(entry.path().string());
    ++files;
    const IndexedMesh mesh = read_vtp(entry.path());
    ASSERT_GT(mesh.num_faces(), 0);
    const PolysSummary summary = summarize_polys(entry.path());
    EXPECT_EQ(mesh.num_vertices(), summary.points);
    EXPECT_EQ(mesh.num_faces(), summary.fan_triangles);
  }
  EXPECT_EQ(files, 10);

  // The files with quads (the README names fibula, foot and bofoot; sacrum
  // has them too) give more triangles than polygons.
  for (const char* name : {"fibula.vtp", "foot.vtp", "bofoot.vtp", "sacrum.vtp"}) {
    EXPECT_GT(read_vtp(folder / name).num_faces(), summarize_polys(folder / name).polys) << name;
  }

  const IndexedMesh femur = read_vtp(folder / "femur_r.vtp");
  EXPECT_EQ(femur.num_faces(), 908);
  EXPECT_EQ(femur.num_vertices(), 456);
  // The femur is in metres, about 0.4 m long.
  const double length = (femur.V.colwise().maxCoeff() - femur.V.colwise().minCoeff()).maxCoeff();
  EXPECT_GT(length, 0.3);
  EXPECT_LT(length, 0.6);
}

}  // namespace
}  // namespace mmm::mesh
