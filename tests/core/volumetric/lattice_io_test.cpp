#include "core/volumetric/lattice_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::volumetric {
namespace {

LabelledLattice two_balls() {
  const mesh::IndexedMesh a = mesh::make_icosphere(3, 6.0, {0.0, 0.0, 0.0});
  const mesh::IndexedMesh b = mesh::make_icosphere(3, 5.0, {9.0, 1.0, 0.0});
  return build_labelled_lattice({{"a", &a}, {"b", &b}}, {}, {.spacing_mm = 1.0});
}

constexpr std::size_t kLabelsAt = 8 + 4 * 8 + 3 * 4 + 4;

TEST(LatticeIoTest, ALatticeFileReadsBackExactly) {
  const mmm::test::ScratchDir dir("lattice-io");
  const LabelledLattice lattice = two_balls();
  write_lattice(dir.path() / "m.lattice", lattice);
  const LabelledLattice back = read_lattice(dir.path() / "m.lattice");
  EXPECT_EQ(back.origin, lattice.origin);
  EXPECT_EQ(back.spacing_mm, lattice.spacing_mm);
  EXPECT_TRUE((back.cells == lattice.cells).all());
  EXPECT_EQ(back.label, lattice.label);
  EXPECT_TRUE(back.muscles.empty());  // the report lives beside it
  write_lattice_vti(dir.path() / "m.vti", lattice);
  const std::string vti = mmm::test::read_text(dir.path() / "m.vti");
  EXPECT_EQ(vti.rfind("<?xml", 0), 0U);
  EXPECT_NE(vti.find("WholeExtent=\"0 " + std::to_string(lattice.cells.x()) + " 0 "),
            std::string::npos);
  // The appended block: a UInt64 byte count, then the labels as they are.
  const std::size_t data = vti.find('_', vti.find("<AppendedData")) + 1;
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, vti.data() + data, sizeof(bytes));
  EXPECT_EQ(bytes, lattice.label.size() * 2);
  EXPECT_EQ(std::memcmp(vti.data() + data + 8, lattice.label.data(), bytes), 0);
  EXPECT_NE(vti.find("</VTKFile>", data + 8 + bytes), std::string::npos);
}

// A damaged or hostile .lattice is refused before its labels are read, naming the file.
TEST(LatticeIoTest, BrokenFilesAreRefusedNamingTheProblem) {
  const mmm::test::ScratchDir dir("lattice-io-bad");
  write_lattice(dir.path() / "good.lattice", two_balls());
  const std::string good = mmm::test::read_text(dir.path() / "good.lattice");
  const auto refused = [&](const std::string& bytes, const std::string& expected) {
    mmm::test::write_file(dir.path() / "bad.lattice", bytes);
    try {
      (void)read_lattice(dir.path() / "bad.lattice");
    } catch (const IoError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("bad.lattice"), std::string::npos) << message;
      EXPECT_NE(message.find(expected), std::string::npos) << message;
      return;
    }
    ADD_FAILURE() << "accepted: " << expected;
  };
  const auto patched = [&](std::size_t at, const auto& value) {
    std::string bytes = good;
    std::memcpy(bytes.data() + at, &value, sizeof(value));
    return bytes;
  };
  refused("not a lattice, just text", "MMMLAT1");
  refused(good.substr(0, good.size() - 3), "truncated");
  refused(good.substr(0, 20), "MMMLAT1");
  refused(patched(8, std::nan("")), "non-finite origin");
  refused(patched(8 + 24, -1.0), "spacing");
  refused(patched(8 + 32, std::int32_t{-4}), "cell count");
  refused(patched(8 + 32, std::int32_t{1 << 30}), "limit");
  refused(patched(kLabelsAt + std::size_t{200}, std::uint16_t{7}), "label 7");
  EXPECT_THROW((void)read_lattice(dir.path() / "missing.lattice"), IoError);
}

}  // namespace
}  // namespace mmm::volumetric
