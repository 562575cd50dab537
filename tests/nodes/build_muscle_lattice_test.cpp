// Node build_muscle_lattice: the toy leg's muscle (2 mm into its femur, as
// atlas segmentations overlap bones) in one labelled tetrahedral model.

#include "nodes/build_muscle_lattice.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/atlas/atlas_meshes.h"
#include "core/directory_bundle.h"
#include "core/mesh/mass_properties.h"
#include "core/volumetric/lattice_io.h"
#include "core/volumetric/lattice_tets.h"
#include "tests/nodes/node_harness.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::nodes {
namespace {

using workflow::PortType;

// The toy leg as an atlas artifact of the harness.
workflow::ArtifactRef add_atlas(test::NodeHarness& harness, const mmm::test::ToyLeg& leg) {
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  return harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"));
}

TEST(BuildMuscleLatticeNodeTest, TheToyMuscleBecomesTetrahedraOutsideTheBoneWithItsVolume) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  const workflow::ArtifactRef atlas = add_atlas(harness, leg);
  const auto outputs = harness.run<BuildMuscleLattice>(
      {{"atlas", atlas}}, {{"spacing_mm", 1.5}, {"threads", std::int64_t{2}}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  ASSERT_EQ(report["muscles"].size(), leg.atlas.muscles.size());
  const nlohmann::json& row = report["muscles"][0];
  EXPECT_EQ(row["muscle"], leg.atlas.muscles[0].name);
  EXPECT_EQ(row["label"], 1);
  EXPECT_GT(row["to_bones_percent"].get<double>(), 0.5);  // the 2 mm in the femur
  EXPECT_LT(std::abs(row["change_percent"].get<double>()), 2.0);
  EXPECT_EQ(report["muscles_over_2_percent"], 0);

  const std::filesystem::path folder = harness.folder() / "lattice";
  unpack_directory(mmm::test::read_text(outputs.at("lattice").path), folder, "lattice");
  const volumetric::TetMesh tets =
      volumetric::lattice_tets(volumetric::read_lattice(folder / "muscles.lattice"));
  EXPECT_EQ(tets.T.rows(), report["tetrahedra"].get<Eigen::Index>());
  EXPECT_EQ(tets.V.rows(), report["nodes"].get<Eigen::Index>());
  EXPECT_NEAR(volumetric::tet_volumes(tets).sum(), row["kept_mm3"].get<double>(), 1e-6);
  const std::string vti = mmm::test::read_text(folder / "muscles.vti");
  EXPECT_NE(vti.find("<ImageData WholeExtent=\"0 "), std::string::npos);
  const nlohmann::json summary =
      nlohmann::json::parse(mmm::test::read_text(folder / "lattice.json"));
  EXPECT_EQ(summary["muscles"][0]["muscle"], leg.atlas.muscles[0].name);
  EXPECT_DOUBLE_EQ(summary["spacing_mm"].get<double>(), 1.5);
}

TEST(BuildMuscleLatticeNodeTest, AnUnknownMuscleIsRefusedNamingIt) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  const workflow::ArtifactRef atlas = add_atlas(harness, leg);
  try {
    harness.run<BuildMuscleLattice>({{"atlas", atlas}}, {{"muscles", std::string("soleus_x")}});
    FAIL() << "an unknown muscle was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("soleus_x"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mmm::nodes
