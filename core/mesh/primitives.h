#pragma once
// Closed, consistently outward-oriented primitive meshes with known analytic
// volume, area and distance fields: the reference cases for every numerical
// check, and the shapes of wrap obstacles.

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Icosahedron subdivided `subdivisions` times (each step splits every
// triangle into four), vertices projected onto the sphere.
// #F = 20 * 4^subdivisions, #V = 10 * 4^subdivisions + 2.
IndexedMesh make_icosphere(int subdivisions, double radius = 1.0,
                           const Eigen::Vector3d& center = Eigen::Vector3d::Zero());

// Axis-aligned box [min, max] as 12 triangles (8 vertices).
IndexedMesh make_box(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner);

// Torus around the z axis: tube centre circle of radius major_radius, tube
// radius minor_radius; major_segments x minor_segments quads, each split in two.
IndexedMesh make_torus(double major_radius, double minor_radius, int major_segments,
                       int minor_segments);

// Closed cylinder along z from z = 0 to z = height: side of `segments` quads
// plus two fan caps with centre vertices.
IndexedMesh make_cylinder(double radius, double height, int segments);

}  // namespace mmm::mesh
