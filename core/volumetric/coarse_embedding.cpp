#include "core/volumetric/coarse_embedding.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <unordered_map>

#include "core/errors.h"

namespace mmm::volumetric {
namespace {

using GridKey = std::int64_t;

GridKey key_of(const Eigen::Array3i& at) {
  constexpr GridKey kSide = 1 << 20;
  return (static_cast<GridKey>(at.z()) * kSide + at.y()) * kSide + at.x();
}

// Node index per grid corner of a lattice_tets mesh (its nodes are corners
// of a grid with this origin and spacing).
std::unordered_map<GridKey, int> node_index(const TetMesh& mesh, const Eigen::Vector3d& origin,
                                            double spacing) {
  std::unordered_map<GridKey, int> out;
  out.reserve(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Eigen::Array3i at =
        ((mesh.V.row(v).transpose() - origin) / spacing).array().round().cast<int>();
    out.emplace(key_of(at), static_cast<int>(v));
  }
  return out;
}

// The coarse lattice: a cell per `factor`^3 fine cells, labelled by the
// muscle with most fine cells in it.
LabelledLattice coarse_lattice(const LabelledLattice& fine, int factor) {
  LabelledLattice coarse;
  coarse.origin = fine.origin;
  coarse.spacing_mm = fine.spacing_mm * factor;
  coarse.cells = (fine.cells + factor - 1) / factor;
  coarse.muscles = fine.muscles;
  coarse.label.assign(static_cast<std::size_t>(coarse.cells.prod()), 0);
  std::vector<std::map<std::uint16_t, int>> counts(coarse.label.size());
  for (int k = 0; k < fine.cells.z(); ++k) {
    for (int j = 0; j < fine.cells.y(); ++j) {
      for (int i = 0; i < fine.cells.x(); ++i) {
        const std::uint16_t label = fine.at(i, j, k);
        if (label == 0) continue;
        ++counts[static_cast<std::size_t>(coarse.index(i / factor, j / factor, k / factor))][label];
      }
    }
  }
  for (std::size_t c = 0; c < counts.size(); ++c) {
    int best = 0;
    for (const auto& [label, count] : counts[c]) {
      if (count > best) {
        best = count;
        coarse.label[c] = label;
      }
    }
  }
  return coarse;
}

}  // namespace

EmbeddedModel embed_in_coarse_lattice(const LabelledLattice& fine, int factor) {
  if (factor < 1) {
    throw InvalidInputError("coarse embedding: the factor must be at least 1, got " +
                            std::to_string(factor));
  }
  EmbeddedModel model;
  model.factor = factor;
  model.output = lattice_tets(fine);
  if (model.output.T.rows() == 0) {
    throw InvalidInputError("coarse embedding: the lattice has no muscle cell");
  }
  if (factor == 1) return embed_identity(std::move(model.output));
  const LabelledLattice coarse = coarse_lattice(fine, factor);
  model.elements = lattice_tets(coarse);
  const std::unordered_map<GridKey, int> coarse_node =
      node_index(model.elements, coarse.origin, coarse.spacing_mm);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(model.output.V.rows()) * 4);
  model.host.resize(model.output.V.rows(), 4);
  for (Eigen::Index v = 0; v < model.output.V.rows(); ++v) {
    const Eigen::Array3i at = ((model.output.V.row(v).transpose() - fine.origin) / fine.spacing_mm)
                                  .array()
                                  .round()
                                  .cast<int>();
    // The coarse cell holding the node: floor(at / factor), or the one
    // below along an axis where the node lies on a coarse cell face, when
    // that one is simulated.
    bool placed = false;
    for (int option = 0; option < 8 && !placed; ++option) {
      Eigen::Array3i cell;
      bool valid = true;
      for (int a = 0; a < 3; ++a) {
        cell[a] = at[a] / factor;
        if ((option >> a) & 1) {
          valid = valid && at[a] % factor == 0 && cell[a] > 0;
          cell[a] -= 1;
        }
        valid = valid && cell[a] < coarse.cells[a];
      }
      if (!valid || coarse.at(cell.x(), cell.y(), cell.z()) == 0) continue;
      Eigen::Array3d local = (at - cell * factor).cast<double>() / factor;
      std::array<int, 3> axes = {0, 1, 2};
      std::ranges::stable_sort(axes, [&](int a, int b) { return local[a] > local[b]; });
      const std::array<int, 4> corners = {0, 1 << axes[0], (1 << axes[0]) | (1 << axes[1]), 7};
      const std::array<double, 4> weights = {1.0 - local[axes[0]], local[axes[0]] - local[axes[1]],
                                             local[axes[1]] - local[axes[2]], local[axes[2]]};
      for (int c = 0; c < 4; ++c) {
        const int corner = corners[static_cast<std::size_t>(c)];
        const Eigen::Array3i grid =
            cell + Eigen::Array3i(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const int node = coarse_node.at(key_of(grid));
        model.host(v, c) = node;
        if (weights[static_cast<std::size_t>(c)] > 0.0)
          triplets.emplace_back(static_cast<int>(v), node, weights[static_cast<std::size_t>(c)]);
      }
      placed = true;
    }
    if (!placed) {
      throw InvalidInputError("coarse embedding: fine node " + std::to_string(v) +
                              " lies in no simulated coarse cell");
    }
  }
  model.weights.resize(model.output.V.rows(), model.elements.V.rows());
  model.weights.setFromTriplets(triplets.begin(), triplets.end());
  return model;
}

EmbeddedModel embed_identity(TetMesh mesh) {
  EmbeddedModel model;
  model.factor = 1;
  model.weights.resize(mesh.V.rows(), mesh.V.rows());
  model.weights.setIdentity();
  model.host.resize(mesh.V.rows(), 4);
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
    model.host.row(v).setConstant(static_cast<int>(v));
  model.output = mesh;
  model.elements = std::move(mesh);
  return model;
}

void move_output_nodes(EmbeddedModel& model, const std::vector<int>& nodes,
                       const Eigen::MatrixX3d& positions) {
  if (positions.rows() != static_cast<Eigen::Index>(nodes.size()) || !positions.allFinite()) {
    throw InvalidInputError("coarse embedding: moved nodes need one finite position each");
  }
  const bool identity = model.factor == 1;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(model.weights.nonZeros()) + 4 * nodes.size());
  std::vector<char> moved(static_cast<std::size_t>(model.output.V.rows()), 0);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const int v = nodes[k];
    if (v < 0 || v >= model.output.V.rows()) {
      throw InvalidInputError("coarse embedding: output node " + std::to_string(v) +
                              " is out of range");
    }
    model.output.V.row(v) = positions.row(static_cast<Eigen::Index>(k));
    if (identity) {
      model.elements.V.row(v) = positions.row(static_cast<Eigen::Index>(k));
      continue;
    }
    moved[static_cast<std::size_t>(v)] = 1;
    // Barycentric coordinates in the host element: p = a + E w, E's columns
    // the edges from corner 0.
    const auto corner = [&](int c) -> Eigen::Vector3d {
      return model.elements.V.row(model.host(v, c)).transpose();
    };
    Eigen::Matrix3d e;
    for (int c = 0; c < 3; ++c) e.col(c) = corner(c + 1) - corner(0);
    const Eigen::Vector3d w =
        e.partialPivLu().solve(positions.row(static_cast<Eigen::Index>(k)).transpose() - corner(0));
    triplets.emplace_back(v, model.host(v, 0), 1.0 - w.sum());
    for (int c = 0; c < 3; ++c) triplets.emplace_back(v, model.host(v, c + 1), w[c]);
  }
  if (identity) return;
  for (int row = 0; row < model.weights.outerSize(); ++row) {
    if (moved[static_cast<std::size_t>(row)] != 0) continue;
    for (EmbeddingWeights::InnerIterator it(model.weights, row); it; ++it)
      triplets.emplace_back(row, static_cast<int>(it.col()), it.value());
  }
  model.weights.setFromTriplets(triplets.begin(), triplets.end());
}

}  // namespace mmm::volumetric
