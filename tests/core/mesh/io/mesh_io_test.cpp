#include "core/mesh/io/mesh_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

std::vector<std::filesystem::path> entries(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> found;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    found.push_back(entry.path());
  }
  return found;
}

TEST(MeshIoTest, FormatFromExtensionIsCaseInsensitive) {
  EXPECT_EQ(format_from_extension("a/b/femur.STL"), MeshFormat::kStl);
  EXPECT_EQ(format_from_extension("x.stl"), MeshFormat::kStl);
  EXPECT_EQ(format_from_extension("x.Obj"), MeshFormat::kObj);
  EXPECT_EQ(format_from_extension("x.PLY"), MeshFormat::kPly);
  EXPECT_EQ(format_from_extension("x.off"), MeshFormat::kOff);
  EXPECT_EQ(format_from_extension("femur_r.VTP"), MeshFormat::kVtp);
}

TEST(MeshIoTest, UnknownExtensionListsTheSupportedOnes) {
  EXPECT_THAT([] { format_from_extension("model.vtk"); },
              ThrowsMessage<IoError>(
                  HasSubstr("unknown mesh extension '.vtk'; supported: .stl .obj .ply .off .vtp")));
  EXPECT_THAT([] { format_from_extension("model"); },
              ThrowsMessage<IoError>(HasSubstr("has no file extension")));
  test::ScratchDir scratch("meshio");
  const auto path = test::write_file(scratch / "mesh.3ds", "not empty");
  EXPECT_THAT([&] { read_mesh(path); },
              ThrowsMessage<IoError>(HasSubstr("supported: .stl .obj .ply .off .vtp")));
}

TEST(MeshIoTest, NonExistentPathSaysNoSuchFile) {
  test::ScratchDir scratch("meshio");
  const auto path = scratch / "missing.stl";
  EXPECT_THAT([&] { read_mesh(path); },
              ThrowsMessage<IoError>(HasSubstr(path.string() + ": no such file")));
}

TEST(MeshIoTest, DirectoryIsNotAMeshFile) {
  test::ScratchDir scratch("meshio");
  std::filesystem::create_directory(scratch / "bones.stl");
  EXPECT_THAT([&] { read_mesh(scratch / "bones.stl"); },
              ThrowsMessage<IoError>(HasSubstr("is a directory, not a mesh file")));
}

TEST(MeshIoTest, EmptyFileIsReported) {
  test::ScratchDir scratch("meshio");
  for (const char* name : {"empty.stl", "empty.obj", "empty.ply", "empty.off", "empty.vtp"}) {
    const auto path = test::write_file(scratch / name, "");
    EXPECT_THAT([&] { read_mesh(path); }, ThrowsMessage<IoError>(HasSubstr("file is empty")))
        << name;
  }
}

TEST(MeshIoTest, EveryFormatRoundTripsThroughWriteMeshAndReadMesh) {
  test::ScratchDir scratch("meshio");
  const IndexedMesh torus = make_torus(3.0, 1.0, 16, 8);
  for (const bool ascii : {false, true}) {
    for (const char* name : {"t.stl", "t.obj", "t.ply", "t.off", "t.vtp"}) {
      SCOPED_TRACE(std::string(name) + (ascii ? " ascii" : " binary"));
      write_mesh(torus, scratch / name, {.ascii = ascii});
      const IndexedMesh read = read_mesh(scratch / name);
      ASSERT_EQ(read.num_faces(), torus.num_faces());
      ASSERT_EQ(read.num_vertices(), torus.num_vertices());
      if (format_from_extension(name) == MeshFormat::kStl) {
        // STL renumbers vertices, so compare order-free column sums. float32
        // storage moves each coordinate (up to 4) by at most 4 * 2^-24 = 2.4e-7:
        // a column sum by #V times that, the 3-vector by sqrt(3) times more.
        EXPECT_LE((read.V.colwise().sum() - torus.V.colwise().sum()).norm(),
                  4.2e-7 * static_cast<double>(torus.num_vertices()));
      } else {
        EXPECT_EQ(read.V, torus.V);
        EXPECT_EQ(read.F, torus.F);
      }
    }
  }
}

TEST(MeshIoTest, WriteCreatesNothingButTheFile) {
  test::ScratchDir scratch("meshio");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  write_mesh(box, scratch / "box.ply");
  write_mesh(box, scratch / "box.ply");  // replacing an existing file
  EXPECT_EQ(entries(scratch.path()), std::vector<std::filesystem::path>{scratch / "box.ply"});
}

TEST(MeshIoTest, WriteIntoMissingFolderFailsAndCreatesNothing) {
  test::ScratchDir scratch("meshio");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  EXPECT_THAT([&] { write_mesh(box, scratch / "no" / "box.stl"); },
              ThrowsMessage<IoError>(HasSubstr("does not exist")));
  EXPECT_TRUE(entries(scratch.path()).empty());
}

TEST(MeshIoTest, FailedWriteKeepsThePreviousFile) {
  test::ScratchDir scratch("meshio");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  write_mesh(box, scratch / "box.obj");
  IndexedMesh broken = box;
  broken.F(3, 1) = 42;  // out of range: rejected before anything is written
  EXPECT_THAT([&] { write_mesh(broken, scratch / "box.obj"); },
              ThrowsMessage<InvalidInputError>(HasSubstr("face 3 refers to vertex 42")));
  EXPECT_EQ(read_mesh(scratch / "box.obj").F, box.F);
  EXPECT_EQ(entries(scratch.path()).size(), 1U);
}

TEST(MeshIoTest, WriteRejectsUnknownExtension) {
  test::ScratchDir scratch("meshio");
  const IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  EXPECT_THAT([&] { write_mesh(box, scratch / "box.vtk"); },
              ThrowsMessage<IoError>(HasSubstr("supported: .stl .obj .ply .off .vtp")));
  EXPECT_TRUE(entries(scratch.path()).empty());
}

TEST(MeshIoTest, ReadsTheRealDataThroughTheDispatcher) {
  const IndexedMesh femur = read_mesh(test::data_dir() / "gait2392" / "Geometry" / "femur_r.vtp");
  EXPECT_EQ(femur.num_faces(), 908);
  const IndexedMesh patella =
      read_mesh(test::data_dir() / "vhf" / "Right" / "VHF_Right_Bone_Patella_smooth.stl");
  EXPECT_EQ(patella.num_faces(), (329484 - 84) / 50);  // binary STL: size = 84 + 50 #F
}

}  // namespace
}  // namespace mmm::mesh
