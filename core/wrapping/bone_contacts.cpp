#include "core/wrapping/bone_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::wrapping {
namespace {

// Rest distances are measured exactly within this margin of a bone's box;
// beyond it the distance to the box is a valid lower bound.
constexpr double kExactMarginMm = 30.0;

double distance_to_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& p) {
  return (p - p.cwiseMax(box.min()).cwiseMin(box.max())).norm();
}

}  // namespace

BoneContacts::BoneContacts(Eigen::MatrixX3d rest_vertices, std::vector<PosableBone> bones,
                           const ContactOptions& options)
    : rest_(std::move(rest_vertices)), bones_(std::move(bones)), options_(options) {
  if (!(options.tolerance_mm >= 0 && options.clearance_mm >= 0)) {
    throw InvalidInputError("bone contacts: tolerance_mm and clearance_mm must be >= 0");
  }
  if (!rest_.allFinite()) throw InvalidInputError("bone contacts: a rest vertex is not finite");
  for (const PosableBone& bone : bones_) {
    if (!bone.surface)
      throw InvalidInputError("bone contacts: bone '" + bone.name + "' has no surface");
    boxes_.push_back(bone.surface->tree().bounds());
    Eigen::VectorXd distance(rest_.rows());
    for (Eigen::Index i = 0; i < rest_.rows(); ++i) {
      const Eigen::Vector3d p = rest_.row(i).transpose();
      const double to_box = distance_to_box(boxes_.back(), p);
      distance[i] = to_box > kExactMarginMm ? to_box : bone.surface->at(p);
    }
    rest_distance_.push_back(std::move(distance));
  }
}

std::vector<BoneContacts::Hit> BoneContacts::inside(
    const Eigen::MatrixX3d& x, const std::vector<Eigen::Isometry3d>& poses) const {
  if (poses.size() != bones_.size() || x.rows() != rest_.rows()) {
    throw InvalidInputError("bone contacts: " + std::to_string(poses.size()) + " poses for " +
                            std::to_string(bones_.size()) + " bones, " + std::to_string(x.rows()) +
                            " vertices for " + std::to_string(rest_.rows()));
  }
  std::vector<Hit> hits;
  std::vector<int> hit_of(static_cast<std::size_t>(x.rows()), -1);
  for (std::size_t b = 0; b < bones_.size(); ++b) {
    const Eigen::Isometry3d to_rest = poses[b].inverse();
    const Eigen::AlignedBox3d& box = boxes_[b];
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const Eigen::Vector3d y = to_rest * Eigen::Vector3d(x.row(i).transpose());
      if (!box.contains(y)) continue;
      if (rest_distance_[b][i] - (y - rest_.row(i).transpose()).norm() > 0) continue;
      const double sd = bones_[b].surface->at(y);
      if (sd >= 0) continue;
      int& slot = hit_of[static_cast<std::size_t>(i)];
      if (slot >= 0 && hits[static_cast<std::size_t>(slot)].depth >= -sd) continue;
      const mesh::AabbTree::ClosestPoint closest = bones_[b].surface->tree().closest_point(y);
      Eigen::Vector3d outward = closest.point - y;
      const double length = outward.norm();
      if (length > 1e-12) {
        outward /= length;
      } else {
        const auto& mesh = bones_[b].surface->tree().mesh();
        const Eigen::Vector3d a = mesh.V.row(mesh.F(closest.face, 0));
        outward = (Eigen::Vector3d(mesh.V.row(mesh.F(closest.face, 1))) - a)
                      .cross(Eigen::Vector3d(mesh.V.row(mesh.F(closest.face, 2))) - a)
                      .normalized();
      }
      const Eigen::Vector3d target = poses[b] * (closest.point + options_.clearance_mm * outward);
      Hit hit{static_cast<int>(i), b, -sd, target};
      if (slot >= 0) {
        hits[static_cast<std::size_t>(slot)] = hit;
      } else {
        slot = static_cast<int>(hits.size());
        hits.push_back(hit);
      }
    }
  }
  return hits;
}

std::vector<Contact> BoneContacts::find(const Eigen::MatrixX3d& x,
                                        const std::vector<Eigen::Isometry3d>& poses,
                                        const std::vector<char>& active) const {
  std::vector<Contact> contacts;
  for (const Hit& hit : inside(x, poses)) {
    if (hit.depth <= options_.tolerance_mm) continue;
    if (!active.empty() && active[static_cast<std::size_t>(hit.vertex)] != 0) continue;
    contacts.push_back({hit.vertex, hit.target, static_cast<int>(hit.bone)});
  }
  return contacts;
}

PenetrationMetrics BoneContacts::measure(const Eigen::MatrixX3d& x,
                                         const std::vector<Eigen::Isometry3d>& poses) const {
  PenetrationMetrics metrics;
  for (const Hit& hit : inside(x, poses)) {
    ++metrics.vertices_inside;
    if (hit.depth > options_.tolerance_mm) ++metrics.vertices_deeper;
    if (hit.depth > metrics.max_depth_mm) {
      metrics.max_depth_mm = hit.depth;
      metrics.deepest_bone = bones_[hit.bone].name;
    }
  }
  return metrics;
}

}  // namespace mmm::wrapping
