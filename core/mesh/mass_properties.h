#pragma once
// Size, position and shape of a triangle mesh: area, enclosed signed volume,
// centroid, second moments, principal axes, bounding boxes.
//
// Volume and second moments use the divergence theorem: every face and the
// reference point span a signed tetrahedron; summing their volumes and
// covariances (Tonon 2004, "Explicit exact formulas for the 3-D tetrahedron
// inertia tensor") gives the solid's exact values for a closed, consistently
// oriented mesh. The reference point is the bounding-box centre, which keeps
// the sums well conditioned for meshes far from the origin (VHF is ~600 mm
// away from it).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Sum of triangle areas (mm^2).
double surface_area(const IndexedMesh& mesh);

// Enclosed signed volume (mm^3): positive when the faces are oriented
// outward, negative when inward. Meaningful only for a closed mesh with
// consistent orientation (see check_mesh); an open mesh gets the volume of
// the cone from its bounding-box centre, which is not a property of the shape.
double signed_volume(const IndexedMesh& mesh);

// Axis-aligned bounding box of the vertices.
Eigen::AlignedBox3d bounding_box(const IndexedMesh& mesh);

struct MassProperties {
  double area = 0;    // mm^2
  double volume = 0;  // mm^3, signed (see signed_volume)
  // Centroid of the enclosed solid when it has a non-zero volume (a solid),
  // otherwise the area-weighted centroid of the surface.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  bool solid = false;  // true when the solid's values were used
  // Second moment about the centroid, integral of (x - c)(x - c)^T over the
  // solid (mm^5) or over the surface (mm^4) when not a solid.
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();
  // Columns: unit principal axes, ordered by decreasing spread of the shape
  // (column 0 is the long axis); right-handed.
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();
  // Moments of inertia about those axes for unit density (mm^5 for a solid).
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();
};

// Throws InvalidInputError for a mesh without faces or with invalid data.
MassProperties mass_properties(const IndexedMesh& mesh);

// A box with arbitrary orientation: centre + axes * [-h, h].
struct OrientedBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns, unit, right-handed
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();

  [[nodiscard]] double volume() const { return 8.0 * half_extents.prod(); }
  [[nodiscard]] bool contains(const Eigen::Vector3d& point, double tolerance = 0) const;
};

// Box aligned with the principal axes of the mesh and tight around its
// vertices (not the minimum-volume box, but the one whose axes follow the
// shape; for a muscle, axis 0 runs from origin to insertion).
OrientedBox oriented_bounding_box(const IndexedMesh& mesh);

}  // namespace mmm::mesh
