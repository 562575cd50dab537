// Node simulate_muscles (volumetric pathway): the toy leg's muscles driven by
// the real walking trial keep their volume, stay out of the bones and out of
// each other, with the energy pathway's outputs; the stored lattice is used
// and a broken one is refused naming the file; the result does not depend on
// the number of threads.

#include "nodes/simulate_muscles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/pvd.h"
#include "nodes/build_muscle_lattice.h"
#include "nodes/decompose_fibres.h"
#include "tests/nodes/node_harness.h"
#include "tests/nodes/toy_walk.h"
#include "tests/support/test_data.h"

namespace mmm::nodes {
namespace {

using test::toy_leg_and_walk;
using test::ToyLegAndWalk;
using workflow::PortType;

nlohmann::json report_of(const std::map<std::string, workflow::ArtifactRef>& outputs) {
  return nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
}

// Two vastus muscles touching along their length (overlapping 3 mm at rest:
// the lattice gives the overlap to one of them), over 0.2 s of the walk.
TEST(SimulateMusclesNodeTest, TouchingMusclesKeepVolumeStayApartAndOutOfTheBones) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.7, 3.0, true);
  const auto lattice =
      harness.run<BuildMuscleLattice>({{"atlas", toy.atlas}}, {{"spacing_mm", 2.0}});
  const auto outputs = harness.run<SimulateMuscles>(
      {{"atlas", toy.atlas}, {"motion", toy.motion}, {"lattice", lattice.at("lattice")}},
      {{"animation_stride", std::int64_t{2}}, {"threads", std::int64_t{2}}});
  const nlohmann::json report = report_of(outputs);
  const int frames = report["frames"];
  EXPECT_GE(frames, 10);
  EXPECT_EQ(report["pathway"], "volumetric");
  EXPECT_DOUBLE_EQ(report["model"]["spacing_mm"].get<double>(), 2.0);  // the stored lattice's
  ASSERT_EQ(report["muscles"].size(), 2U);
  EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-3);
  EXPECT_LE(report["max_depth_mm"].get<double>(), 0.5);
  EXPECT_TRUE(report["muscle_penetration_measured"].get<bool>());
  EXPECT_LE(report["max_depth_in_other_muscles_mm"].get<double>(), 0.5);
  EXPECT_EQ(report["max_inverted_elements"], 0);
  // The vasti lie on the femur: elements reaching into it follow it.
  EXPECT_GT(report["model"]["element_nodes_in_bones"].get<int>(), 0);
  for (const nlohmann::json& muscle : report["muscles"]) {
    EXPECT_GE(muscle["attachment_gap_mm"].get<double>(), 0.0) << muscle["muscle"];
    EXPECT_LT(std::abs(muscle["lattice_change_percent"].get<double>()), 5.0) << muscle["muscle"];
  }
  // The energy pathway's outputs.
  test::expect_wrapping_outputs(harness, outputs, frames, 2, "vastus_b_r", 2);
  // decompose_fibres reads the simulated motion as it reads the energy
  // pathway's: the fibres stay inside the simulated surfaces in every frame.
  const auto fibres =
      harness.run<DecomposeFibres>({{"atlas", toy.atlas}, {"wrapped", outputs.at("wrapped")}},
                                   {{"fibres", std::int64_t{16}}, {"segments", std::int64_t{8}}});
  const nlohmann::json fibre_report = report_of(fibres);
  EXPECT_EQ(fibre_report["frames"], (frames + 1) / 2);
  EXPECT_EQ(fibre_report["wrapping_pathway"], "volumetric");
  for (const nlohmann::json& muscle : fibre_report["muscles"]) {
    EXPECT_GE(muscle["frames_min_inside_fraction"].get<double>(), 0.98) << muscle["muscle"];
  }
}

// Without a stored lattice the node builds one; one thread or two, the
// muscles' surfaces are the same to the byte.
TEST(SimulateMusclesNodeTest, TheSurfacesDoNotDependOnTheNumberOfThreads) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.58, -1.0, true);
  const auto run = [&](std::int64_t threads, const std::string& folder) {
    const auto outputs = harness.run<SimulateMuscles>(
        {{"atlas", toy.atlas}, {"motion", toy.motion}},
        {{"spacing_mm", 2.5}, {"threads", threads}, {"muscle_penetration", false}});
    unpack_directory(mmm::test::read_text(outputs.at("animation").path), harness.folder() / folder,
                     "animation");
    return report_of(outputs);
  };
  const nlohmann::json one = run(1, "one");
  const nlohmann::json two = run(2, "two");
  EXPECT_FALSE(one["muscle_penetration_measured"].get<bool>());
  EXPECT_DOUBLE_EQ(one["model"]["spacing_mm"].get<double>(), 2.5);
  const std::string muscle = "vastus_r_0000.vtp";
  const std::string a = mmm::test::read_text(harness.folder() / "one" / "wrapping" / muscle);
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, mmm::test::read_text(harness.folder() / "two" / "wrapping" / muscle));
}

// The touching vasti as separate bodies: their interface nodes are tied in
// pairs; stuck, the pairs stay together; sliding, they stay on each other
// across the interface. Both keep the volumes and stay out of the bones.
TEST(SimulateMusclesNodeTest, SeparateMusclesStickOrSlideAsConfigured) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.62, 3.0, true);
  for (const std::string interfaces : {"stick", "slide"}) {
    const nlohmann::json report = report_of(harness.run<SimulateMuscles>(
        {{"atlas", toy.atlas}, {"motion", toy.motion}},
        {{"spacing_mm", 2.0}, {"interfaces", interfaces}, {"threads", std::int64_t{2}}}));
    EXPECT_EQ(report["model"]["interfaces"], interfaces);
    EXPECT_GT(report["model"]["interface_pairs"].get<int>(), 50) << interfaces;
    EXPECT_LT(report["model"]["max_interface_gap_mm"].get<double>(), 0.5) << interfaces;
    EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-3) << interfaces;
    EXPECT_LE(report["max_depth_mm"].get<double>(), 0.5) << interfaces;
    EXPECT_EQ(report["max_inverted_elements"], 0) << interfaces;
  }
  EXPECT_THROW((void)harness.run<SimulateMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                                  {{"interfaces", std::string("glued")}}),
               InvalidInputError);
}

TEST(SimulateMusclesNodeTest, ABrokenLatticeIsRefusedNamingTheFile) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.55);
  const auto lattice =
      harness.run<BuildMuscleLattice>({{"atlas", toy.atlas}}, {{"spacing_mm", 3.0}});
  const std::filesystem::path folder = harness.folder() / "broken";
  unpack_directory(mmm::test::read_text(lattice.at("lattice").path), folder, "lattice");
  const auto refuses = [&](const std::string& expected) {
    try {
      harness.run<SimulateMuscles>(
          {{"atlas", toy.atlas},
           {"motion", toy.motion},
           {"lattice", harness.add(PortType::kFile, pack_directory(folder))}});
      FAIL() << "a broken lattice was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  mmm::test::write_file(folder / "lattice.json", R"({"muscles": [{"muscle": 3}]})");
  refuses("lattice.json");
  mmm::test::write_file(
      folder / "lattice.json",
      R"({"muscles": [{"muscle": "soleus_x", "segmented_mm3": 1, "kept_mm3": 1}]})");
  refuses("soleus_x");
  mmm::test::write_file(folder / "muscles.lattice", "MMMLAT1\nshort");
  refuses("muscles.lattice");
}

TEST(SimulateMusclesNodeTest, AMotionThatIsNotJsonIsRefusedNamingTheInput) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.55);
  try {
    harness.run<SimulateMuscles>(
        {{"atlas", toy.atlas}, {"motion", harness.add(PortType::kBonePoses, "not json {")}});
    FAIL() << "a motion that is not JSON was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("input 'motion'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mmm::nodes
