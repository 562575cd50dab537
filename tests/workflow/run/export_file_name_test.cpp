// Exported Files are named by what they hold, so that people's tools open
// them with a double click (OpenSim the .mot, a spreadsheet the .csv,
// ParaView the unpacked folder of a bundle).

#include <gtest/gtest.h>

#include "tests/support/test_data.h"
#include "workflow/run/export_outputs.h"

namespace mmm::workflow {
namespace {

std::string name_for(const std::string& bytes) {
  const test::ScratchDir dir("export-name");
  const std::filesystem::path blob = test::write_file(dir / "blob", bytes);
  return export_file_name("out", PortType::kFile, blob);
}

TEST(ExportFileNameTest, FilesGetTheExtensionTheirContentShows) {
  EXPECT_EQ(name_for("\x89PNG\r\n\x1a\n...."), "out.png");
  EXPECT_EQ(name_for("<svg xmlns=\"http://www.w3.org/2000/svg\"></svg>"), "out.svg");
  EXPECT_EQ(name_for("%PDF-1.4"), "out.pdf");
  EXPECT_EQ(name_for("mmm-bundle 1\nend\n"), "out.bundle");
  EXPECT_EQ(name_for("PathFileType\t4\t(X/Y/Z)\twalk.trc\n"), "out.trc");
  EXPECT_EQ(name_for("walk_ik\nversion=1\nnRows=2\nnColumns=3\ninDegrees=yes\nendheader\n"
                     "time\ta\tb\n"),
            "out.mot");
  EXPECT_EQ(name_for("<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">"), "out.osim");
  EXPECT_EQ(name_for("frame,time_s,kind\n1,0.5,marker\n"), "out.csv");
  // Not recognisably anything: no extension rather than a wrong one.
  EXPECT_EQ(name_for("hello world\n"), "out");
  EXPECT_EQ(name_for("a,b<c\n"), "out");
  EXPECT_EQ(export_file_name("report", PortType::kReport), "report.json");
}

}  // namespace
}  // namespace mmm::workflow
