#pragma once
// Tetrahedra for a labelled lattice (labelled_lattice.h): every muscle cell
// is split into six tetrahedra around its main diagonal, the same split in
// every cell (Kuhn's), so that neighbouring cells agree on their shared face's
// diagonal and the mesh is conforming. Cells of different muscles share the
// nodes of their common faces: the interface between two touching muscles is
// one set of nodes, there is no gap and no overlap to keep consistent.
//
// A muscle's surface for the outputs is the boundary of its tetrahedra: the
// faces of its tetrahedra that no other tetrahedron of it shares, oriented
// outwards. It is closed, and it encloses exactly the muscle's cells.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/mesh/mesh.h"
#include "core/volumetric/labelled_lattice.h"

namespace mmm::volumetric {

using TetIndices = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

struct TetMesh {
  Eigen::MatrixX3d V;                // nodes (mm): the corners of the labelled cells
  TetIndices T;                      // positively oriented (volume > 0)
  std::vector<std::uint16_t> label;  // per tetrahedron: k + 1 for the k-th muscle
};

TetMesh lattice_tets(const LabelledLattice& lattice);

// Signed volume of each tetrahedron (mm^3).
Eigen::VectorXd tet_volumes(const TetMesh& mesh);

// The boundary of the tetrahedra labelled `label`, outward, as a surface on
// the tet mesh's own nodes (V is the whole node array; unused rows stay).
// Throws InvalidInputError when no tetrahedron has that label.
mesh::IndexedMesh label_boundary(const TetMesh& mesh, std::uint16_t label);

}  // namespace mmm::volumetric
