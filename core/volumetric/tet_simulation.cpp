#include "core/volumetric/tet_simulation.h"

#include <Eigen/SVD>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>

#include "core/errors.h"
#include "core/mesh/signed_distance.h"
#include "core/parallel_for.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::volumetric {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Gradient = Eigen::Matrix<double, 4, 3>;

constexpr int kVolumeSweeps = 3;  // d F[r, :] / d x_r of the four corners

Matrix3d edges(const Eigen::MatrixX3d& x, const TetIndices& t, Eigen::Index i) {
  Matrix3d d;
  for (int j = 0; j < 3; ++j) d.col(j) = (x.row(t(i, j + 1)) - x.row(t(i, 0))).transpose();
  return d;
}

// Nearest rotation and nearest volume-preserving map of F (SVD with any
// reflection folded into the last singular value).
void project(const Matrix3d& f, Matrix3d& rotation, Matrix3d& volume) {
  Eigen::JacobiSVD<Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d u = svd.matrixU();
  Matrix3d v = svd.matrixV();
  Vector3d s = svd.singularValues();
  if (u.determinant() < 0) {
    u.col(2) *= -1.0;
    s[2] *= -1.0;
  }
  if (v.determinant() < 0) {
    v.col(2) *= -1.0;
    s[2] *= -1.0;
  }
  rotation = u * v.transpose();
  const double product = s.prod();
  if (product > 1e-12) {
    volume = u * (s / std::cbrt(product)).asDiagonal() * v.transpose();
  } else {
    volume = rotation;  // inverted or flat: the nearest rotation is the way back
  }
}

// Per node, the bones whose driven nodes it is connected to, weighted by
// 1 / (d + h)^2 with d its distance along the mesh's edges to the nearest
// of them (Dijkstra from all of a bone's driven nodes at once) and h the
// mean edge length; normalised to sum 1.
std::vector<std::vector<std::pair<int, double>>> blend_weights(
    const TetMesh& mesh, const std::vector<DrivenNode>& driven, int bones) {
  const auto n = static_cast<std::size_t>(mesh.V.rows());
  std::vector<std::vector<int>> neighbours(n);
  double total = 0.0;
  std::size_t count = 0;
  for (Eigen::Index t = 0; t < mesh.T.rows(); ++t) {
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        neighbours[static_cast<std::size_t>(mesh.T(t, a))].push_back(mesh.T(t, b));
        neighbours[static_cast<std::size_t>(mesh.T(t, b))].push_back(mesh.T(t, a));
        total += (mesh.V.row(mesh.T(t, a)) - mesh.V.row(mesh.T(t, b))).norm();
        ++count;
      }
    }
  }
  for (std::vector<int>& list : neighbours) {
    std::ranges::sort(list);
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  const double h = count > 0 ? total / static_cast<double>(count) : 1.0;
  std::vector<std::vector<std::pair<int, double>>> out(n);
  for (int bone = 0; bone < bones; ++bone) {
    std::vector<double> distance(n, std::numeric_limits<double>::infinity());
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    for (const DrivenNode& d : driven) {
      if (d.bone != bone) continue;
      distance[static_cast<std::size_t>(d.node)] = 0.0;
      queue.emplace(0.0, d.node);
    }
    if (queue.empty()) continue;
    while (!queue.empty()) {
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > distance[static_cast<std::size_t>(i)]) continue;
      for (const int j : neighbours[static_cast<std::size_t>(i)]) {
        const double next = d + (mesh.V.row(i) - mesh.V.row(j)).norm();
        if (next < distance[static_cast<std::size_t>(j)]) {
          distance[static_cast<std::size_t>(j)] = next;
          queue.emplace(next, j);
        }
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isfinite(distance[i])) {
        out[i].emplace_back(bone, 1.0 / ((distance[i] + h) * (distance[i] + h)));
      }
    }
  }
  for (std::vector<std::pair<int, double>>& weights : out) {
    double sum = 0.0;
    for (const auto& [bone, w] : weights) sum += w;
    for (auto& [bone, w] : weights) w /= sum;
  }
  return out;
}

// One Newton step of a closed surface's volume towards `target` along its
// gradient (dV/dx_a = (x_b x x_c) / 6 per face), moving only the nodes that
// are not driven: x += lambda g, lambda = (target - V) / |g|^2.
void restore_volume(Eigen::MatrixX3d& x, const Eigen::MatrixX3i& faces, double target,
                    const std::vector<char>& fixed) {
  double volume = 0.0;
  std::vector<std::pair<int, Vector3d>> gradient;
  std::vector<int> slot(static_cast<std::size_t>(x.rows()), -1);
  const auto add = [&](int node, const Vector3d& g) {
    int& k = slot[static_cast<std::size_t>(node)];
    if (k < 0) {
      k = static_cast<int>(gradient.size());
      gradient.emplace_back(node, Vector3d::Zero());
    }
    gradient[static_cast<std::size_t>(k)].second += g;
  };
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vector3d a = x.row(faces(f, 0)).transpose();
    const Vector3d b = x.row(faces(f, 1)).transpose();
    const Vector3d c = x.row(faces(f, 2)).transpose();
    volume += a.cross(b).dot(c) / 6.0;
    add(faces(f, 0), b.cross(c) / 6.0);
    add(faces(f, 1), c.cross(a) / 6.0);
    add(faces(f, 2), a.cross(b) / 6.0);
  }
  double norm2 = 0.0;
  for (const auto& [node, g] : gradient) {
    if (fixed[static_cast<std::size_t>(node)] == 0) norm2 += g.squaredNorm();
  }
  if (!(norm2 > 0)) return;
  const double lambda = (target - volume) / norm2;
  for (const auto& [node, g] : gradient) {
    if (fixed[static_cast<std::size_t>(node)] == 0) x.row(node) += lambda * g.transpose();
  }
}

void require_positive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw InvalidInputError(std::string("simulation ") + name + " must be a positive number, got " +
                            std::to_string(value));
  }
}

}  // namespace

struct TetSimulation::State {
  struct Contact {
    int node = 0;
    int bone = 0;
  };
  TetMesh rest;
  SimulationOptions options;
  std::vector<DrivenNode> driven;
  std::vector<std::unique_ptr<mesh::SignedDistance>> bones;
  std::vector<Gradient> gradient;  // per tetrahedron
  Eigen::VectorXd rest_volume;     // per tetrahedron
  Eigen::VectorXd mass;            // per node: its share of the volume
  std::vector<double> label_volume;
  std::vector<Contact> contacts;
  scaling::SparseCholesky solver;
  Eigen::MatrixX3d x;
  // Warm start: each node follows a blend of the bones' motion since the
  // last frame, weighted by how near (along the mesh's edges) it is to each
  // bone's driven nodes.
  std::vector<std::vector<std::pair<int, double>>> blend;  // per node: (bone, weight)
  std::vector<Eigen::Isometry3d> last_poses;
  // Per label (index label - 1): its boundary triangles, outward, on the
  // model's nodes, for the per-muscle volume constraint.
  std::vector<Eigen::MatrixX3i> boundary;
  std::vector<char> is_driven;
  double scale = 1.0;  // typical diagonal of the tetrahedra's part, for the weights
};

TetSimulation::TetSimulation(TetMesh rest, std::vector<DrivenNode> driven,
                             const std::vector<const mesh::IndexedMesh*>& bones,
                             const SimulationOptions& options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  if (rest.T.rows() == 0 || rest.V.rows() == 0)
    throw InvalidInputError("simulation: empty tet mesh");
  require_positive(options.shape_weight + options.volume_weight, "shape_weight + volume_weight");
  require_positive(options.driven_weight, "driven_weight");
  require_positive(options.inertia_weight, "inertia_weight");
  require_positive(options.contact_reach_mm, "contact_reach_mm");
  require_positive(options.contact_weight, "contact_weight");
  if (options.iterations < 1) throw InvalidInputError("simulation iterations must be at least 1");
  if (!(options.shape_weight >= 0) || !(options.volume_weight >= 0) ||
      !(options.bone_clearance_mm >= 0) || !std::isfinite(options.bone_clearance_mm)) {
    throw InvalidInputError(
        "simulation: shape_weight, volume_weight and bone_clearance_mm must "
        "be non-negative numbers");
  }
  s.options = options;
  s.rest = std::move(rest);
  s.driven = std::move(driven);
  const Eigen::Index n = s.rest.V.rows();
  const Eigen::Index tets = s.rest.T.rows();
  for (const DrivenNode& d : s.driven) {
    if (d.node < 0 || d.node >= n || d.bone < 0 || d.bone >= static_cast<int>(bones.size())) {
      throw InvalidInputError("simulation: driven node " + std::to_string(d.node) + " on bone " +
                              std::to_string(d.bone) + " is out of range");
    }
  }
  for (std::size_t b = 0; b < bones.size(); ++b) {
    if (bones[b] == nullptr || bones[b]->empty()) {
      throw InvalidInputError("simulation: bone " + std::to_string(b) + " has no surface");
    }
    s.bones.push_back(std::make_unique<mesh::SignedDistance>(*bones[b]));
  }

  s.gradient.resize(static_cast<std::size_t>(tets));
  s.rest_volume.resize(tets);
  s.mass = Eigen::VectorXd::Zero(n);
  std::uint16_t labels = 0;
  for (const std::uint16_t l : s.rest.label) labels = std::max(labels, l);
  s.label_volume.assign(labels, 0.0);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(tets) * 16 + static_cast<std::size_t>(n));
  const double w = options.shape_weight + options.volume_weight;
  double diagonal = 0.0;
  for (Eigen::Index t = 0; t < tets; ++t) {
    const Matrix3d dm = edges(s.rest.V, s.rest.T, t);
    const double volume = dm.determinant() / 6.0;
    if (!(volume > 0)) {
      throw InvalidInputError("simulation: rest tetrahedron " + std::to_string(t) +
                              " is inverted or flat");
    }
    const Matrix3d inverse = dm.inverse();
    Gradient g;
    g.bottomRows<3>() = inverse;
    g.row(0) = -inverse.colwise().sum();
    s.gradient[static_cast<std::size_t>(t)] = g;
    s.rest_volume[t] = volume;
    s.label_volume[s.rest.label[static_cast<std::size_t>(t)] - 1] += volume;
    const Eigen::Matrix4d block = w * volume * g * g.transpose();
    for (int a = 0; a < 4; ++a) {
      s.mass[s.rest.T(t, a)] += volume / 4.0;
      for (int b = 0; b < 4; ++b)
        triplets.emplace_back(s.rest.T(t, a), s.rest.T(t, b), block(a, b));
    }
    diagonal += block.trace() / 4.0;
  }
  s.scale = diagonal / static_cast<double>(tets);
  const double mean_mass = s.mass.mean();
  for (Eigen::Index i = 0; i < n; ++i) {
    triplets.emplace_back(i, i, options.inertia_weight * s.scale * s.mass[i] / mean_mass);
  }

  // Nodes near a bone at rest are checked against it (driven nodes follow
  // their bone and are not).
  s.is_driven.assign(static_cast<std::size_t>(n), 0);
  for (const DrivenNode& d : s.driven) s.is_driven[static_cast<std::size_t>(d.node)] = 1;
  for (std::size_t b = 0; b < s.bones.size(); ++b) {
    const double reach2 = options.contact_reach_mm * options.contact_reach_mm;
    std::vector<char> near(static_cast<std::size_t>(n), 0);
    parallel_for(static_cast<std::size_t>(n), options.threads, [&](std::size_t i) {
      near[i] = s.bones[b]
                        ->tree()
                        .closest_point_within(
                            s.rest.V.row(static_cast<Eigen::Index>(i)).transpose(), reach2)
                        .has_value()
                    ? 1
                    : 0;
    });
    for (std::size_t i = 0; i < near.size(); ++i) {
      if (near[i] != 0 && s.is_driven[i] == 0)
        s.contacts.push_back({static_cast<int>(i), static_cast<int>(b)});
    }
  }
  for (const DrivenNode& d : s.driven) {
    triplets.emplace_back(d.node, d.node, options.driven_weight * s.scale);
  }
  for (const State::Contact& c : s.contacts) {
    triplets.emplace_back(c.node, c.node, options.contact_weight * s.scale);
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  s.solver.compute(a);
  if (s.solver.info() != Eigen::Success) {
    throw SolverError("simulation: the system could not be factored (a node in no tetrahedron?)");
  }
  s.x = s.rest.V;
  s.blend = blend_weights(s.rest, s.driven, static_cast<int>(s.bones.size()));
  s.boundary.resize(s.label_volume.size());
  for (std::size_t l = 0; l < s.label_volume.size(); ++l) {
    if (s.label_volume[l] > 0) {
      s.boundary[l] = label_boundary(s.rest, static_cast<std::uint16_t>(l + 1)).F;
    }
  }
  s.last_poses.assign(s.bones.size(), Eigen::Isometry3d::Identity());
}

TetSimulation::~TetSimulation() = default;
TetSimulation::TetSimulation(TetSimulation&&) noexcept = default;
TetSimulation& TetSimulation::operator=(TetSimulation&&) noexcept = default;

FrameStats TetSimulation::step(const std::vector<Eigen::Isometry3d>& poses) {
  const auto start = std::chrono::steady_clock::now();
  State& s = *state_;
  if (poses.size() != s.bones.size()) {
    throw InvalidInputError("simulation step: " + std::to_string(poses.size()) +
                            " bone poses for " + std::to_string(s.bones.size()) + " bones");
  }
  for (const Eigen::Isometry3d& pose : poses) {
    if (!pose.matrix().allFinite())
      throw InvalidInputError("simulation step: a pose is not finite");
  }
  const Eigen::Index n = s.x.rows();
  const Eigen::Index tets = s.rest.T.rows();
  const SimulationOptions& o = s.options;
  const Eigen::MatrixX3d previous = s.x;
  std::vector<Eigen::Isometry3d> delta(poses.size());
  for (std::size_t b = 0; b < poses.size(); ++b) delta[b] = poses[b] * s.last_poses[b].inverse();
  parallel_for(static_cast<std::size_t>(n), o.threads, [&](std::size_t i) {
    if (s.blend[i].empty()) return;
    const Vector3d p = previous.row(static_cast<Eigen::Index>(i)).transpose();
    Vector3d moved = Vector3d::Zero();
    for (const auto& [bone, w] : s.blend[i])
      moved += w * (delta[static_cast<std::size_t>(bone)] * p);
    s.x.row(static_cast<Eigen::Index>(i)) = moved.transpose();
  });
  s.last_poses = poses;
  const double mean_mass = s.mass.mean();
  Eigen::MatrixX3d fixed_rhs = Eigen::MatrixX3d::Zero(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    fixed_rhs.row(i) = o.inertia_weight * s.scale * s.mass[i] / mean_mass * previous.row(i);
  }
  for (const DrivenNode& d : s.driven) {
    const Vector3d target =
        poses[static_cast<std::size_t>(d.bone)] * s.rest.V.row(d.node).transpose();
    fixed_rhs.row(d.node) += o.driven_weight * s.scale * target.transpose();
    s.x.row(d.node) = target.transpose();  // warm start
  }
  std::vector<Matrix3d> target_f(static_cast<std::size_t>(tets));
  // Where a checked node should be: itself when it is clear of its bone,
  // else the nearest point of the bone's surface plus the clearance.
  // One closest-point query and one inside test per node (what
  // SignedDistance::at does, keeping the point).
  std::vector<Eigen::Isometry3d> inverse(poses.size());
  for (std::size_t b = 0; b < poses.size(); ++b) inverse[b] = poses[b].inverse();
  const auto outside_of = [&](std::size_t c, const Eigen::MatrixX3d& x) -> Vector3d {
    const State::Contact& k = s.contacts[c];
    const auto b = static_cast<std::size_t>(k.bone);
    Vector3d here = x.row(k.node).transpose();
    const Vector3d p = inverse[b] * here;
    const mesh::SignedDistance& bone = *s.bones[b];
    const mesh::AabbTree::ClosestPoint nearest = bone.tree().closest_point(p);
    const bool inside = bone.winding().is_inside(p);
    const double length = std::sqrt(nearest.squared_distance);
    if (!inside && length >= o.bone_clearance_mm) return here;
    if (length < 1e-12) return here;  // on the surface: no direction to go
    Vector3d out = (p - nearest.point) / length;
    if (inside) out = -out;  // the way out is towards the surface and beyond
    return poses[b] * (nearest.point + o.bone_clearance_mm * out);
  };
  std::vector<Vector3d> contact_target(s.contacts.size());
  for (int iteration = 0; iteration < o.iterations; ++iteration) {
    parallel_for(static_cast<std::size_t>(tets), o.threads, [&](std::size_t t) {
      const auto i = static_cast<Eigen::Index>(t);
      Eigen::Matrix<double, 4, 3> corners;
      for (int a = 0; a < 4; ++a) corners.row(a) = s.x.row(s.rest.T(i, a));
      const Matrix3d f = corners.transpose() * s.gradient[t];
      Matrix3d rotation;
      Matrix3d volume;
      project(f, rotation, volume);
      target_f[t] = o.shape_weight * rotation + o.volume_weight * volume;
    });
    parallel_for(s.contacts.size(), o.threads,
                 [&](std::size_t c) { contact_target[c] = outside_of(c, s.x); });
    Eigen::MatrixX3d rhs = fixed_rhs;
    for (Eigen::Index t = 0; t < tets; ++t) {
      // sum_t V_t G_t P_t^T: row a of G_t P^T goes to corner a.
      const Eigen::Matrix<double, 4, 3> part = s.rest_volume[t] *
                                               s.gradient[static_cast<std::size_t>(t)] *
                                               target_f[static_cast<std::size_t>(t)].transpose();
      for (int a = 0; a < 4; ++a) rhs.row(s.rest.T(t, a)) += part.row(a);
    }
    for (std::size_t c = 0; c < s.contacts.size(); ++c) {
      rhs.row(s.contacts[c].node) += o.contact_weight * s.scale * contact_target[c].transpose();
    }
    s.x = s.solver.solve(rhs);
    // Each muscle's volume back to its rest volume, muscle after muscle;
    // shared interface nodes are moved by both, so a few sweeps.
    for (int sweep = 0; sweep < kVolumeSweeps; ++sweep) {
      for (std::size_t l = 0; l < s.boundary.size(); ++l) {
        if (s.boundary[l].rows() > 0) {
          restore_volume(s.x, s.boundary[l], s.label_volume[l], s.is_driven);
        }
      }
    }
  }
  FrameStats stats;
  std::vector<double> depth(s.contacts.size(), 0.0);
  parallel_for(s.contacts.size(), o.threads, [&](std::size_t c) {
    const State::Contact& k = s.contacts[c];
    const Vector3d p = inverse[static_cast<std::size_t>(k.bone)] * s.x.row(k.node).transpose();
    depth[c] = std::max(0.0, -s.bones[static_cast<std::size_t>(k.bone)]->at(p));
  });
  for (const double d : depth) {
    stats.max_bone_depth_mm = std::max(stats.max_bone_depth_mm, d);
    stats.nodes_in_bones += d > 0 ? 1 : 0;
  }
  std::vector<double> volume(s.label_volume.size(), 0.0);
  for (Eigen::Index t = 0; t < tets; ++t) {
    const double v = edges(s.x, s.rest.T, t).determinant() / 6.0;
    stats.inverted += v <= 0 ? 1 : 0;
    volume[s.rest.label[static_cast<std::size_t>(t)] - 1] += v;
  }
  stats.volume_change.resize(volume.size());
  for (std::size_t l = 0; l < volume.size(); ++l) {
    stats.volume_change[l] = s.label_volume[l] > 0 ? volume[l] / s.label_volume[l] - 1.0 : 0.0;
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

const Eigen::MatrixX3d& TetSimulation::positions() const { return state_->x; }
const TetMesh& TetSimulation::rest() const { return state_->rest; }
int TetSimulation::checked_nodes() const { return static_cast<int>(state_->contacts.size()); }

}  // namespace mmm::volumetric
