#include "core/mesh/io/pvd.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::ThrowsMessage;

std::vector<PvdEntry> two_parts_two_steps() {
  return {
      {0.0, "walk/femur_r_0000.vtp", 0, "femur_r"},
      {0.0, "walk/fibres & lines_0000.vtp", 1, "fibres <soleus>"},
      {1.0 / 3.0, "walk/femur_r_0001.vtp", 0, "femur_r"},
      {1.0 / 3.0, "walk/fibres & lines_0001.vtp", 1, ""},
  };
}

void expect_same_entries(const std::vector<PvdEntry>& read, const std::vector<PvdEntry>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    // Shortest round-trip text: times come back bit for bit.
    EXPECT_EQ(read[i].time, written[i].time) << "entry " << i;
    EXPECT_EQ(read[i].file, written[i].file) << "entry " << i;
    EXPECT_EQ(read[i].part, written[i].part) << "entry " << i;
    EXPECT_EQ(read[i].name, written[i].name) << "entry " << i;
  }
}

TEST(PvdTest, RoundTripIsExact) {
  test::ScratchDir scratch("pvd");
  const std::vector<PvdEntry> entries = two_parts_two_steps();
  write_pvd(entries, scratch / "walk.pvd");
  expect_same_entries(read_pvd(scratch / "walk.pvd"), entries);
}

TEST(PvdTest, WritesParaViewCollectionFormat) {
  test::ScratchDir scratch("pvd");
  write_pvd({{0.5, "frames/femur_r_0000.vtp", 0, "femur_r"}, {0.5, "frames/x.vtp", 1, ""}},
            scratch / "walk.pvd");
  const std::string text = test::read_text(scratch / "walk.pvd");
  EXPECT_THAT(text, HasSubstr("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" "
                              "version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n"));
  EXPECT_THAT(text, HasSubstr(R"(<DataSet timestep="0.5" group="" part="0" )"
                              R"(file="frames/femur_r_0000.vtp" name="femur_r"/>)"));
  // An empty name is left out, so that older ParaView versions see nothing new.
  EXPECT_THAT(text, HasSubstr(R"(<DataSet timestep="0.5" group="" part="1" )"
                              R"(file="frames/x.vtp"/>)"));
  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.Parse(text.c_str()), tinyxml2::XML_SUCCESS);
}

TEST(PvdTest, AttributesAreXmlEscaped) {
  test::ScratchDir scratch("pvd");
  write_pvd(two_parts_two_steps(), scratch / "walk.pvd");
  const std::string text = test::read_text(scratch / "walk.pvd");
  EXPECT_THAT(text, HasSubstr(R"(file="walk/fibres &amp; lines_0000.vtp")"));
  EXPECT_THAT(text, HasSubstr(R"(name="fibres &lt;soleus&gt;")"));
  EXPECT_THAT(text, Not(HasSubstr("<soleus>")));
}

// Each bad entry names the entry and leaves no file behind.
void expect_invalid_entry(const PvdEntry& entry, const std::string& message) {
  test::ScratchDir scratch("pvd");
  std::vector<PvdEntry> entries = two_parts_two_steps();
  entries.push_back(entry);
  EXPECT_THAT([&] { write_pvd(entries, scratch / "walk.pvd"); },
              ThrowsMessage<InvalidInputError>(HasSubstr(message)));
  EXPECT_FALSE(std::filesystem::exists(scratch / "walk.pvd"));
}

TEST(PvdTest, AbsoluteFilePathIsInvalidInput) {
  expect_invalid_entry({1.0, std::filesystem::temp_directory_path() / "femur.vtp", 0, ""},
                       "entry 4 file '");
  expect_invalid_entry({1.0, "/femur.vtp", 0, ""},
                       "is absolute; give it relative to the .pvd's folder");
}

TEST(PvdTest, FileOutsideTheFolderIsInvalidInput) {
  expect_invalid_entry({1.0, "../femur.vtp", 0, ""},
                       "entry 4 file '../femur.vtp' does not name a file");
  expect_invalid_entry({1.0, "walk/../../femur.vtp", 0, ""}, "does not name a file inside");
  expect_invalid_entry({1.0, "", 0, ""}, "entry 4 has an empty file path");
}

TEST(PvdTest, NonFiniteTimeAndNegativePartAreInvalidInput) {
  expect_invalid_entry({std::numeric_limits<double>::quiet_NaN(), "a.vtp", 0, ""},
                       "entry 4 has a non-finite time");
  expect_invalid_entry({std::numeric_limits<double>::infinity(), "a.vtp", 0, ""},
                       "entry 4 has a non-finite time");
  expect_invalid_entry({1.0, "a.vtp", -1, ""}, "entry 4 has part -1");
}

TEST(PvdTest, HandWrittenCollectionWithDefaultsIsRead) {
  test::ScratchDir scratch("pvd");
  const auto path = test::write_file(scratch / "hand.pvd",
                                     "<?xml version=\"1.0\"?>\n"
                                     "<VTKFile type=\"Collection\" version=\"0.1\">\n"
                                     "<Collection>\n"
                                     "  <DataSet timestep=\"2\" file=\"a.vtp\"/>\n"
                                     "  <DataSet timestep=\"1e-3\" part=\"3\" file=\"b.vtp\"/>\n"
                                     "</Collection>\n"
                                     "</VTKFile>\n");
  expect_same_entries(read_pvd(path), {{2.0, "a.vtp", 0, ""}, {1e-3, "b.vtp", 3, ""}});
}

TEST(PvdTest, MalformedCollectionsAreIoErrors) {
  test::ScratchDir scratch("pvd");
  const std::string head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\">\n<Collection>\n";
  const std::string tail = "</Collection>\n</VTKFile>\n";
  const auto no_file =
      test::write_file(scratch / "no_file.pvd", head + "<DataSet timestep=\"0\"/>\n" + tail);
  EXPECT_THAT([&] { read_pvd(no_file); },
              ThrowsMessage<IoError>(HasSubstr("line 4: <DataSet> has no file attribute")));
  const auto bad_time = test::write_file(
      scratch / "bad_time.pvd", head + "<DataSet timestep=\"soon\" file=\"a.vtp\"/>\n" + tail);
  EXPECT_THAT([&] { read_pvd(bad_time); },
              ThrowsMessage<IoError>(HasSubstr("timestep='soon' is not a finite number")));
  const auto poly_data = test::write_file(scratch / "surface.pvd",
                                          "<VTKFile type=\"PolyData\"><PolyData/></VTKFile>\n");
  EXPECT_THAT([&] { read_pvd(poly_data); },
              ThrowsMessage<IoError>(HasSubstr("a .pvd index has type \"Collection\"")));
  const auto no_collection =
      test::write_file(scratch / "empty.pvd", "<VTKFile type=\"Collection\"></VTKFile>\n");
  EXPECT_THAT([&] { read_pvd(no_collection); },
              ThrowsMessage<IoError>(HasSubstr("<VTKFile> has no <Collection>")));
}

}  // namespace
}  // namespace mmm::mesh
