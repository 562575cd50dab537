#include "core/volumetric/tet_simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::volumetric {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;
using mesh::IndexedMesh;

TetMesh blocks(const std::vector<std::pair<Vector3d, Vector3d>>& boxes, double spacing) {
  std::vector<IndexedMesh> surfaces;
  surfaces.reserve(boxes.size());
  for (const auto& [lo, hi] : boxes) surfaces.push_back(mesh::make_box(lo, hi));
  std::vector<NamedSurface> named;
  named.reserve(surfaces.size());
  for (std::size_t b = 0; b < surfaces.size(); ++b) {
    named.push_back({"block" + std::to_string(b), &surfaces[b]});
  }
  return lattice_tets(
      build_labelled_lattice(named, {}, {.spacing_mm = spacing, .max_regrowth_mm = 0.0}));
}

// Nodes on a plane: coordinate `axis` equal to `value`.
std::vector<int> nodes_at(const TetMesh& mesh, int axis, double value) {
  std::vector<int> out;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    if (std::abs(mesh.V(i, axis) - value) < 1e-9) out.push_back(static_cast<int>(i));
  }
  return out;
}

std::vector<DrivenNode> driven_by(const std::vector<int>& nodes, int bone) {
  std::vector<DrivenNode> out;
  out.reserve(nodes.size());
  for (const int n : nodes) out.push_back({n, bone});
  return out;
}

// A small bone far from the model, only to carry a pose.
const IndexedMesh& far_handle() {
  static const IndexedMesh handle = mesh::make_icosphere(1, 2.0, {500.0, 500.0, 500.0});
  return handle;
}

// Both end faces of a block follow one rigid motion over 10 frames (a
// rotation of 29 degrees and a 25 mm shift), then hold it: the block follows
// it exactly (a rigid map is the energy's minimum), keeping its volume.
TEST(TetSimulationTest, ARigidMotionOfTheEndsMovesTheBlockRigidly) {
  const TetMesh mesh = blocks({{{0, 0, 0}, {30, 30, 30}}}, 3.0);
  std::vector<int> ends = nodes_at(mesh, 2, 0.0);
  for (const int n : nodes_at(mesh, 2, 30.0)) ends.push_back(n);
  TetSimulation simulation(mesh, driven_by(ends, 0), {&far_handle()}, {.threads = 2});
  const auto pose_at = [](double s) {
    Isometry3d pose = Isometry3d::Identity();
    pose.rotate(Eigen::AngleAxisd(0.5 * s, Vector3d(1, 2, 3).normalized()));
    pose.pretranslate(s * Vector3d(12.0, -7.0, 20.0));
    return pose;
  };
  FrameStats stats;
  for (int frame = 1; frame <= 14; ++frame) {
    stats = simulation.step({pose_at(std::min(1.0, frame / 10.0))});
    ASSERT_EQ(stats.inverted, 0) << "frame " << frame;
  }
  const Isometry3d pose = pose_at(1.0);
  double worst = 0.0;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    worst = std::max(
        worst,
        (simulation.positions().row(i).transpose() - pose * mesh.V.row(i).transpose()).norm());
  }
  EXPECT_LT(worst, 0.05);
  EXPECT_EQ(stats.inverted, 0);
  EXPECT_LT(std::abs(stats.volume_change.at(0)), 1e-3);
}

// Two touching blocks, their far faces moved 6 mm in opposite directions
// along the interface: they shear as one body. Their interface is one set of
// nodes, so they can neither open a gap nor overlap; no element inverts and
// each keeps its volume.
TEST(TetSimulationTest, TwoTouchingBlocksShearedApartKeepTheirSharedFace) {
  const TetMesh mesh = blocks({{{0, 0, 0}, {30, 30, 30}}, {{30, 0, 0}, {60, 30, 30}}}, 3.0);
  std::vector<DrivenNode> driven = driven_by(nodes_at(mesh, 0, 0.0), 0);
  for (const DrivenNode& d : driven_by(nodes_at(mesh, 0, 60.0), 1)) driven.push_back(d);
  TetSimulation simulation(mesh, driven, {&far_handle(), &far_handle()}, {.threads = 2});
  FrameStats stats;
  for (int frame = 1; frame <= 6; ++frame) {
    const Isometry3d left(Eigen::Translation3d(0.0, -1.0 * frame, 0.0));
    const Isometry3d right(Eigen::Translation3d(0.0, 1.0 * frame, 0.0));
    stats = simulation.step({left, right});
    ASSERT_EQ(stats.inverted, 0) << "frame " << frame;
  }
  for (const double change : stats.volume_change) EXPECT_LT(std::abs(change), 1e-4);
  // The interface moved with both blocks: its middle stays near y = 0 shift
  // (symmetry), the blocks' far faces are 12 mm apart along y.
  double shift = 0.0;
  const std::vector<int> interface = nodes_at(mesh, 0, 30.0);
  for (const int n : interface) shift += simulation.positions()(n, 1) - mesh.V(n, 1);
  EXPECT_NEAR(shift / static_cast<double>(interface.size()), 0.0, 0.05);
  const int far_left = nodes_at(mesh, 0, 0.0).front();
  const int far_right = nodes_at(mesh, 0, 60.0).front();
  EXPECT_NEAR(simulation.positions()(far_right, 1) - mesh.V(far_right, 1) -
                  (simulation.positions()(far_left, 1) - mesh.V(far_left, 1)),
              12.0, 1e-3);
}

// The same blocks as separate bodies, their interface nodes tied in pairs.
// Stuck, they shear as one body, as with shared nodes. Sliding, each block
// moves with its own far face: the interface slides by the whole 12 mm while
// its two sides stay on each other (no gap, no overlap across it). No
// element inverts and each block keeps its volume.
TEST(TetSimulationTest, SeparateBlocksStickOrSlideAlongTheirInterface) {
  std::vector<IndexedMesh> surfaces = {mesh::make_box({0, 0, 0}, {30, 30, 30}),
                                       mesh::make_box({30, 0, 0}, {60, 30, 30})};
  const LabelledLattice lattice = build_labelled_lattice(
      {{"a", surfaces.data()}, {"b", &surfaces[1]}}, {}, {.spacing_mm = 3.0, .max_regrowth_mm = 0});
  for (const bool slide : {false, true}) {
    EmbeddedModel model = embed_muscles_separately(lattice, 2);
    std::vector<DrivenNode> driven;
    for (Eigen::Index i = 0; i < model.output.V.rows(); ++i) {
      if (model.output.V(i, 0) == 0.0) driven.push_back({static_cast<int>(i), 0});
      if (model.output.V(i, 0) == 60.0) driven.push_back({static_cast<int>(i), 1});
    }
    const std::vector<InterfacePair> pairs = model.interfaces;
    const Eigen::MatrixX3d rest = model.output.V;
    TetSimulation simulation(std::move(model), driven, {&far_handle(), &far_handle()},
                             {.slide = slide, .iterations = 10, .threads = 2});
    FrameStats stats;
    for (int frame = 1; frame <= 6; ++frame) {
      stats = simulation.step({Isometry3d(Eigen::Translation3d(0.0, -1.0 * frame, 0.0)),
                               Isometry3d(Eigen::Translation3d(0.0, 1.0 * frame, 0.0))});
      ASSERT_EQ(stats.inverted, 0) << "frame " << frame;
    }
    for (const double change : stats.volume_change) EXPECT_LT(std::abs(change), 1e-4);
    // The volume steps after the last solve move each side on its own: a few
    // hundredths of a millimetre.
    EXPECT_LT(stats.max_interface_gap_mm, 0.1) << slide;
    double slid = 0.0;  // mean offset along y across the interface
    for (const InterfacePair& pair : pairs) {
      slid += simulation.positions()(pair.b, 1) - simulation.positions()(pair.a, 1);
      EXPECT_NEAR(simulation.positions()(pair.a, 0), simulation.positions()(pair.b, 0), 0.1);
    }
    slid /= static_cast<double>(pairs.size());
    if (slide) {
      // Each side moved with its own block: 6 mm each way.
      EXPECT_GT(slid, 10.0);
      EXPECT_GT(stats.max_interface_slide_mm, 10.0);
    } else {
      EXPECT_LT(std::abs(slid), 0.05);
      EXPECT_LT(stats.max_interface_slide_mm, 0.05);
    }
    (void)rest;
  }
}

// A block pushed 6 mm down onto a ball (a bone, radius 10 mm) wraps around
// it instead of entering it, keeping its volume.
TEST(TetSimulationTest, ABlockPushedOntoABoneStaysOutOfIt) {
  const TetMesh mesh = blocks({{{0, 0, 0}, {30, 30, 30}}}, 2.0);
  const IndexedMesh ball = mesh::make_icosphere(4, 10.0, {15.0, 15.0, -9.0});
  TetSimulation simulation(mesh, driven_by(nodes_at(mesh, 2, 30.0), 1), {&ball, &far_handle()},
                           {.threads = 2});
  EXPECT_GT(simulation.checked_nodes(), 100);
  FrameStats stats;
  for (int frame = 1; frame <= 6; ++frame) {
    stats = simulation.step(
        {Isometry3d::Identity(), Isometry3d(Eigen::Translation3d(0.0, 0.0, -1.0 * frame))});
    ASSERT_EQ(stats.inverted, 0) << "frame " << frame;
    EXPECT_LE(stats.max_bone_depth_mm, 0.5) << "frame " << frame;
  }
  EXPECT_LT(std::abs(stats.volume_change.at(0)), 1e-4);
  // The bottom node nearest the centre was held up by the ball (the push
  // alone would have taken it to z = -6) and rests on it.
  Eigen::Index centre = 0;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    if ((mesh.V.row(i) - Eigen::RowVector3d(15, 15, 0)).norm() <
        (mesh.V.row(centre) - Eigen::RowVector3d(15, 15, 0)).norm()) {
      centre = i;
    }
  }
  const Vector3d on_top = simulation.positions().row(centre).transpose();
  EXPECT_GT(on_top.z(), -1.0);
  EXPECT_NEAR((on_top - Vector3d(15.0, 15.0, -9.0)).norm(), 10.0, 0.5);
}

// The whole model moved rigidly in one step (the skeleton's root taking
// the atlas into the world, say): a coarse embedding of two touching
// blocks follows exactly, every muscle surface node included.
TEST(TetSimulationTest, ARigidMotionOfEverythingIsReproducedExactly) {
  std::vector<IndexedMesh> surfaces = {mesh::make_box({0, 0, 0}, {24, 24, 24}),
                                       mesh::make_box({24, 0, 0}, {48, 24, 24})};
  const LabelledLattice lattice = build_labelled_lattice(
      {{"a", surfaces.data()}, {"b", &surfaces[1]}}, {}, {.spacing_mm = 1.5, .max_regrowth_mm = 0});
  EmbeddedModel model = embed_in_coarse_lattice(lattice, 2);
  std::vector<DrivenNode> driven;
  for (const double x : {0.0, 48.0}) {
    for (Eigen::Index i = 0; i < model.output.V.rows(); ++i) {
      if (std::abs(model.output.V(i, 0) - x) < 1e-9) driven.push_back({static_cast<int>(i), 0});
    }
  }
  const Eigen::MatrixX3d rest = model.output.V;
  TetSimulation simulation(std::move(model), driven, {&far_handle()},
                           {.iterations = 3, .threads = 2});
  Isometry3d pose = Isometry3d::Identity();
  pose.rotate(Eigen::AngleAxisd(1.3, Vector3d(2, -1, 1).normalized()));
  pose.pretranslate(Vector3d(300, -150, 80));
  const FrameStats stats = simulation.step({pose});
  const Eigen::MatrixX3d expected =
      (rest * pose.linear().transpose()).rowwise() + pose.translation().transpose();
  EXPECT_LT((simulation.positions() - expected).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(stats.inverted, 0);
  for (const double change : stats.volume_change) EXPECT_LT(std::abs(change), 1e-9);
}

// Same inputs, same outputs to the last bit, whatever the number of threads.
TEST(TetSimulationTest, TheResultDoesNotDependOnTheNumberOfThreads) {
  const TetMesh mesh = blocks({{{0, 0, 0}, {30, 30, 30}}, {{30, 0, 0}, {60, 30, 30}}}, 3.0);
  std::vector<DrivenNode> driven = driven_by(nodes_at(mesh, 0, 0.0), 0);
  for (const DrivenNode& d : driven_by(nodes_at(mesh, 0, 60.0), 1)) driven.push_back(d);
  const auto run = [&](int threads) {
    TetSimulation simulation(mesh, driven, {&far_handle(), &far_handle()}, {.threads = threads});
    for (int frame = 1; frame <= 4; ++frame) {
      Isometry3d left = Isometry3d::Identity();
      left.translate(Vector3d(0, -1.5 * frame, 0));
      Isometry3d right = Isometry3d::Identity();
      right.translate(Vector3d(0, 1.5 * frame, 0));
      simulation.step({left, right});
    }
    return Eigen::MatrixX3d(simulation.positions());
  };
  const Eigen::MatrixX3d one = run(1);
  const Eigen::MatrixX3d two = run(2);
  EXPECT_EQ(
      std::memcmp(one.data(), two.data(), sizeof(double) * static_cast<std::size_t>(one.size())),
      0);
}

TEST(TetSimulationTest, BadInputIsRefused) {
  const TetMesh mesh = blocks({{{0, 0, 0}, {6, 6, 6}}}, 3.0);
  EXPECT_THROW(TetSimulation(TetMesh{}, {}, {}), InvalidInputError);
  EXPECT_THROW(TetSimulation(mesh, {{0, 1}}, {&far_handle()}), InvalidInputError);
  EXPECT_THROW(TetSimulation(mesh, {{100000, 0}}, {&far_handle()}), InvalidInputError);
  EXPECT_THROW(TetSimulation(mesh, {}, {nullptr}), InvalidInputError);
  EXPECT_THROW(TetSimulation(mesh, {}, {}, {.iterations = 0}), InvalidInputError);
  EXPECT_THROW(TetSimulation(mesh, {}, {}, {.driven_weight = NAN}), InvalidInputError);
  TetMesh flipped = mesh;
  std::swap(flipped.T(0, 0), flipped.T(0, 1));
  EXPECT_THROW(TetSimulation(flipped, {}, {}), InvalidInputError);
  TetSimulation ok(mesh, {{0, 0}}, {&far_handle()});
  EXPECT_THROW(ok.step({}), InvalidInputError);
  Isometry3d nan = Isometry3d::Identity();
  nan.translation().x() = NAN;
  EXPECT_THROW(ok.step({nan}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::volumetric
