// Tying the volumetric model to the skeleton at rest: surface nodes in a
// bone are moved out onto it (the embedding staying exact), element nodes
// inside a bone are anchored to it except near another body's bone, and
// attachment areas beyond reach are left out and reported.

#include "core/volumetric/rest_binding.h"

#include <gtest/gtest.h>

#include <memory>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/mesh/signed_distance.h"

namespace mmm::volumetric {
namespace {

using Eigen::Vector3d;

// Bones on bodies 0, 1, ... in order.
wrapping::PosedBones posed(const std::vector<std::pair<std::string, mesh::IndexedMesh>>& meshes) {
  wrapping::PosedBones bones;
  for (const auto& [name, surface] : meshes) {
    bones.index[name] = static_cast<int>(bones.names.size());
    bones.bodies.push_back(static_cast<int>(bones.names.size()));
    bones.names.push_back(name);
    bones.surfaces.push_back({name, std::make_shared<const mesh::SignedDistance>(surface)});
  }
  return bones;
}

// A 40 mm muscle block with a bone box reaching 2.5 mm into its side.
struct BlockOnBone {
  mesh::IndexedMesh muscle = mesh::make_box({0, 0, 0}, {40, 20, 20});
  mesh::IndexedMesh bone = mesh::make_box({-30, -5, -5}, {2.5, 25, 25});
  EmbeddedModel model;
  MuscleSurface surface;
  BlockOnBone() {
    model =
        embed_in_coarse_lattice(build_labelled_lattice({{"muscle", &muscle}}, {{"bone", &bone}},
                                                       {.spacing_mm = 2.0, .max_regrowth_mm = 0.0}),
                                2);
    surface = muscle_surface(model.output, 1);
  }
};

TEST(RestBindingTest, SurfaceNodesInABoneAreMovedOutAndTheEmbeddingStaysExact) {
  BlockOnBone b;
  const wrapping::PosedBones bones = posed({{"bone", b.bone}});
  int moved = 0;
  const double largest =
      move_out_of_bones(b.model, b.surface.nodes, bones, 0.2, 2.0 * std::sqrt(3.0), 2, moved);
  EXPECT_GT(moved, 0);
  EXPECT_LE(largest, 2.0 * std::sqrt(3.0));
  for (const int node : b.surface.nodes) {
    EXPECT_GE(bones.surfaces[0].surface->at(Vector3d(b.model.output.V.row(node).transpose())),
              0.2 - 1e-9);
  }
  EXPECT_LT((b.model.weights * b.model.elements.V - b.model.output.V).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(RestBindingTest, ElementNodesInsideABoneFollowItExceptNearAnotherBodysBone) {
  BlockOnBone b;
  const double reach = 4.0 * std::sqrt(3.0);
  const std::vector<DrivenNode> alone =
      element_anchors(b.model.elements, posed({{"bone", b.bone}}), reach, 10.0, 2);
  ASSERT_FALSE(alone.empty());
  for (const DrivenNode& d : alone) {
    EXPECT_TRUE(d.element);
    EXPECT_EQ(d.bone, 0);
    EXPECT_LT(b.model.elements.V(d.node, 0), 2.5);  // inside the bone
  }
  // Another body's bone 5 mm beyond the block's far end, 40 mm from every
  // anchor: nothing changes.
  const mesh::IndexedMesh other = mesh::make_box({45, -5, -5}, {60, 25, 25});
  const std::vector<DrivenNode> joint = element_anchors(
      b.model.elements, posed({{"bone", b.bone}, {"other", other}}), reach, 10.0, 2);
  EXPECT_EQ(joint.size(), alone.size());  // the anchored ones are 40 mm away from it
  // Another body's bone 6 mm above the muscle (the block's top is z = 20):
  // anchors within 10 mm of it are dropped, the rest kept.
  const mesh::IndexedMesh near = mesh::make_box({-30, -5, 26}, {2.5, 25, 40});
  const std::vector<DrivenNode> close =
      element_anchors(b.model.elements, posed({{"bone", b.bone}, {"near", near}}), reach, 10.0, 2);
  EXPECT_LT(close.size(), alone.size());
  EXPECT_FALSE(close.empty());
  for (const DrivenNode& d : close) {
    EXPECT_EQ(d.bone, 0);
    EXPECT_LT(b.model.elements.V(d.node, 2), 16.0 + 1e-9);
  }
}

TEST(RestBindingTest, AttachmentAreasBeyondReachAreLeftOutAndReported) {
  BlockOnBone b;
  const wrapping::PosedBones bones = posed({{"bone", b.bone}});
  const mesh::IndexedMesh& full = bones.surfaces[0].surface->tree().mesh();
  atlas::Muscle muscle;
  muscle.name = "muscle";
  // The bone's faces on its +x side (touching the block), and those on its
  // -x side, 30 mm from the block.
  atlas::AttachmentArea touching;
  touching.bone = "bone";
  atlas::AttachmentArea far = touching;
  for (Eigen::Index f = 0; f < full.F.rows(); ++f) {
    const double x =
        (full.V(full.F(f, 0), 0) + full.V(full.F(f, 1), 0) + full.V(full.F(f, 2), 0)) / 3.0;
    if (x > 2.4) touching.faces.push_back(static_cast<int>(f));
    if (x < -29.9) far.faces.push_back(static_cast<int>(f));
  }
  muscle.origins = {touching};
  muscle.insertions = {far};
  const std::vector<int> taken(static_cast<std::size_t>(b.model.output.V.rows()), -1);
  double gap = 0.0;
  int left_out = 0;
  const std::vector<DrivenNode> nodes =
      attachments(muscle, b.surface, bones, taken, 4.0, gap, left_out);
  EXPECT_FALSE(nodes.empty());
  EXPECT_EQ(left_out, 1);
  EXPECT_NEAR(gap, 30.0, 2.5);
  muscle.insertions.front().faces = {static_cast<int>(full.F.rows())};
  EXPECT_THROW(attachments(muscle, b.surface, bones, taken, 4.0, gap, left_out), InvalidInputError);
}

}  // namespace
}  // namespace mmm::volumetric
