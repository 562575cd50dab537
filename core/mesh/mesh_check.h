#pragma once
// Topological and geometric health report of a triangle mesh: what a user
// must know before trusting a volume, a signed distance or a deformation.
//
// Works on the face-vertex form so it can describe input that a half-edge
// structure cannot even hold (non-manifold edges, bow-tie vertices).
//   edges:      undirected edge -> incident faces; 1 face = boundary, >2 =
//               non-manifold, 2 faces traversing it the same way =
//               inconsistent orientation.
//   vertices:   the faces around a vertex, linked through the manifold edges
//               they share, must form a single fan; more fans = non-manifold
//               (bow-tie) vertex.
//   components: union-find over the vertices of each face.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct MeshCheckOptions {
  // Two distinct vertices closer than this (mm) count as duplicates.
  double duplicate_vertex_distance = 1e-6;
  // A face whose area is below this fraction of the squared bounding-box
  // diagonal counts as degenerate (zero area up to rounding of mm-sized data).
  double degenerate_area_fraction = 1e-14;
};

struct MeshCheckReport {
  Eigen::Index vertices = 0;
  Eigen::Index faces = 0;
  Eigen::Index edges = 0;
  Eigen::Index boundary_edges = 0;
  Eigen::Index boundary_loops = 0;
  Eigen::Index non_manifold_edges = 0;
  Eigen::Index non_manifold_vertices = 0;
  Eigen::Index inconsistently_oriented_edges = 0;
  Eigen::Index degenerate_faces = 0;
  Eigen::Index duplicate_vertices = 0;  // vertices coinciding with an earlier one
  Eigen::Index unreferenced_vertices = 0;
  Eigen::Index connected_components = 0;
  Eigen::Index euler_characteristic = 0;  // V - E + F over referenced vertices

  // Every edge has exactly two faces: the surface bounds a volume.
  [[nodiscard]] bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0; }
  [[nodiscard]] bool manifold() const {
    return non_manifold_edges == 0 && non_manifold_vertices == 0;
  }
  [[nodiscard]] bool orientation_consistent() const { return inconsistently_oriented_edges == 0; }
  // Closed, manifold and consistently oriented: volume, inside tests and
  // signed distance are well defined.
  [[nodiscard]] bool watertight() const {
    return closed() && manifold() && orientation_consistent();
  }
  // Watertight and in one piece: one solid's surface, as a bone's should be.
  [[nodiscard]] bool single_solid() const { return watertight() && connected_components == 1; }
  // One line per problem found, empty for a clean watertight mesh.
  [[nodiscard]] std::vector<std::string> problems() const;
};

// Throws InvalidInputError on out-of-range indices or non-finite coordinates.
MeshCheckReport check_mesh(const IndexedMesh& mesh, const MeshCheckOptions& options = {});

}  // namespace mmm::mesh
