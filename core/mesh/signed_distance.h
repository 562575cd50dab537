#pragma once
// Signed distance to a triangle mesh: magnitude from the exact closest point
// (AabbTree), sign from the generalized winding number (WindingNumber,
// Barill et al. 2018), which stays robust on meshes with small holes,
// self-intersections or duplicated faces where pseudo-normal signs fail.
//   sd(q) = (w(q) > 1/2 ? -1 : +1) * |q - closest_point(q)|

#include <Eigen/Core>
#include <memory>

#include "core/mesh/aabb_tree.h"
#include "core/mesh/mesh.h"
#include "core/mesh/winding_number.h"

namespace mmm::mesh {

class SignedDistance {
 public:
  struct Options {
    AabbTree::Options tree;
    WindingNumber::Options winding;
  };

  // Builds the tree and the winding-number moments over a copy of `mesh`
  // (V #V by 3 in mm, F #F by 3, closed and outward oriented for a meaningful
  // sign). Throws InvalidInputError on an empty or invalid mesh or options.
  // Movable (the tree lives on the heap, so the winding number's reference to
  // it survives a move); not copyable.
  explicit SignedDistance(const IndexedMesh& mesh);
  SignedDistance(const IndexedMesh& mesh, const Options& options);

  // Signed distance at q (mm): negative inside, positive outside. Throws
  // InvalidInputError when q is not finite. Const and thread-safe.
  [[nodiscard]] double at(const Eigen::Vector3d& q) const;

  // Any 3-vector expression (Vector3d::Zero(), p + offset, ...): without this
  // it would convert to both overloads and be ambiguous.
  template <typename Derived>
  requires(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 1)
      [[nodiscard]] double at(const Eigen::MatrixBase<Derived>& q) const {
    return at(Eigen::Vector3d(q));
  }

  // Batch form: points #P by 3 (mm) -> #P signed distances (mm), in order.
  [[nodiscard]] Eigen::VectorXd at(const Eigen::MatrixX3d& points) const;

  [[nodiscard]] const AabbTree& tree() const { return *tree_; }
  [[nodiscard]] const WindingNumber& winding() const { return winding_; }

 private:
  std::unique_ptr<AabbTree> tree_;
  WindingNumber winding_;
};

}  // namespace mmm::mesh
