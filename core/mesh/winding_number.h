#pragma once
// Generalized winding number of a triangle mesh (Jacobson, Kavan & Sorkine-
// Hornung 2013, "Robust inside-outside segmentation using generalized winding
// numbers"): w(q) = sum over faces of the signed solid angle the face subtends
// at q, divided by 4 pi. For a closed outward-oriented surface w is 1 inside
// and 0 outside; on a surface with small holes it stays close to those values
// away from the holes, so w > 1/2 is a robust inside test.
//
// Hierarchical evaluation (Barill, Dickson, Schmidt, Levin & Jacobson 2018,
// "Fast winding numbers for soups and clouds"), over the boxes of an AabbTree.
// The solid angle of a patch is the integral of n . f(x) dA with the kernel
// f(x) = (x - q) / |x - q|^3. Far from q, f is Taylor-expanded to second order
// around the patch's area-weighted centroid p, which leaves three moments of
// the patch (exact for flat triangles) to precompute per node:
//   N   = integral of n dA                   (sum of the faces' vector areas)
//   M   = integral of n (x - p)^T dA          (3 x 3)
//   T_i = integral of n_i (x - p)(x - p)^T dA  (i = 0..2, each 3 x 3 symmetric)
// and r = max distance from p to a vertex of the node. With d = p - q:
//   omega ~ N.d / |d|^3                                       (dipole)
//         + tr(M) / |d|^3 - 3 d.M d / |d|^5                   (first order)
//         - 3 (2 sum_i (T_i d)_i + d.tr(T)) / (2 |d|^5)
//         + 15 sum_i d_i d.T_i d / (2 |d|^7)                   (second order)
// at(q): visit nodes from the root;
//     |d| > beta * r ->  add the expansion above
//     leaf           ->  add the exact solid angle of each face
//                        (Van Oosterom & Strackee 1983)
//     otherwise      ->  visit both children
//   w = total / (4 pi)
// At beta = 2 the dipole alone errs by up to ~7e-2 where all far nodes add up
// coherently (inside a sphere); with the two further orders the error stays
// below 1e-2 (measured: up to 4e-3 on spheres and tori, 6e-3 on a muscle).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/mesh/aabb_tree.h"
#include "core/mesh/mesh.h"

namespace mmm::mesh {

class WindingNumber {
 public:
  struct Options {
    // A node is far from q, and replaced by its expansion, when |q - centre| >
    // beta * radius. Must be > 1 (q outside the node's ball); larger is more
    // accurate and slower. 2 keeps the error below 1e-2 (see above).
    double beta = 2.0;
  };

  // Precomputes the per-node sums over `tree`. Lifetime: keeps a reference to
  // `tree`, which must outlive this object and every copy of it (SignedDistance
  // owns both for you). Throws InvalidInputError when beta <= 1 or is not finite.
  explicit WindingNumber(const AabbTree& tree);
  WindingNumber(const AabbTree& tree, const Options& options);
  // A temporary tree would dangle.
  explicit WindingNumber(AabbTree&& tree) = delete;
  WindingNumber(AabbTree&& tree, const Options& options) = delete;

  // Generalized winding number at q (mm): ~1 inside, ~0 outside a closed
  // outward-oriented surface, ~1/2 on it. Throws InvalidInputError when q is
  // not finite. Const and thread-safe.
  [[nodiscard]] double at(const Eigen::Vector3d& q) const;

  // at(q) > 0.5.
  [[nodiscard]] bool is_inside(const Eigen::Vector3d& q) const { return at(q) > 0.5; }

  [[nodiscard]] const AabbTree& tree() const { return *tree_; }
  [[nodiscard]] const Options& options() const { return options_; }

 private:
  // What every visit reads (kept small so the traversal stays in cache).
  struct NodeBall {
    Eigen::Vector3d centre;  // area-weighted centroid p (mm)
    double far_squared = 0;  // (beta * r)^2 (mm^2)
    int second_child = -1;   // as in AabbTree::Node; -1 for a leaf
    int begin = 0;           // leaf: faces [begin, end) of face_order()
    int end = 0;
  };
  // What a far visit reads: N (mm^2), M row-major (mm^3), and the six
  // distinct entries xx, yy, zz, xy, xz, yz of each symmetric T_i (mm^4).
  struct NodeExpansion {
    Eigen::Vector3d vector_area;
    std::array<double, 9> first{};
    std::array<std::array<double, 6>, 3> second{};
  };
  struct Corners {
    Eigen::Vector3d a;
    Eigen::Vector3d b;
    Eigen::Vector3d c;
  };

  // The expansion of the header comment, for d = centre - q, d2 = |d|^2.
  static double far_field(const NodeExpansion& expansion, const Eigen::Vector3d& d, double d2);

  const AabbTree* tree_;
  Options options_;
  std::vector<NodeBall> balls_;            // per node of tree_->nodes()
  std::vector<NodeExpansion> expansions_;  // per node of tree_->nodes()
  std::vector<Corners> corners_;           // per face, in tree_->face_order()
};

// Exact generalized winding number at q: the sum over all faces, O(#F). The
// reference for tests and for one-off queries. Throws InvalidInputError on an
// invalid mesh or a non-finite q.
//   mesh  V #V by 3 (mm), F #F by 3, outward counter-clockwise
double winding_number_exact(const IndexedMesh& mesh, const Eigen::Vector3d& q);

}  // namespace mmm::mesh
