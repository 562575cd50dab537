// Quadric-error decimation (Garland & Heckbert 1997, "Surface simplification
// using quadric error metrics") through OpenMesh's Decimater:
//
//   lock boundary vertices (optional)
//   heap of vertices keyed by their cheapest legal half-edge collapse v0 -> v1
//   while #F > target and the heap is not empty:
//     pop v0; if the collapse is still legal (link condition, not locked, no
//     face normal turned by more than the limit): collapse, merge quadrics,
//     re-key the one-ring
//
// Half-edge collapses keep v1 where it is, so the output is a subset of the
// input vertices and no new point can leave the input's bounding box.

#include "core/mesh/decimate.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/errors.h"

// clang-format off
#include "core/mesh/openmesh_begin.h"
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include "core/mesh/openmesh_end.h"
// clang-format on

namespace mmm::mesh {
namespace {

using Decimater = OpenMesh::Decimater::DecimaterT<Mesh>;
using QuadricHandle = OpenMesh::Decimater::ModQuadricT<Mesh>::Handle;
using NormalFlippingHandle = OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle;

void validate_options(const DecimateOptions& options) {
  if (options.target_faces < 4) {
    throw InvalidInputError("decimate: target_faces must be >= 4 (a tetrahedron), got " +
                            std::to_string(options.target_faces));
  }
  const double angle = options.max_normal_deviation_degrees;
  if (!std::isfinite(angle) || angle <= 0.0 || angle > 180.0) {
    throw InvalidInputError("decimate: max_normal_deviation_degrees must be in (0, 180], got " +
                            std::to_string(angle) +
                            "; use 180 to allow any collapse that does not flip a face");
  }
}

}  // namespace

IndexedMesh decimate(const IndexedMesh& mesh, const DecimateOptions& options,
                     DecimateReport* report) {
  validate_options(options);
  validate_indices_and_coordinates(mesh);
  if (report != nullptr) {
    report->faces_before = mesh.num_faces();
    report->faces_after = mesh.num_faces();
  }
  if (options.target_faces >= mesh.num_faces()) return mesh;

  ConversionReport conversion;
  Mesh halfedge = to_halfedge(mesh, &conversion);
  if (!conversion.rejected_faces.empty()) {
    throw InvalidInputError(
        "decimate: face " + std::to_string(conversion.rejected_faces.front()) + " (and " +
        std::to_string(conversion.rejected_faces.size() - 1) +
        " more) cannot be part of a manifold half-edge mesh (non-manifold edge, repeated vertex "
        "or inconsistent orientation); repair the mesh before decimating it");
  }

  // Status flags are requested here (not only by the Decimater, which
  // releases them when destroyed) so that garbage collection below sees the
  // deleted elements. Face normals are computed up front: the normal-flipping
  // module needs them and would otherwise announce on OpenMesh's omerr()
  // stream that it computes them, the only thing the Decimater prints.
  halfedge.request_vertex_status();
  halfedge.request_edge_status();
  halfedge.request_face_status();
  halfedge.request_face_normals();
  halfedge.update_face_normals();
  if (options.preserve_boundary) {
    for (const auto vh : halfedge.vertices()) {
      if (halfedge.is_boundary(vh)) halfedge.status(vh).set_locked(true);
    }
  }
  {
    Decimater decimater(halfedge);
    QuadricHandle quadric;
    NormalFlippingHandle normal_flipping;
    decimater.add(quadric);
    decimater.add(normal_flipping);
    decimater.module(quadric).unset_max_err();
    decimater.module(normal_flipping)
        .set_max_normal_deviation(options.max_normal_deviation_degrees);
    if (!decimater.initialize()) {
      throw std::logic_error(
          "decimate: OpenMesh's Decimater refused its module set (quadric priority plus normal "
          "flipping); this is a bug in mmm, not in the input");
    }
    decimater.decimate_to_faces(0, static_cast<size_t>(options.target_faces));
  }
  halfedge.delete_isolated_vertices();
  halfedge.garbage_collection();
  IndexedMesh result = to_indexed(halfedge);
  if (report != nullptr) report->faces_after = result.num_faces();
  return result;
}

}  // namespace mmm::mesh
