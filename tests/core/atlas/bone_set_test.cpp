// Bone-set manifests: units, frame conventions and a transform bring the
// files into the patient frame; every malformed field is an error naming it.

#include <gtest/gtest.h>

#include "core/atlas/bone_set.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::atlas {
namespace {

// A 20 x 20 x 20 mm box (in metres when `metres`) around (x, y, z).
void write_box(const std::filesystem::path& path, const Eigen::Vector3d& centre, double scale) {
  mesh::IndexedMesh box = mesh::make_icosphere(2, 10.0);
  box.V = ((box.V.rowwise() + centre.transpose()) * scale).eval();
  mesh::write_mesh(box, path);
}

std::string message_of(const std::filesystem::path& manifest) {
  try {
    read_bone_set(manifest);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(BoneSetTest, MetresAndLpsAreBroughtIntoThePatientFrameInMillimetres) {
  const test::ScratchDir dir("bone_set");
  write_box(dir / "femur.stl", Eigen::Vector3d(100, 200, 300), 0.001);
  test::write_file(
      dir / "set.yaml",
      "mmm_bone_set: 1\nunits: m\nframe: LPS\n"
      "transform: [[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n"
      "bones: {femur_r: femur.stl}\nlandmarks: {femoral_head_centre_r: [0.1, 0.2, 0.3]}\n");
  const BoneSet set = read_bone_set(dir / "set.yaml");
  ASSERT_TRUE(set.bones.contains("femur_r"));
  const mesh::MassProperties mass = mesh::mass_properties(set.bones.at("femur_r"));
  // LPS -> RAS negates x and y; then the transform moves x by 5 mm.
  EXPECT_LT((mass.centroid - Eigen::Vector3d(-95, -200, 300)).norm(), 1e-4);  // STL: floats
  EXPECT_GT(mass.volume, 0.0) << "faces flipped with the mirror, so the surface stays outward";
  EXPECT_LT((set.landmarks.at("femoral_head_centre_r") - Eigen::Vector3d(-95, -200, 300)).norm(),
            1e-9);
}

TEST(BoneSetTest, EveryMalformedFieldIsNamed) {
  const test::ScratchDir dir("bone_set_bad");
  write_box(dir / "femur.ply", Eigen::Vector3d::Zero(), 1.0);
  const auto check = [&](const std::string& text, const std::string& expected) {
    test::write_file(dir / "set.yaml", text);
    const std::string message = message_of(dir / "set.yaml");
    EXPECT_NE(message.find(expected), std::string::npos) << text << "\n -> " << message;
  };
  const std::string ok = "mmm_bone_set: 1\nunits: mm\nframe: RAS\n";
  check("units: mm\n", "mmm_bone_set");
  check("mmm_bone_set: 1\nframe: RAS\nbones: {femur_r: femur.ply}\n", "units");
  check("mmm_bone_set: 1\nunits: mm\nframe: XYZ\nbones: {femur_r: femur.ply}\n", "frame");
  check(ok + "bones: {}\n", "bones");
  check(ok + "bones: {femur_r: missing.ply}\n", "bones.femur_r");
  check(ok + "bones: {femur_r: femur.ply}\ncolour: red\n", "unknown field 'colour'");
  check(ok + "bones: {femur_r: femur.ply}\ntransform: [[1,0,0],[0,1,0],[0,0,1]]\n", "transform");
  check(ok + "bones: {femur_r: femur.ply}\ntransform: [[0,0,0,0],[0,0,0,0],[0,0,0,0],[0,0,0,1]]\n",
        "singular");
  check(ok + "bones: {femur_r: femur.ply}\nlandmarks: {a: [1, 2]}\n", "landmarks.a");
  check(ok + "bones: {femur_r: femur.ply}\nlandmarks: {a: [1, 2, .nan]}\n", "landmarks.a");
}

}  // namespace
}  // namespace mmm::atlas
