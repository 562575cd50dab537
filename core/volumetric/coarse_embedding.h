#pragma once
// A fine labelled model embedded in a coarser one, so that the simulation
// moves few nodes while the outputs keep the fine lattice's detail.
//
// The coarse grid has the fine grid's origin and `factor` times its spacing;
// a coarse cell is simulated when it holds a fine muscle cell, and its label
// is the muscle with most fine cells in it (the lowest label on a tie), for
// the material. Every fine node lies in a simulated coarse cell, in one of its
// Kuhn tetrahedra: its position is a fixed combination of that tetrahedron's
// four corners (barycentric weights, >= 0, summing to 1).
//
// The map from coarse nodes to fine nodes is piecewise affine and continuous.
// While no coarse tetrahedron inverts it is one-to-one, so fine muscles that
// share an interface at rest keep sharing it and never overlap, whatever the
// coarse nodes do. A coarse tetrahedron may straddle a gap between two
// muscles; it then keeps them from passing through each other as well.
//
// Inside a unit cube with local coordinates c = (u, v, w), the Kuhn
// tetrahedron holding c follows the axes in decreasing order of c,
// c_a1 >= c_a2 >= c_a3: corners 0, bit(a1), bit(a1) | bit(a2), 7 with
// weights 1 - c_a1, c_a1 - c_a2, c_a2 - c_a3, c_a3.

#include <Eigen/SparseCore>
#include <vector>

#include "core/volumetric/labelled_lattice.h"
#include "core/volumetric/lattice_tets.h"

namespace mmm::volumetric {

using EmbeddingWeights = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Two output nodes of different muscles that are one point of their shared
// interface at rest (embed_muscles_separately).
struct InterfacePair {
  int a = 0;
  int b = 0;
};

struct EmbeddedModel {
  TetMesh elements;          // simulated (coarse)
  TetMesh output;            // its muscles' boundaries are the outputs (fine)
  EmbeddingWeights weights;  // output nodes x element nodes: output.V = weights * elements.V
  // Per output node, the four element nodes of the element holding it.
  Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor> host;
  int factor = 1;
  // Separate muscles only: the pairs of output nodes that were one node.
  std::vector<InterfacePair> interfaces;
};

// `factor` >= 1 (1: the elements are the fine tetrahedra themselves).
// Throws InvalidInputError for a factor below 1 or a lattice without a
// muscle cell.
EmbeddedModel embed_in_coarse_lattice(const LabelledLattice& fine, int factor);

// Every muscle a body of its own: the fine model's nodes on an interface
// between muscles are split, one copy per muscle (`interfaces` pairs each
// further copy with the first), and every muscle is embedded in coarse
// elements of its own (a coarse cell holding fine cells of k muscles becomes
// k elements, one per muscle, on k copies of its corners; "virtual nodes").
// No element or node is shared between muscles, so interfaces can slide; the
// simulation ties the pairs (tet_simulation.h). Same weights within a muscle
// as embed_in_coarse_lattice. Throws as embed_in_coarse_lattice.
EmbeddedModel embed_muscles_separately(const LabelledLattice& fine, int factor);

// The identity embedding: the elements are the output.
EmbeddedModel embed_identity(TetMesh mesh);

// Output nodes moved at rest (`nodes[k]` to row k of `positions`): their
// weights become the barycentric coordinates of the new position in their
// host element (negative when it left it), so output.V = weights *
// elements.V still holds and a rigid motion of the elements still moves them
// rigidly. With the identity embedding the element nodes move too. Throws
// InvalidInputError for a node out of range or a non-finite position.
void move_output_nodes(EmbeddedModel& model, const std::vector<int>& nodes,
                       const Eigen::MatrixX3d& positions);

}  // namespace mmm::volumetric
