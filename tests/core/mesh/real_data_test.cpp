// The mesh kernel on the real atlas data: which surfaces are closed, and
// whether the volumes of the closed ones are anatomically plausible.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

std::vector<std::filesystem::path> files_under(const std::filesystem::path& folder,
                                               const std::string& extension) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (entry.path().extension() == extension) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool is_muscle(const std::filesystem::path& file) {
  return file.filename().string().find("_Muscle_") != std::string::npos;
}

// Every VHF surface is a closed, manifold, outward-oriented solid: the
// dataset was segmented and smoothed into watertight shells. All are one
// shell except the talus, which comes as three separate shells in this copy.
// The shared copy holds 63 Denver surfaces (60 right: 37 muscles, 11 bones,
// 8 cartilages, 4 ligaments; 3 left) and 3 registered CT bones.
TEST(RealDataTest, EveryVhfSurfaceIsWatertightAndOutward) {
  const auto files = files_under(test::data_dir() / "vhf", ".stl");
  ASSERT_EQ(files.size(), 66U) << "the shared VHF copy holds 63 Denver surfaces and 3 CT bones";
  for (const auto& file : files) {
    const IndexedMesh mesh = read_mesh(file);
    const MeshCheckReport report = check_mesh(mesh);
    EXPECT_TRUE(report.watertight()) << file.filename();
    const bool talus = file.filename() == "VHF_Right_Bone_Talus_smooth.stl";
    EXPECT_EQ(report.connected_components, talus ? 3 : 1) << file.filename();
    EXPECT_EQ(report.degenerate_faces, 0) << file.filename();
    EXPECT_GT(signed_volume(mesh), 0.0) << file.filename() << " faces point inward";
  }
}

// Lower-limb muscle volumes of adults span about 20 cm^3 (pectineus,
// piriformis of small subjects) to 1200 cm^3 (gluteus maximus of large ones)
// in MRI studies (Handsfield et al. 2014); the VHF is a small adult female,
// so every muscle must fall in that range and the gluteus maximus must be
// the largest. The small deep muscles of the shank and hip in this copy
// (gemelli, plantaris, popliteus, extensor hallucis longus) get 1-20 cm^3.
TEST(RealDataTest, VhfMuscleVolumesArePlausible) {
  const std::vector<std::string> small = {"VHF_Right_Muscle_InferiorGemellus_smooth.stl",
                                          "VHF_Right_Muscle_SuperiorGemellus_smooth.stl",
                                          "VHF_Right_Muscle_Plantaris_smooth.stl",
                                          "VHF_Right_Muscle_Popliteus_smooth.stl",
                                          "VHF_Right_Muscle_ExtensorHallucisLongus_smooth.stl"};
  double largest = 0;
  std::string largest_name;
  int muscles = 0;
  for (const auto& file : files_under(test::data_dir() / "vhf", ".stl")) {
    if (!is_muscle(file)) continue;
    ++muscles;
    const double volume = signed_volume(read_mesh(file));
    const bool is_small =
        std::find(small.begin(), small.end(), file.filename().string()) != small.end();
    EXPECT_GT(volume, is_small ? 1e3 : 20e3) << file.filename();
    EXPECT_LT(volume, is_small ? 20e3 : 1200e3) << file.filename();
    if (volume > largest) {
      largest = volume;
      largest_name = file.filename().string();
    }
  }
  EXPECT_EQ(muscles, 38);  // 37 right-leg muscles + the left long head of biceps femoris
  EXPECT_EQ(largest_name, "VHF_Right_Muscle_GluteusMaximus_smooth.stl");
}

// The OpenSim gait2392 bones are coarse display meshes: most are closed, but
// the pelvis halves and the foot are open shells, so they get no volume.
TEST(RealDataTest, Gait2392ClosednessIsKnown) {
  const std::vector<std::string> open = {"foot.vtp", "l_pelvis.vtp", "pelvis.vtp"};
  const auto files = files_under(test::data_dir() / "gait2392/Geometry", ".vtp");
  ASSERT_EQ(files.size(), 10U);
  for (const auto& file : files) {
    const IndexedMesh mesh = read_mesh(file);
    const MeshCheckReport report = check_mesh(mesh);
    const bool expected_open =
        std::find(open.begin(), open.end(), file.filename().string()) != open.end();
    EXPECT_EQ(report.closed(), !expected_open) << file.filename();
    if (report.watertight()) {
      // Metres: a bone of this model encloses 1e-5 to 1e-3 m^3 (10-1000 cm^3).
      const double volume = signed_volume(mesh);
      EXPECT_GT(volume, 1e-5) << file.filename();
      EXPECT_LT(volume, 1e-3) << file.filename();
    }
  }
}

// The femoral-head cartilage is a cap on a sphere: its centroid must lie
// near the hip centre the data README gives (636.9, 448.9, 883.0) mm — a
// check that coordinates and units come through the reader unchanged.
TEST(RealDataTest, FemoralHeadCartilageSitsAtTheHipCentre) {
  const IndexedMesh cartilage =
      read_mesh(test::data_dir() / "vhf/Right/VHF_Right_Cartilage_FemurHead_smooth.stl");
  const Eigen::Vector3d hip(636.9, 448.9, 883.0);
  const MassProperties p = mass_properties(cartilage);
  // The cap covers one side of a 22.5 mm sphere, so its centroid sits within
  // one radius of the centre.
  EXPECT_LT((p.centroid - hip).norm(), 22.5);
}

}  // namespace
}  // namespace mmm::mesh
