// Node wrap_muscles: a toy leg driven by the real walking trial (retargeted
// by fuse_motion) has its muscle wrapped frame by frame with the volume held
// and no vertex in a bone, and every output in a format its tool opens; a
// motion of an OpenSim model is refused with a hint.

#include "nodes/wrap_muscles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/pvd.h"
#include "core/wrapping/muscle_frames.h"
#include "nodes/build_hulls.h"
#include "nodes/decompose_fibres.h"
#include "nodes/fuse_motion.h"
#include "tests/nodes/node_harness.h"
#include "tests/nodes/toy_walk.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::nodes {
namespace {

using test::toy_leg_and_walk;
using test::ToyLegAndWalk;
using workflow::PortType;

TEST(WrapMusclesNodeTest, WrapsTheToyLegsMuscleOverARetargetedWalk) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.7);
  const mmm::test::ToyLeg& leg = toy.leg;
  const workflow::ArtifactRef& atlas = toy.atlas;
  const auto outputs = harness.run<WrapMuscles>({{"atlas", atlas}, {"motion", toy.motion}},
                                                {{"animation_stride", std::int64_t{2}}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  const int frames = report["frames"];
  EXPECT_GE(frames, 10);
  EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(report["max_depth_mm"].get<double>(), 0.1 + 1e-9);  // the contact tolerance
  EXPECT_EQ(report["unconverged_muscle_frames"], 0);
  ASSERT_EQ(report["muscles"].size(), leg.atlas.muscles.size());
  test::expect_wrapping_outputs(harness, outputs, frames,
                                static_cast<long>(leg.atlas.muscles.size()),
                                leg.atlas.muscles.front().name, 2);
}

// decompose_fibres after wrap_muscles: fibres at every frame of the
// animation, inside the muscle, following it (their lengths change with the
// knee), with a picture and a report; bad parameters are refused by name.
TEST(DecomposeFibresNodeTest, FibresFollowTheWrappedMuscleFrameByFrame) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.9, -1.0, true);
  const auto wrapped = harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                                {{"animation_stride", std::int64_t{6}}});
  const auto outputs =
      harness.run<DecomposeFibres>({{"atlas", toy.atlas}, {"wrapped", wrapped.at("wrapped")}},
                                   {{"fibres", std::int64_t{16}}, {"segments", std::int64_t{10}}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  const int frames = report["frames"];
  EXPECT_GE(frames, 4);
  EXPECT_GE(report["min_inside_fraction"].get<double>(), 0.99);
  ASSERT_EQ(report["muscles"].size(), 1U);
  EXPECT_EQ(report["muscles"][0]["method"], "slicing");
  EXPECT_EQ(report["muscles"][0]["fibres"], 16);
  // One length per fibre and frame; the lengths change over the walk.
  std::istringstream csv(mmm::test::read_text(outputs.at("lengths").path));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "muscle,method,fibre,frame,time_s,length_mm");
  std::map<int, double> total;
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    std::vector<std::string> cells;
    std::stringstream cell_stream(line);
    for (std::string cell; std::getline(cell_stream, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 6U);
    total[std::stoi(cells[3])] += std::stod(cells[5]);
  }
  EXPECT_EQ(rows, 16 * frames);
  double shortest = 1e300;
  double longest = 0.0;
  for (const auto& [frame, length] : total) {
    shortest = std::min(shortest, length);
    longest = std::max(longest, length);
  }
  // The fibres end on the muscle's own end patches (no tendon), so they
  // change only as much as the wrapped belly (0.3 % here); fibres copied
  // from rest would not change at all, nor stay inside every frame's
  // surface (min_inside_fraction covers the frames).
  EXPECT_GT(longest - shortest, 0.001 * longest);
  EXPECT_GE(report["muscles"][0]["frames_min_inside_fraction"].get<double>(), 0.99);
  const std::filesystem::path fibres = harness.folder() / "fibres";
  unpack_directory(mmm::test::read_text(outputs.at("fibres").path), fibres, "fibres");
  EXPECT_EQ(mesh::read_pvd(fibres / "fibres.pvd").size(), static_cast<std::size_t>(frames));
  EXPECT_EQ(mmm::test::read_text(outputs.at("picture").path).substr(1, 3), "PNG");
  EXPECT_THROW((void)harness.run<DecomposeFibres>({{"atlas", toy.atlas}},
                                                  {{"methods", std::string("vastus_r=voxels")}}),
               InvalidInputError);
  EXPECT_THROW((void)harness.run<DecomposeFibres>({{"atlas", toy.atlas}},
                                                  {{"muscles", std::string("nobody")}}),
               InvalidInputError);
  // A wrapped motion that is not one, or lacks a muscle to decompose, is
  // refused naming the input.
  const auto refused = [&](const std::string& bytes, const std::string& expected) {
    try {
      (void)harness.run<DecomposeFibres>(
          {{"atlas", toy.atlas}, {"wrapped", harness.add(PortType::kMuscleFrames, bytes)}});
      ADD_FAILURE() << "accepted; expected " << expected;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("wrapping.pvd", "input 'wrapped': header");
  wrapping::MuscleFrames none =
      wrapping::decode_muscle_frames(mmm::test::read_text(wrapped.at("wrapped").path), "wrapped");
  none.muscles.clear();
  refused(wrapping::encode_muscle_frames(none), "has no muscle");
}

// Muscles are decomposed in parallel and written in muscle order: the
// fibres and lengths are the same to the byte on one thread or on two.
TEST(DecomposeFibresNodeTest, TheOutputsDoNotDependOnTheNumberOfThreads) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.7, 0.0, true);
  ASSERT_EQ(toy.leg.atlas.muscles.size(), 2U);
  const auto wrapped = harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                                {{"animation_stride", std::int64_t{6}}});
  const auto decompose = [&](std::int64_t threads) {
    return harness.run<DecomposeFibres>(
        {{"atlas", toy.atlas}, {"wrapped", wrapped.at("wrapped")}},
        {{"fibres", std::int64_t{16}}, {"segments", std::int64_t{8}}, {"threads", threads}});
  };
  const auto one = decompose(1);
  const auto two = decompose(2);
  for (const char* output : {"fibres", "lengths"}) {
    EXPECT_EQ(mmm::test::read_text(one.at(output).path), mmm::test::read_text(two.at(output).path))
        << output;
  }
  const nlohmann::json report = nlohmann::json::parse(mmm::test::read_text(two.at("report").path));
  ASSERT_EQ(report["muscles"].size(), 2U);
  EXPECT_EQ(report["muscles"][0]["muscle"], toy.leg.atlas.muscles[0].name);
  EXPECT_EQ(report["muscles"][1]["muscle"], toy.leg.atlas.muscles[1].name);
}

TEST(WrapMusclesNodeTest, StoredHullsAreReusedWhileTheSurfaceAndFaceCountMatch) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.55);
  const auto hulls =
      harness.run<BuildHulls>({{"atlas", toy.atlas}}, {{"hull_faces", std::int64_t{60}}});
  const nlohmann::json hull_report =
      nlohmann::json::parse(mmm::test::read_text(hulls.at("report").path));
  EXPECT_EQ(hull_report["vertices_outside"], 0);
  ASSERT_EQ(hull_report["muscles"].size(), toy.leg.atlas.muscles.size());
  EXPECT_LE(hull_report["muscles"][0]["faces_after"].get<int>(), 60);

  const auto wrap_report = [&](std::int64_t hull_faces) {
    const auto outputs = harness.run<WrapMuscles>(
        {{"atlas", toy.atlas}, {"motion", toy.motion}, {"hulls", hulls.at("hulls")}},
        {{"hull_faces", hull_faces}});
    return nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  };
  const nlohmann::json reused = wrap_report(60);
  EXPECT_EQ(reused["hulls_built_here"], 0);
  EXPECT_TRUE(reused["muscles"][0]["hull"]["reused"].get<bool>());
  EXPECT_EQ(reused["muscles"][0]["hull"]["build_s"].get<double>(), 0.0);
  EXPECT_LT(reused["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(reused["max_depth_mm"].get<double>(), 0.1 + 1e-9);

  const std::size_t warnings_before = harness.log().size();
  const nlohmann::json rebuilt = wrap_report(80);  // another face count: not the stored hull
  EXPECT_EQ(rebuilt["hulls_built_here"], static_cast<int>(toy.leg.atlas.muscles.size()));
  EXPECT_FALSE(rebuilt["muscles"][0]["hull"]["reused"].get<bool>());
  bool warned = false;
  for (std::size_t i = warnings_before; i < harness.log().size(); ++i)
    warned =
        warned || harness.log()[i].find("give build_hulls the same atlas") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(WrapMusclesNodeTest, WithMuscleContactsOverlappingMusclesAreSeparatedAndKeptApart) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.6, 3.0);
  const auto outputs = harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                                {{"muscle_contacts", true}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  EXPECT_TRUE(report["muscle_contacts"].get<bool>());
  EXPECT_TRUE(report["muscle_penetration_measured"].get<bool>());
  ASSERT_EQ(report["muscles"].size(), 2U);
  for (const nlohmann::json& muscle : report["muscles"]) {
    EXPECT_NEAR(muscle["separation"]["overlap_at_rest_mm"].get<double>(), 3.0, 0.3);
    EXPECT_LT(muscle["separation"]["overlap_after_mm"].get<double>(), 0.3);
    EXPECT_GT(muscle["separation"]["max_move_mm"].get<double>(), 0.5);
    // Touching after the separation: each shares its neighbour's motion near the interface.
    EXPECT_GT(muscle["separation"]["interface_vertices"].get<int>(), 0);
  }
  EXPECT_GE(report["separation_rounds"].get<int>(), 1);
  EXPECT_EQ(report["options"]["muscle_interface_reach_mm"].get<double>(), 20.0);
  EXPECT_LT(report["max_depth_in_other_muscles_mm"].get<double>(), 1.0);
  EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(report["max_depth_mm"].get<double>(), 0.1 + 1e-9);
  EXPECT_EQ(report["unconverged_muscle_frames"], 0);
  // The metrics CSV has the penetration into the other muscles filled.
  std::istringstream metrics(mmm::test::read_text(outputs.at("metrics").path));
  std::string header;
  std::string row;
  std::getline(metrics, header);
  std::getline(metrics, row);
  ASSERT_EQ(header.rfind("muscle,frame,time_s,volume_error_percent,max_depth_mm,vertices_inside,"
                         "vertices_deeper,deepest_bone,muscle_depth_mm,",
                         0),
            0U);
  std::vector<std::string> fields;
  std::istringstream cells(row);
  for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
  ASSERT_GT(fields.size(), 8U);
  EXPECT_FALSE(fields[8].empty()) << row;
  EXPECT_LT(std::stod(fields[8]), 1.0) << row;
}

TEST(WrapMusclesNodeTest, SettlingRoundsTakeTheMusclesOutOfEachOtherAndAreRecorded) {
  // The neighbour in front of the toy vastus: the knee moves them differently.
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.6, 3.0, false, Eigen::Vector3d::UnitZ());
  const auto run = [&](std::int64_t settling) {
    const auto outputs = harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                                  {{"muscle_contacts", true},
                                                   {"muscle_contact_rounds", std::int64_t{1}},
                                                   {"muscle_contact_weight", 1.0},
                                                   {"muscle_interface_reach_mm", 0.0},
                                                   {"muscle_contact_settling_rounds", settling}});
    return nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  };
  // One soft round leaves the muscles more than half a millimetre inside each other.
  const nlohmann::json unsettled = run(0);
  EXPECT_GT(unsettled["max_depth_in_other_muscles_mm"].get<double>(), 0.4);
  const nlohmann::json settled = run(6);
  EXPECT_EQ(settled["options"]["muscle_contact_settling_rounds"].get<int>(), 6);
  EXPECT_LT(settled["max_depth_in_other_muscles_mm"].get<double>(), 0.2);
  EXPECT_LT(settled["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(settled["max_depth_mm"].get<double>(), 0.1 + 1e-9);
  EXPECT_EQ(settled["unconverged_muscle_frames"], 0);
  EXPECT_THROW((void)run(-1), std::exception);  // a negative count is refused
  // Each pose keeps its best surfaces over the rounds: more rounds never
  // leave the muscles deeper inside each other.
  double deeper = unsettled["max_depth_in_other_muscles_mm"].get<double>();
  for (const std::int64_t rounds : {1, 2, 3}) {
    const double depth = run(rounds)["max_depth_in_other_muscles_mm"].get<double>();
    EXPECT_LE(depth, deeper + 1e-9) << rounds << " settling rounds";
    deeper = depth;
  }
  EXPECT_LE(settled["max_depth_in_other_muscles_mm"].get<double>(), deeper + 1e-9);
}

TEST(WrapMusclesNodeTest, TheJointContactSolverKeepsTheMusclesApartAndIsRecorded) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.6, 3.0);
  const auto outputs =
      harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                               {{"muscle_contacts", true}, {"muscle_contact_solver", "joint"}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  EXPECT_EQ(report["options"]["muscle_contact_solver"], "joint");
  EXPECT_EQ(report["options"]["joint_contact_rounds"].get<int>(), 10);
  EXPECT_LT(report["max_depth_in_other_muscles_mm"].get<double>(), 0.2);
  EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(report["max_depth_mm"].get<double>(), 0.1 + 1e-9);
  EXPECT_EQ(report["unconverged_muscle_frames"], 0);
}

TEST(WrapMusclesNodeTest, AMotionOfAnOpenSimModelIsRefusedWithAHint) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  const auto fused = harness.run<FuseMotion>(
      {{"model", harness.add_file(PortType::kFile, mmm::test::gait2392_pipelines() / "reference" /
                                                       "subject01_simbody.osim")},
       {"trial", harness.add_file(PortType::kFile,
                                  mmm::test::gait2392_pipelines() / "subject01_walk1.trc")}},
      {{"start_time", 0.5}, {"end_time", 0.55}});
  try {
    harness.run<WrapMuscles>(
        {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
         {"motion", fused.at("motion")}});
    FAIL() << "wrapped an atlas with an OpenSim model's motion";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("give fuse_motion the atlas input"), std::string::npos)
        << error.what();
  }
}

TEST(WrapMusclesNodeTest, AMotionThatIsNotJsonIsRefusedNamingTheInput) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  EXPECT_THROW(
      harness.run<WrapMuscles>(
          {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
           {"motion", harness.add(PortType::kBonePoses, "not json {")}}),
      InvalidInputError);
}

TEST(WrapMusclesNodeTest, TouchingMusclesShareTheirMotionAcrossTheInterfaceUnlessTheReachIsZero) {
  test::NodeHarness harness;
  const ToyLegAndWalk toy = toy_leg_and_walk(harness, 0.6, 3.0);
  const auto run = [&](double reach) {
    const auto outputs =
        harness.run<WrapMuscles>({{"atlas", toy.atlas}, {"motion", toy.motion}},
                                 {{"muscle_contacts", true}, {"muscle_interface_reach_mm", reach}});
    return nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  };
  const nlohmann::json alone = run(0.0);
  const nlohmann::json shared = run(20.0);
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(alone["muscles"][m]["separation"]["interface_vertices"].get<int>(), 0);
    EXPECT_GT(shared["muscles"][m]["separation"]["interface_vertices"].get<int>(), 0);
  }
  EXPECT_THROW((void)run(-1.0), std::exception);  // a negative reach is refused
}

}  // namespace
}  // namespace mmm::nodes
