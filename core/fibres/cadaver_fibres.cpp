#include "core/fibres/cadaver_fibres.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>

#include "core/errors.h"
#include "core/fibres/constrained_spline.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector3d;

void check_options(const CadaverFibreOptions& options) {
  if (options.segments < 1 || options.surface_fibres < 2 || options.depth_layers < 1) {
    throw InvalidInputError(
        "cadaver fibres: options need segments >= 1, surface_fibres >= 2 and depth_layers >= 1, "
        "got " +
        std::to_string(options.segments) + ", " + std::to_string(options.surface_fibres) + ", " +
        std::to_string(options.depth_layers));
  }
}

Vector3d row(const Fibre& fibre, Eigen::Index i) { return fibre.row(i).transpose(); }

// Normalised arc length at each point of a measured fibre; throws for too
// few, non-finite or repeated points.
std::vector<double> arc_length(const Fibre& fibre, std::size_t index) {
  const std::string name = "cadaver fibres: measured fibre " + std::to_string(index);
  if (fibre.rows() < 2) {
    throw InvalidInputError(name + " has " + std::to_string(fibre.rows()) +
                            " points; at least 2 are needed");
  }
  if (!fibre.allFinite()) throw InvalidInputError(name + " has a non-finite point (NaN or inf)");
  std::vector<double> t(static_cast<std::size_t>(fibre.rows()), 0.0);
  for (Eigen::Index i = 1; i < fibre.rows(); ++i)
    t[static_cast<std::size_t>(i)] =
        t[static_cast<std::size_t>(i - 1)] + (row(fibre, i) - row(fibre, i - 1)).norm();
  const double length = t.back();
  for (double& value : t) value /= length;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      throw InvalidInputError(name + ": points " + std::to_string(i - 1) + " and " +
                              std::to_string(i) + " coincide; hint: drop repeated points");
    }
  }
  return t;
}

// The fibre resampled at t = i / segments by a constrained spline per coordinate.
Fibre resample_along(const Fibre& fibre, std::size_t index, int segments) {
  const std::vector<double> t = arc_length(fibre, index);
  Fibre samples(segments + 1, 3);
  for (Eigen::Index c = 0; c < 3; ++c) {
    const Eigen::VectorXd column = fibre.col(c);
    const ConstrainedSpline spline(t, std::vector<double>(column.data(), column.data() + t.size()));
    for (int i = 0; i <= segments; ++i)
      samples(i, c) = spline.evaluate(static_cast<double>(i) / segments);
  }
  return samples;
}

// Refuses a measured fibre whose ends are swapped relative to fibre 0's.
void check_direction(const std::vector<Fibre>& measured) {
  const Fibre& first = measured.front();
  const Vector3d origin = row(first, 0);
  const Vector3d insertion = row(first, first.rows() - 1);
  for (std::size_t f = 1; f < measured.size(); ++f) {
    const Vector3d o = row(measured[f], 0);
    const Vector3d i = row(measured[f], measured[f].rows() - 1);
    if ((o - insertion).norm() + (i - origin).norm() <
        (o - origin).norm() + (i - insertion).norm()) {
      throw InvalidInputError("cadaver fibres: measured fibre " + std::to_string(f) +
                              " runs the other way than fibre 0 (its origin is nearer fibre 0's "
                              "insertion); hint: every fibre runs from origin to insertion");
    }
  }
}

// Knot u_f of each measured fibre across the muscle: the cumulative chord
// between neighbours averaged over the resampled points, normalised.
std::vector<double> across_knots(const std::vector<Fibre>& resampled) {
  std::vector<double> u(resampled.size(), 0.0);
  for (std::size_t f = 1; f < resampled.size(); ++f) {
    const double chord =
        (resampled[f] - resampled[f - 1]).rowwise().norm().mean();  // rows are points
    if (!(chord > 0.0)) {
      throw InvalidInputError("cadaver fibres: measured fibres " + std::to_string(f - 1) + " and " +
                              std::to_string(f) + " coincide; hint: give each measured fibre once");
    }
    u[f] = u[f - 1] + chord;
  }
  const double total = u.back();
  for (double& value : u) value /= total;
  return u;
}

// Unit normals at the vertices: the faces' unit normals weighted by their
// angles at the vertex (Thurmer & Wuthrich 1998); zero at unused vertices.
std::vector<Vector3d> vertex_normals(const mesh::IndexedMesh& mesh) {
  std::vector<Vector3d> normals(static_cast<std::size_t>(mesh.V.rows()), Vector3d::Zero());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose();
    const Vector3d b = mesh.V.row(mesh.F(f, 1)).transpose();
    const Vector3d c = mesh.V.row(mesh.F(f, 2)).transpose();
    const Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0.0)) continue;  // degenerate: no direction to give
    const Vector3d unit = n.normalized();
    const std::array<Vector3d, 3> corners = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const Vector3d e1 = corners.at(static_cast<std::size_t>((k + 1) % 3)) -
                          corners.at(static_cast<std::size_t>(k));
      const Vector3d e2 = corners.at(static_cast<std::size_t>((k + 2) % 3)) -
                          corners.at(static_cast<std::size_t>(k));
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      normals[static_cast<std::size_t>(mesh.F(f, k))] += angle * unit;
    }
  }
  for (Vector3d& n : normals)
    if (n.norm() > 0.0) n.normalize();
  return normals;
}

Vector3d face_normal(const mesh::IndexedMesh& mesh, int face) {
  const Vector3d a = mesh.V.row(mesh.F(face, 0)).transpose();
  const Vector3d b = mesh.V.row(mesh.F(face, 1)).transpose();
  const Vector3d c = mesh.V.row(mesh.F(face, 2)).transpose();
  return (b - a).cross(c - a);
}

// Minus the interpolated vertex normal at a closest point (the face normal
// where the vertex normals cancel); zero on a degenerate face.
Vector3d inward(const mesh::IndexedMesh& mesh, const std::vector<Vector3d>& normals,
                const mesh::AabbTree::ClosestPoint& closest) {
  Vector3d n = Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    n += closest.barycentric[k] * normals[static_cast<std::size_t>(mesh.F(closest.face, k))];
  if (!(n.norm() > 1e-9)) n = face_normal(mesh, closest.face);
  return n.norm() > 0.0 ? Vector3d(-n.normalized()) : Vector3d::Zero();
}

// Length of the chord from p along the unit direction d to where the ray
// leaves the muscle (first crossing beyond `skip` of a face facing along d).
std::optional<double> exit_length(const mesh::AabbTree& tree, const Vector3d& p, const Vector3d& d,
                                  double skip) {
  if (d.isZero()) return std::nullopt;
  for (const mesh::AabbTree::RayHit& hit : tree.all_hits(p, d)) {
    if (hit.t > skip && face_normal(tree.mesh(), hit.face).dot(d) > 0.0) return hit.t;
  }
  return std::nullopt;
}

// Missing chord lengths of one surface fibre, linear in the vertex index
// between the nearest hits (the nearest hit's beyond the last); 0 without any.
void fill_missing(std::vector<std::optional<double>>& lengths) {
  const int n = static_cast<int>(lengths.size());
  int previous = -1;
  for (int i = 0; i < n; ++i) {
    const auto index = static_cast<std::size_t>(i);
    if (lengths[index]) {
      previous = i;
      continue;
    }
    int next = i + 1;
    while (next < n && !lengths[static_cast<std::size_t>(next)]) ++next;
    double value = 0.0;
    if (previous >= 0 && next < n) {
      const double w = static_cast<double>(i - previous) / (next - previous);
      value = (1.0 - w) * *lengths[static_cast<std::size_t>(previous)] +
              w * *lengths[static_cast<std::size_t>(next)];
    } else if (previous >= 0) {
      value = *lengths[static_cast<std::size_t>(previous)];
    } else if (next < n) {
      value = *lengths[static_cast<std::size_t>(next)];
    }
    lengths[index] = value;
    // Filled values are not hits: keep `previous` on the last real hit.
  }
}

}  // namespace

CadaverFibreResult cadaver_fibres(const mesh::IndexedMesh& surface,
                                  const std::vector<Fibre>& measured,
                                  const CadaverFibreOptions& options) {
  check_options(options);
  if (surface.empty()) {
    throw InvalidInputError(
        "cadaver fibres: the muscle surface has no face; hint: pass the closed muscle mesh");
  }
  if (measured.size() < 2) {
    throw InvalidInputError("cadaver fibres: " + std::to_string(measured.size()) +
                            " measured fibres; at least 2 are needed to interpolate across");
  }
  std::vector<Fibre> resampled;
  resampled.reserve(measured.size());
  for (std::size_t f = 0; f < measured.size(); ++f)
    resampled.push_back(resample_along(measured[f], f, options.segments));
  check_direction(measured);
  const std::vector<double> u = across_knots(resampled);

  const mesh::AabbTree tree(surface);
  const int points = options.segments + 1;
  const int across = options.surface_fibres;
  CadaverFibreResult result;
  result.surface.assign(static_cast<std::size_t>(across), Fibre(points, 3));
  std::vector<mesh::AabbTree::ClosestPoint> closest(static_cast<std::size_t>(across) *
                                                    static_cast<std::size_t>(points));
  std::vector<double> values(measured.size());
  for (int i = 0; i < points; ++i) {
    for (Eigen::Index c = 0; c < 3; ++c) {
      for (std::size_t f = 0; f < measured.size(); ++f) values[f] = resampled[f](i, c);
      const ConstrainedSpline spline(u, values);
      for (int j = 0; j < across; ++j)
        result.surface[static_cast<std::size_t>(j)](i, c) =
            spline.evaluate(static_cast<double>(j) / (across - 1));
    }
    for (int j = 0; j < across; ++j) {
      Fibre& fibre = result.surface[static_cast<std::size_t>(j)];
      const auto slot = static_cast<std::size_t>(j) * static_cast<std::size_t>(points) +
                        static_cast<std::size_t>(i);
      closest[slot] = tree.closest_point(row(fibre, i));
      fibre.row(i) = closest[slot].point.transpose();
    }
  }

  const int layers = options.depth_layers;
  if (layers == 1) {
    result.fibres = result.surface;
    return result;
  }
  const std::vector<Vector3d> normals = vertex_normals(tree.mesh());
  const double skip = 1e-6 * tree.bounds().diagonal().norm();
  result.fibres.reserve(static_cast<std::size_t>(across) * static_cast<std::size_t>(layers));
  for (int j = 0; j < across; ++j) {
    const Fibre& top = result.surface[static_cast<std::size_t>(j)];
    std::vector<Vector3d> directions(static_cast<std::size_t>(points));
    std::vector<std::optional<double>> lengths(static_cast<std::size_t>(points));
    for (int i = 0; i < points; ++i) {
      const auto index = static_cast<std::size_t>(i);
      directions[index] =
          inward(tree.mesh(), normals,
                 closest[static_cast<std::size_t>(j) * static_cast<std::size_t>(points) + index]);
      lengths[index] = exit_length(tree, row(top, i), directions[index], skip);
      if (!lengths[index]) ++result.rays_missed;
    }
    fill_missing(lengths);
    for (int k = 0; k < layers; ++k) {
      const double depth = static_cast<double>(k) / (layers - 1);
      Fibre fibre(points, 3);
      for (int i = 0; i < points; ++i) {
        const auto index = static_cast<std::size_t>(i);
        fibre.row(i) = top.row(i) + depth * *lengths[index] * directions[index].transpose();
      }
      result.fibres.push_back(std::move(fibre));
    }
  }
  if (result.rays_missed == across * points) {
    throw InvalidInputError(
        "cadaver fibres: none of the " + std::to_string(across * points) +
        " inward rays leaves the muscle; hint: the surface must be closed and oriented outward "
        "(counter-clockwise seen from outside)");
  }
  return result;
}

}  // namespace mmm::fibres
