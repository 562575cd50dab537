#pragma once
// Bounding-volume hierarchy of axis-aligned boxes over the triangles of an
// IndexedMesh: exact closest point and ray queries in O(log #F) on average.
//
// Build (top down, once):
//   node(faces): box = bounds of the faces' vertices
//     if #faces <= max_leaf_size: leaf
//     else: axis = longest axis of the box of the face centroids
//           split the faces at the median centroid along that axis (nth_element)
//           node(lower half), node(upper half)
// The median split (rather than the surface area heuristic) keeps the tree
// balanced whatever the triangle sizes: depth <= ceil(log2 #F), build
// O(#F log #F), and a fixed 64-entry stack always suffices for traversal.
// Nodes live in one flat array in depth-first order (first child = next node).
// Closest-point queries walk a compact copy of it: both child boxes of a node
// side by side, in floats rounded outwards (56 bytes per inner node), and the
// faces as indices into vertex positions renumbered in leaf order, which keeps
// the working set of a 48K-face mesh near 2 MB. Queries allocate nothing
// (all_hits excepted: it returns a vector) and use a fixed-size stack.
//
// Closest point: branch and bound, nearest child first, boxes pruned by their
// squared distance to the query; point-triangle distance by Voronoi regions
// (Ericson, "Real-Time Collision Detection", 2005, section 5.1.5).
// Rays: slab test per box (zero direction components handled without
// infinities), Moller & Trumbore 1997 per triangle.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <optional>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

class AabbTree {
 public:
  struct Options {
    // Largest number of triangles in a leaf (>= 1). Smaller leaves mean tighter
    // boxes but more nodes; 4 is the usual sweet spot for closest-point queries.
    int max_leaf_size = 4;
  };

  // One box of the hierarchy. Every node (leaf or not) covers the contiguous
  // range [begin, end) of face_order(); an inner node's first child is the
  // node right after it in nodes(), its second child is nodes()[second_child].
  struct Node {
    Eigen::AlignedBox3d box;  // bounds of the covered triangles (mm)
    int begin = 0;
    int end = 0;
    int second_child = -1;  // -1 for a leaf
    [[nodiscard]] bool is_leaf() const { return second_child < 0; }
  };

  // Closest point of the surface to a query.
  //   point             on the surface (mm)
  //   face              row of F holding it
  //   squared_distance  |query - point|^2 (mm^2)
  //   barycentric       weights of V(F(face, 0..2)) giving point, in [0, 1] up to
  //                     rounding
  struct ClosestPoint {
    Eigen::Vector3d point;
    int face = -1;
    double squared_distance = std::numeric_limits<double>::infinity();
    Eigen::Vector3d barycentric;
  };

  // A ray-triangle intersection at origin + t * direction.
  //   t            ray parameter, in units of the direction's length
  //   face         row of F that is hit
  //   barycentric  weights of V(F(face, 0..2)) giving the hit point
  struct RayHit {
    double t = 0;
    int face = -1;
    Eigen::Vector3d barycentric;
  };

  // Builds the tree over its own copy of `mesh` (pass an rvalue to move it
  // in; the caller's mesh may die after). Throws InvalidInputError when the
  // mesh has no face, a non-finite coordinate, a face index out of range, or
  // when max_leaf_size < 1.
  explicit AabbTree(IndexedMesh mesh);
  AabbTree(IndexedMesh mesh, const Options& options);

  // Exact closest point of the surface to `query` (mm). Ties between faces at
  // the same distance go to one of them. Throws InvalidInputError when the
  // query is not finite.
  [[nodiscard]] ClosestPoint closest_point(const Eigen::Vector3d& query) const;

  // Same, restricted to the ball of squared radius max_squared_distance (mm^2):
  // std::nullopt when no surface point lies that close. A tight bound (e.g. the
  // squared distance to a previous answer for a nearby query) prunes more of
  // the tree; the answer is the same as closest_point whenever it exists.
  [[nodiscard]] std::optional<ClosestPoint> closest_point_within(const Eigen::Vector3d& query,
                                                                 double max_squared_distance) const;

  // First triangle hit by origin + t * direction for t in [0, t_max]. The
  // direction need not be unit length (t is in its units) but must be non-zero.
  // A ray lying in the plane of a triangle does not hit it. Hits up to 1e-10
  // (in barycentric units) outside a triangle count, so a ray through a shared
  // edge or vertex never slips between the faces. Throws InvalidInputError on a
  // zero or non-finite direction, a non-finite origin or a NaN t_max.
  [[nodiscard]] std::optional<RayHit> first_hit(
      const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
      double t_max = std::numeric_limits<double>::infinity()) const;

  // Every crossing of the ray with the surface for t in [0, t_max], sorted by
  // t. Hits at the same point (within 1e-9 of the bounding-box diagonal) on
  // faces sharing a vertex are one crossing of the surface through their shared
  // edge or vertex and are reported once (the first face found). Same
  // conventions and errors as first_hit.
  [[nodiscard]] std::vector<RayHit> all_hits(
      const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
      double t_max = std::numeric_limits<double>::infinity()) const;

  // The tree's own copy of the mesh.
  [[nodiscard]] const IndexedMesh& mesh() const { return mesh_; }
  // Bounds of all vertices referenced by a face (mm).
  [[nodiscard]] Eigen::AlignedBox3d bounds() const { return nodes_.front().box; }
  [[nodiscard]] int num_nodes() const { return static_cast<int>(nodes_.size()); }
  // Depth of the deepest leaf (the root alone has depth 0).
  [[nodiscard]] int depth() const { return depth_; }
  // The hierarchy, root first (see Node), and the faces in leaf order:
  // face_order()[i] is a row of F.
  [[nodiscard]] const std::vector<Node>& nodes() const { return nodes_; }
  [[nodiscard]] const std::vector<int>& face_order() const { return face_order_; }

 private:
  // The inner nodes again, compacted for closest-point traversal: both child
  // boxes side by side (lane j of lo[axis] is child j), in floats rounded
  // outwards, so that one visit reads one 56-byte block and computes both box
  // distances at once. child[j] >= 0 is another pair; child[j] < 0 is the
  // leaf ~child[j], holding corners_[leaf_start_[leaf], leaf_start_[leaf + 1]).
  struct ChildPair {
    std::array<Eigen::Array2f, 3> lo;
    std::array<Eigen::Array2f, 3> hi;
    std::array<int, 2> child{};
  };

  void build(const Options& options);
  void build_compact();
  [[nodiscard]] ClosestPoint search_closest(const Eigen::Vector3d& query, double bound) const;
  void check_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 double t_max) const;
  [[nodiscard]] bool share_vertex(int face_a, int face_b) const;

  IndexedMesh mesh_;
  std::vector<Node> nodes_;
  std::vector<int> face_order_;
  // Query-side copy of the geometry, small enough to stay in cache: vertex
  // positions renumbered in order of first use by the leaves, and the corners
  // of each face (in face_order_) as indices into points_.
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<int, 3>> corners_;
  std::vector<ChildPair> pairs_;  // pairs_[0] is the root unless the root is a leaf
  std::vector<int> leaf_start_;   // #leaves + 1 offsets into corners_
  double box_pad_ = 0;            // boxes are inflated by this much for ray tests (mm)
  int depth_ = 0;
};

}  // namespace mmm::mesh
