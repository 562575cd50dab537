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

// Places fine grid node `at` (row v of the output) in the coarse cell that
// holds it, floor(at / factor), or the one below along an axis where the
// node lies on a coarse cell face, the first for which `simulated(cell)`;
// its four corners' nodes from `node_of(grid)`. False when no cell holds it.
template <typename Simulated, typename NodeOf>
bool place_node(const Eigen::Array3i& at, int factor, const Eigen::Array3i& cells,
                const Simulated& simulated, const NodeOf& node_of, EmbeddedModel& model,
                Eigen::Index v, std::vector<Eigen::Triplet<double>>& triplets) {
  for (int option = 0; option < 8; ++option) {
    Eigen::Array3i cell;
    bool valid = true;
    for (int a = 0; a < 3; ++a) {
      cell[a] = at[a] / factor;
      if ((option >> a) & 1) {
        valid = valid && at[a] % factor == 0 && cell[a] > 0;
        cell[a] -= 1;
      }
      valid = valid && cell[a] < cells[a];
    }
    if (!valid || !simulated(cell)) continue;
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
      const int node = node_of(grid);
      model.host(v, c) = node;
      if (weights[static_cast<std::size_t>(c)] > 0.0)
        triplets.emplace_back(static_cast<int>(v), node, weights[static_cast<std::size_t>(c)]);
    }
    return true;
  }
  return false;
}

Eigen::Array3i grid_of(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, double spacing) {
  return ((p - origin) / spacing).array().round().cast<int>();
}

// Every output node of `model` placed in its coarse cell (place_node) and
// the weights set: `simulated(v, cell)` and `node_of(v, grid)` for output
// node v. Throws InvalidInputError for a node no simulated cell holds.
template <typename Simulated, typename NodeOf>
void embed_output_nodes(EmbeddedModel& model, const LabelledLattice& fine, int factor,
                        const Eigen::Array3i& cells, const Simulated& simulated,
                        const NodeOf& node_of) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(model.output.V.rows()) * 4);
  model.host.resize(model.output.V.rows(), 4);
  for (Eigen::Index v = 0; v < model.output.V.rows(); ++v) {
    const Eigen::Array3i at =
        grid_of(model.output.V.row(v).transpose(), fine.origin, fine.spacing_mm);
    const bool placed = place_node(
        at, factor, cells, [&](const Eigen::Array3i& cell) { return simulated(v, cell); },
        [&](const Eigen::Array3i& grid) { return node_of(v, grid); }, model, v, triplets);
    if (!placed) {
      throw InvalidInputError("coarse embedding: fine node " + std::to_string(v) +
                              " lies in no simulated coarse cell");
    }
  }
  model.weights.resize(model.output.V.rows(), model.elements.V.rows());
  model.weights.setFromTriplets(triplets.begin(), triplets.end());
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
  embed_output_nodes(
      model, fine, factor, coarse.cells,
      [&](Eigen::Index, const Eigen::Array3i& cell) {
        return coarse.at(cell.x(), cell.y(), cell.z()) != 0;
      },
      [&](Eigen::Index, const Eigen::Array3i& grid) { return coarse_node.at(key_of(grid)); });
  return model;
}

EmbeddedModel embed_muscles_separately(const LabelledLattice& fine, int factor) {
  if (factor < 1) {
    throw InvalidInputError("coarse embedding: the factor must be at least 1, got " +
                            std::to_string(factor));
  }
  const TetMesh shared = lattice_tets(fine);
  if (shared.T.rows() == 0) {
    throw InvalidInputError("coarse embedding: the lattice has no muscle cell");
  }
  // One copy of a node per muscle around it, in the order first met.
  TetMesh output;
  output.T.resize(shared.T.rows(), 4);
  output.label = shared.label;
  std::vector<std::vector<int>> copies(static_cast<std::size_t>(shared.V.rows()));
  std::vector<std::uint16_t> node_label;
  std::vector<int> original;
  for (Eigen::Index t = 0; t < shared.T.rows(); ++t) {
    const std::uint16_t label = shared.label[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a) {
      std::vector<int>& list = copies[static_cast<std::size_t>(shared.T(t, a))];
      const auto mine = std::ranges::find_if(
          list, [&](int c) { return node_label[static_cast<std::size_t>(c)] == label; });
      if (mine != list.end()) {
        output.T(t, a) = *mine;
        continue;
      }
      const auto copy = static_cast<int>(node_label.size());
      node_label.push_back(label);
      original.push_back(shared.T(t, a));
      list.push_back(copy);
      output.T(t, a) = copy;
    }
  }
  output.V.resize(static_cast<Eigen::Index>(original.size()), 3);
  for (std::size_t v = 0; v < original.size(); ++v)
    output.V.row(static_cast<Eigen::Index>(v)) = shared.V.row(original[v]);
  std::vector<InterfacePair> interfaces;
  for (const std::vector<int>& list : copies) {
    for (std::size_t k = 1; k < list.size(); ++k) interfaces.push_back({list.front(), list[k]});
  }
  if (factor == 1) {
    EmbeddedModel model = embed_identity(std::move(output));
    model.interfaces = std::move(interfaces);
    return model;
  }
  // Per muscle, its coarse cells (those holding one of its fine cells) as
  // a lattice over their bounding box, and its elements.
  LabelledLattice coarse;
  coarse.origin = fine.origin;
  coarse.spacing_mm = fine.spacing_mm * factor;
  coarse.cells = (fine.cells + factor - 1) / factor;
  const std::size_t labels = fine.muscles.size();
  std::vector<std::vector<std::int64_t>> cells_of(labels + 1);
  for (int k = 0; k < fine.cells.z(); ++k) {
    for (int j = 0; j < fine.cells.y(); ++j) {
      for (int i = 0; i < fine.cells.x(); ++i) {
        const std::uint16_t label = fine.at(i, j, k);
        if (label != 0 && label <= labels)
          cells_of[label].push_back(coarse.index(i / factor, j / factor, k / factor));
      }
    }
  }
  struct Part {
    LabelledLattice cells;
    Eigen::Array3i low = Eigen::Array3i::Zero();
    std::unordered_map<GridKey, int> node;
  };
  std::vector<Part> parts(labels + 1);
  EmbeddedModel model;
  model.factor = factor;
  std::vector<Eigen::Vector3d> element_nodes;
  std::vector<std::array<int, 4>> element_tets;
  for (std::size_t l = 1; l <= labels; ++l) {
    std::vector<std::int64_t>& list = cells_of[l];
    if (list.empty()) continue;
    std::ranges::sort(list);
    list.erase(std::unique(list.begin(), list.end()), list.end());
    const auto cell_at = [&](std::int64_t index) {
      const auto x = static_cast<int>(index % coarse.cells.x());
      const auto y = static_cast<int>((index / coarse.cells.x()) % coarse.cells.y());
      const auto z = static_cast<int>(
          index / (static_cast<std::int64_t>(coarse.cells.x()) * coarse.cells.y()));
      return Eigen::Array3i(x, y, z);
    };
    Eigen::Array3i low = cell_at(list.front());
    Eigen::Array3i high = low;
    for (const std::int64_t index : list) {
      low = low.min(cell_at(index));
      high = high.max(cell_at(index));
    }
    Part& part = parts[l];
    part.low = low;
    part.cells.origin = coarse.origin + coarse.spacing_mm * low.cast<double>().matrix();
    part.cells.spacing_mm = coarse.spacing_mm;
    part.cells.cells = high - low + 1;
    part.cells.muscles = fine.muscles;
    part.cells.label.assign(static_cast<std::size_t>(part.cells.cells.prod()), 0);
    for (const std::int64_t index : list) {
      const Eigen::Array3i at = cell_at(index) - low;
      part.cells.label[static_cast<std::size_t>(part.cells.index(at.x(), at.y(), at.z()))] =
          static_cast<std::uint16_t>(l);
    }
    const TetMesh tets = lattice_tets(part.cells);
    const auto offset = static_cast<int>(element_nodes.size());
    for (Eigen::Index v = 0; v < tets.V.rows(); ++v) {
      element_nodes.emplace_back(tets.V.row(v).transpose());
      part.node.emplace(
          key_of(grid_of(tets.V.row(v).transpose(), coarse.origin, coarse.spacing_mm)),
          offset + static_cast<int>(v));
    }
    for (Eigen::Index t = 0; t < tets.T.rows(); ++t) {
      element_tets.push_back({offset + tets.T(t, 0), offset + tets.T(t, 1), offset + tets.T(t, 2),
                              offset + tets.T(t, 3)});
      model.elements.label.push_back(static_cast<std::uint16_t>(l));
    }
  }
  model.elements.V.resize(static_cast<Eigen::Index>(element_nodes.size()), 3);
  for (std::size_t v = 0; v < element_nodes.size(); ++v)
    model.elements.V.row(static_cast<Eigen::Index>(v)) = element_nodes[v].transpose();
  model.elements.T.resize(static_cast<Eigen::Index>(element_tets.size()), 4);
  for (std::size_t t = 0; t < element_tets.size(); ++t)
    for (int a = 0; a < 4; ++a)
      model.elements.T(static_cast<Eigen::Index>(t), a) =
          element_tets[t][static_cast<std::size_t>(a)];
  model.output = std::move(output);
  model.interfaces = std::move(interfaces);
  const auto part_of = [&](Eigen::Index v) -> const Part& {
    return parts[node_label[static_cast<std::size_t>(v)]];
  };
  embed_output_nodes(
      model, fine, factor, coarse.cells,
      [&](Eigen::Index v, const Eigen::Array3i& cell) {
        const Part& part = part_of(v);
        const Eigen::Array3i local = cell - part.low;
        return (local >= 0).all() && (local < part.cells.cells).all() &&
               part.cells.at(local.x(), local.y(), local.z()) != 0;
      },
      [&](Eigen::Index v, const Eigen::Array3i& grid) { return part_of(v).node.at(key_of(grid)); });
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
