#pragma once
// The mesh types of mmm.
//
// IndexedMesh is the plain face-vertex form (Eigen V, F) that readers return,
// that checks inspect (it can hold non-manifold input faithfully) and that the
// numerical kernels take, libigl style. Mesh is the half-edge form (OpenMesh,
// double-precision points) used where topology is walked or edited:
// decimation, hulls, remeshing.

#include <Eigen/Core>
#include <cstddef>

// clang-format off
#include "core/mesh/openmesh_begin.h"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include "core/mesh/openmesh_end.h"
// clang-format on

namespace mmm::mesh {

// V  #V by 3 vertex positions (mm unless a caller says otherwise)
// F  #F by 3 vertex indices into V, counter-clockwise seen from outside
struct IndexedMesh {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i F;

  [[nodiscard]] Eigen::Index num_vertices() const { return V.rows(); }
  [[nodiscard]] Eigen::Index num_faces() const { return F.rows(); }
  [[nodiscard]] bool empty() const { return F.rows() == 0; }
};

struct DoubleTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using Mesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

// A point of the half-edge form as an Eigen vector, and back.
inline Eigen::Vector3d to_eigen(const Mesh::Point& p) { return {p[0], p[1], p[2]}; }
inline Mesh::Point to_mesh_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// Faces OpenMesh refused while building the half-edge form (a face that would
// make an edge non-manifold, or repeats a vertex). Indices into the input F.
struct ConversionReport {
  std::vector<Eigen::Index> rejected_faces;
};

// Builds the half-edge mesh. Faces that a half-edge structure cannot hold are
// skipped and listed in *report when given; throws InvalidInputError on an
// index out of range or a non-finite coordinate.
Mesh to_halfedge(const IndexedMesh& indexed, ConversionReport* report = nullptr);

// Back to face-vertex form; deleted elements are dropped (garbage collected).
IndexedMesh to_indexed(const Mesh& mesh);

// Throws InvalidInputError naming the first offending vertex or face when a
// coordinate is not finite or a face index is outside [0, #V).
void validate_indices_and_coordinates(const IndexedMesh& mesh);

}  // namespace mmm::mesh
