#include "core/mesh/mesh.h"

#include <cmath>
#include <string>
#include <vector>

// clang-format off
#include "core/mesh/openmesh_begin.h"
#include <OpenMesh/Core/System/omstream.hh>
#include "core/mesh/openmesh_end.h"
// clang-format on

#include "core/errors.h"

namespace mmm::mesh {
namespace {

// OpenMesh's log streams (omlog, omout, omerr) are built by their first
// caller, and that first construction is not thread-safe: two nodes
// decimating at once on a fresh process could both connect the stream's
// targets and corrupt the heap (seen as a rare SIGSEGV of `mmm run -j 2`,
// in std::vector<basic_multiplex_target*>::_M_realloc_insert). Build them
// during static initialisation, before any thread exists; this file is
// linked into every program that converts to OpenMesh (to_halfedge).
const bool kOpenMeshStreamsReady = [] {
  omlog();
  omout();
  omerr();
  return true;
}();

}  // namespace

void validate_indices_and_coordinates(const IndexedMesh& mesh) {
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    if (!mesh.V.row(v).allFinite()) {
      throw InvalidInputError("vertex " + std::to_string(v) +
                              " has a non-finite coordinate (NaN or infinity)");
    }
  }
  const Eigen::Index num_vertices = mesh.V.rows();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int index = mesh.F(f, k);
      if (index < 0 || index >= num_vertices) {
        throw InvalidInputError("face " + std::to_string(f) + " refers to vertex " +
                                std::to_string(index) + " but the mesh has " +
                                std::to_string(num_vertices) + " vertices");
      }
    }
  }
}

Mesh to_halfedge(const IndexedMesh& indexed, ConversionReport* report) {
  validate_indices_and_coordinates(indexed);
  Mesh mesh;
  mesh.reserve(static_cast<size_t>(indexed.V.rows()), 3 * static_cast<size_t>(indexed.F.rows()),
               static_cast<size_t>(indexed.F.rows()));
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(static_cast<size_t>(indexed.V.rows()));
  for (Eigen::Index v = 0; v < indexed.V.rows(); ++v) {
    handles.push_back(
        mesh.add_vertex(Mesh::Point(indexed.V(v, 0), indexed.V(v, 1), indexed.V(v, 2))));
  }
  // OpenMesh prints to its error stream when it rejects a complex face; the
  // rejection is reported to the caller instead, so silence that stream.
  const bool was_enabled = omerr().is_enabled();
  omerr().disable();
  for (Eigen::Index f = 0; f < indexed.F.rows(); ++f) {
    const int a = indexed.F(f, 0);
    const int b = indexed.F(f, 1);
    const int c = indexed.F(f, 2);
    Mesh::FaceHandle face;
    if (a != b && b != c && a != c) {
      face = mesh.add_face(handles[static_cast<size_t>(a)], handles[static_cast<size_t>(b)],
                           handles[static_cast<size_t>(c)]);
    }
    if (!face.is_valid() && report != nullptr) report->rejected_faces.push_back(f);
  }
  if (was_enabled) omerr().enable();
  return mesh;
}

IndexedMesh to_indexed(const Mesh& mesh_in) {
  Mesh mesh = mesh_in;
  if (mesh.has_vertex_status() || mesh.has_face_status()) mesh.garbage_collection();
  IndexedMesh out;
  out.V.resize(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (const auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    out.V.row(vh.idx()) << p[0], p[1], p[2];
  }
  out.F.resize(static_cast<Eigen::Index>(mesh.n_faces()), 3);
  for (const auto fh : mesh.faces()) {
    int k = 0;
    for (const auto vh : mesh.fv_range(fh)) out.F(fh.idx(), k++) = vh.idx();
  }
  return out;
}

}  // namespace mmm::mesh
