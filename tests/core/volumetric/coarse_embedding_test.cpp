// Coarse embedding: every fine node is an exact affine combination of the
// coarse element holding it (weights >= 0 summing to 1), so the map carries
// the fine model exactly at rest and rigidly under a rigid motion; nodes
// moved at rest keep both properties.

#include "core/volumetric/coarse_embedding.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::volumetric {
namespace {

using Eigen::Vector3d;

LabelledLattice two_blocks(double spacing) {
  static const mesh::IndexedMesh a = mesh::make_box({0, 0, 0}, {20, 14, 11});
  static const mesh::IndexedMesh b = mesh::make_box({20, 0, 0}, {31, 14, 11});
  return build_labelled_lattice({{"a", &a}, {"b", &b}}, {},
                                {.spacing_mm = spacing, .max_regrowth_mm = 0.0});
}

TEST(CoarseEmbeddingTest, FineNodesAreExactConvexCombinationsOfTheirElement) {
  for (const int factor : {1, 2, 3}) {
    const EmbeddedModel model = embed_in_coarse_lattice(two_blocks(1.0), factor);
    ASSERT_EQ(model.weights.rows(), model.output.V.rows());
    ASSERT_EQ(model.weights.cols(), model.elements.V.rows());
    EXPECT_LT((model.weights * model.elements.V - model.output.V).cwiseAbs().maxCoeff(), 1e-9)
        << "factor " << factor;
    for (int row = 0; row < model.weights.outerSize(); ++row) {
      double sum = 0.0;
      int count = 0;
      for (EmbeddingWeights::InnerIterator it(model.weights, row); it; ++it) {
        EXPECT_GE(it.value(), 0.0);
        sum += it.value();
        ++count;
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
      EXPECT_LE(count, 4);
    }
    EXPECT_TRUE((tet_volumes(model.elements).array() > 0).all());
  }
  const EmbeddedModel coarse = embed_in_coarse_lattice(two_blocks(1.0), 3);
  const EmbeddedModel fine = embed_in_coarse_lattice(two_blocks(1.0), 1);
  // A third of the cells across: about 1/27 of the nodes.
  EXPECT_LT(coarse.elements.V.rows() * 10, fine.elements.V.rows());
}

TEST(CoarseEmbeddingTest, ARigidMotionOfTheElementsMovesTheOutputRigidly) {
  EmbeddedModel model = embed_in_coarse_lattice(two_blocks(1.0), 2);
  // Two boundary nodes moved at rest (as out of a bone): still exact.
  const std::vector<int> nodes = {0, static_cast<int>(model.output.V.rows()) - 1};
  Eigen::MatrixX3d moved(2, 3);
  moved.row(0) = model.output.V.row(nodes[0]) + Eigen::RowVector3d(-0.4, 0.3, -0.2);
  moved.row(1) = model.output.V.row(nodes[1]) + Eigen::RowVector3d(0.5, 0.1, 0.6);
  move_output_nodes(model, nodes, moved);
  EXPECT_LT((model.weights * model.elements.V - model.output.V).cwiseAbs().maxCoeff(), 1e-9);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.rotate(Eigen::AngleAxisd(1.1, Vector3d(1, -2, 0.5).normalized()));
  pose.pretranslate(Vector3d(40, -13, 7));
  const Eigen::MatrixX3d x =
      (model.elements.V * pose.linear().transpose()).rowwise() + pose.translation().transpose();
  const Eigen::MatrixX3d expected =
      (model.output.V * pose.linear().transpose()).rowwise() + pose.translation().transpose();
  EXPECT_LT((model.weights * x - expected).cwiseAbs().maxCoeff(), 1e-9);
}

// Each muscle a body of its own: the interface nodes are split, one copy per
// muscle, paired, at the same place at rest; no element or element node is
// shared between the muscles (a coarse cell across the interface becomes one
// element per muscle), and each copy is still an exact convex combination of
// its own muscle's element.
TEST(CoarseEmbeddingTest, SeparateMusclesShareNoNodeAndPairTheirInterface) {
  const LabelledLattice fine = two_blocks(1.0);
  Eigen::Index more = 0;  // elements added by separating, over the factors
  for (const int factor : {1, 2, 3}) {
    const EmbeddedModel shared = embed_in_coarse_lattice(fine, factor);
    const EmbeddedModel model = embed_muscles_separately(fine, factor);
    // The interface at x = 20 (15 x 12 nodes) is split once.
    EXPECT_EQ(model.output.V.rows(), shared.output.V.rows() + Eigen::Index{15} * 12);
    ASSERT_EQ(model.interfaces.size(), 15U * 12U);
    for (const InterfacePair& pair : model.interfaces) {
      EXPECT_EQ(model.output.V.row(pair.a), model.output.V.row(pair.b));
      EXPECT_DOUBLE_EQ(model.output.V(pair.a, 0), 20.0);
    }
    EXPECT_LT((model.weights * model.elements.V - model.output.V).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_GE(model.weights.coeffs().minCoeff(), 0.0);
    // Per element node, the labels of the elements using it: one each.
    std::vector<std::uint16_t> owner(static_cast<std::size_t>(model.elements.V.rows()), 0);
    for (Eigen::Index t = 0; t < model.elements.T.rows(); ++t) {
      for (int a = 0; a < 4; ++a) {
        std::uint16_t& o = owner[static_cast<std::size_t>(model.elements.T(t, a))];
        const std::uint16_t label = model.elements.label[static_cast<std::size_t>(t)];
        EXPECT_TRUE(o == 0 || o == label);
        o = label;
      }
    }
    // An output node's weights point at elements of its own muscle only.
    std::vector<std::uint16_t> node_label(static_cast<std::size_t>(model.output.V.rows()), 0);
    for (Eigen::Index t = 0; t < model.output.T.rows(); ++t)
      for (int a = 0; a < 4; ++a)
        node_label[static_cast<std::size_t>(model.output.T(t, a))] =
            model.output.label[static_cast<std::size_t>(t)];
    for (int row = 0; row < model.weights.outerSize(); ++row) {
      for (EmbeddingWeights::InnerIterator it(model.weights, row); it; ++it)
        EXPECT_EQ(owner[static_cast<std::size_t>(it.col())],
                  node_label[static_cast<std::size_t>(row)]);
    }
    EXPECT_GE(model.elements.T.rows(), shared.elements.T.rows());
    more += model.elements.T.rows() - shared.elements.T.rows();
  }
  EXPECT_GT(more, 0);  // some coarse cell across the interface, split in two
  EXPECT_THROW(embed_muscles_separately(fine, 0), InvalidInputError);
}

TEST(CoarseEmbeddingTest, BadInputIsRefused) {
  EXPECT_THROW(embed_in_coarse_lattice(two_blocks(2.0), 0), InvalidInputError);
  LabelledLattice empty = two_blocks(2.0);
  std::fill(empty.label.begin(), empty.label.end(), std::uint16_t{0});
  EXPECT_THROW(embed_in_coarse_lattice(empty, 2), InvalidInputError);
  EmbeddedModel model = embed_in_coarse_lattice(two_blocks(2.0), 2);
  EXPECT_THROW(move_output_nodes(model, {-1}, Eigen::MatrixX3d::Zero(1, 3)), InvalidInputError);
  EXPECT_THROW(move_output_nodes(model, {0}, Eigen::MatrixX3d::Constant(1, 3, NAN)),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::volumetric
