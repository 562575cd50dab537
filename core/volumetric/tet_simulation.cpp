#include "core/volumetric/tet_simulation.h"

#include "core/volumetric/volume_restorer.h"

#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <string>

#include "core/errors.h"
#include "core/mesh/signed_distance.h"
#include "core/parallel_for.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::volumetric {
namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Gradient = Eigen::Matrix<double, 4, 3>;

// Newton steps on the muscles' volumes: one per round, more after the last
// (the volumes are then exact to ~1e-8).
constexpr int kFinalVolumeSteps = 3;

Matrix3d edges(const Eigen::MatrixX3d& x, const TetIndices& t, Eigen::Index i) {
  Matrix3d d;
  for (int j = 0; j < 3; ++j) d.col(j) = (x.row(t(i, j + 1)) - x.row(t(i, 0))).transpose();
  return d;
}

// The rotation of F's polar decomposition, by Mueller et al.'s iteration
// ("A robust method to extract the rotational part of deformations", 2016)
// from `q` (the element's rotation of the last round), and the volume-
// preserving map F / det(F)^(1/3) (the rotation when F is inverted or flat).
void project(const Matrix3d& f, Eigen::Quaterniond& q, int iterations, Matrix3d& rotation,
             Matrix3d& volume) {
  for (int i = 0; i < iterations; ++i) {
    const Matrix3d r = q.toRotationMatrix();
    const Vector3d omega =
        r.col(0).cross(f.col(0)) + r.col(1).cross(f.col(1)) + r.col(2).cross(f.col(2));
    const double denominator =
        std::abs(r.col(0).dot(f.col(0)) + r.col(1).dot(f.col(1)) + r.col(2).dot(f.col(2))) + 1e-9;
    const Vector3d step = omega / denominator;
    const double angle = step.norm();
    if (angle < 1e-9) break;
    q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, step / angle)) * q;
    q.normalize();
  }
  rotation = q.toRotationMatrix();
  const double det = f.determinant();
  volume = det > 1e-12 ? Matrix3d(f / std::cbrt(det)) : rotation;
}

// Per node, the bones whose driven nodes it is connected to, weighted by
// 1 / (d + h)^2 with d its distance along the mesh's edges to the nearest
// of them (Dijkstra from all of a bone's driven nodes at once) and h the
// mean edge length; normalised to sum 1. `links`: more edges (separate
// muscles: the element nodes of the two sides of an interface pair).
std::vector<std::vector<std::pair<int, double>>> blend_weights(
    const TetMesh& mesh, const std::vector<DrivenNode>& driven, int bones,
    const std::vector<std::pair<int, int>>& links) {
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
  for (const auto& [a, b] : links) {
    neighbours[static_cast<std::size_t>(a)].push_back(b);
    neighbours[static_cast<std::size_t>(b)].push_back(a);
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

void require_positive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw InvalidInputError(std::string("simulation ") + name + " must be a positive number, got " +
                            std::to_string(value));
  }
}

// The triplets of w |W_i x - target|^2 for one output node: (W_i^T W_i) w.
void add_point_term(const EmbeddingWeights& weights, int output_node, double w,
                    std::vector<Eigen::Triplet<double>>& triplets) {
  for (EmbeddingWeights::InnerIterator a(weights, output_node); a; ++a) {
    for (EmbeddingWeights::InnerIterator b(weights, output_node); b; ++b) {
      triplets.emplace_back(static_cast<int>(a.col()), static_cast<int>(b.col()),
                            w * a.value() * b.value());
    }
  }
}

// The triplets of w |W_a x - W_b x|^2 for two output nodes.
void add_difference_term(const EmbeddingWeights& weights, int a, int b, double w,
                         std::vector<Eigen::Triplet<double>>& triplets) {
  for (const auto& [first, first_sign] : {std::pair{a, 1.0}, std::pair{b, -1.0}}) {
    for (const auto& [second, second_sign] : {std::pair{a, 1.0}, std::pair{b, -1.0}}) {
      for (EmbeddingWeights::InnerIterator i(weights, first); i; ++i) {
        for (EmbeddingWeights::InnerIterator j(weights, second); j; ++j) {
          triplets.emplace_back(static_cast<int>(i.col()), static_cast<int>(j.col()),
                                w * first_sign * second_sign * i.value() * j.value());
        }
      }
    }
  }
}

// rhs += w W_i^T target.
void add_point_rhs(const EmbeddingWeights& weights, int output_node, double w,
                   const Vector3d& target, Eigen::MatrixX3d& rhs) {
  for (EmbeddingWeights::InnerIterator it(weights, output_node); it; ++it)
    rhs.row(it.col()) += w * it.value() * target.transpose();
}

}  // namespace

struct TetSimulation::State {
  struct Contact {
    int node = 0;  // output node
    int bone = 0;
    // Where the node was (bone frame) when its bone was last looked up, and
    // how far it could move from there and still be clear of the bone
    // (distance minus clearance; <= 0: not known to be clear). The signed
    // distance changes by at most the distance moved, so until then there is
    // no need to look again.
    Vector3d last_point = Vector3d::Zero();
    double clear_within = 0.0;
  };
  EmbeddedModel model;
  SimulationOptions options;
  std::vector<DrivenNode> driven;
  std::vector<std::unique_ptr<mesh::SignedDistance>> bones;
  std::vector<Eigen::Matrix3Xd> bone_normals;  // per bone, unit face normals (rest)
  std::vector<Gradient> gradient;              // per element
  std::vector<Eigen::Quaterniond> rotation;    // per element, of the last round
  Eigen::VectorXd rest_volume;                 // per element
  Eigen::VectorXd mass;                        // per element node: its share of the volume
  std::vector<double> label_volume;            // per label, of its output boundary at rest
  std::vector<Contact> contacts;
  // Separate muscles: the tied pairs, and per pair the faces of a's muscle
  // surface around a (its normal for sliding).
  std::vector<InterfacePair> interfaces;
  std::vector<std::vector<Eigen::Vector3i>> interface_faces;
  scaling::SparseCholesky solver;
  Eigen::MatrixX3d x;  // element nodes
  Eigen::MatrixX3d y;  // output nodes, W x
  // Warm start: each element node follows a blend of the bones' motion since
  // the last frame, weighted by how near (along the mesh's edges) it is to
  // each bone's driven nodes.
  std::vector<std::vector<std::pair<int, double>>> blend;  // per node: (bone, weight)
  std::vector<Eigen::Isometry3d> last_poses;
  std::unique_ptr<VolumeRestorer> volumes;
  // Per element node, its (element * 4 + corner) entries, CSR.
  std::vector<int> incidence_start;
  std::vector<int> incidence;
  double scale = 1.0;  // typical diagonal of the elements' part, for the weights
};

TetSimulation::TetSimulation(TetMesh rest, std::vector<DrivenNode> driven,
                             const std::vector<const mesh::IndexedMesh*>& bones,
                             const SimulationOptions& options)
    : TetSimulation(embed_identity(std::move(rest)), std::move(driven), bones, options) {}

TetSimulation::TetSimulation(EmbeddedModel model, std::vector<DrivenNode> driven,
                             const std::vector<const mesh::IndexedMesh*>& bones,
                             const SimulationOptions& options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  if (model.elements.T.rows() == 0 || model.elements.V.rows() == 0 || model.output.T.rows() == 0) {
    throw InvalidInputError("simulation: empty tet mesh");
  }
  if (model.weights.rows() != model.output.V.rows() ||
      model.weights.cols() != model.elements.V.rows()) {
    throw InvalidInputError(
        "simulation: the embedding's weights are " + std::to_string(model.weights.rows()) + " x " +
        std::to_string(model.weights.cols()) + " for " + std::to_string(model.output.V.rows()) +
        " output and " + std::to_string(model.elements.V.rows()) + " element nodes");
  }
  require_positive(options.shape_weight + options.volume_weight, "shape_weight + volume_weight");
  require_positive(options.driven_weight, "driven_weight");
  require_positive(options.inertia_weight, "inertia_weight");
  require_positive(options.contact_reach_mm, "contact_reach_mm");
  require_positive(options.contact_weight, "contact_weight");
  if (options.iterations < 1) throw InvalidInputError("simulation iterations must be at least 1");
  if (options.rotation_iterations < 1)
    throw InvalidInputError("simulation rotation_iterations must be at least 1");
  if (!(options.shape_weight >= 0) || !(options.volume_weight >= 0) ||
      !(options.bone_clearance_mm >= 0) || !std::isfinite(options.bone_clearance_mm)) {
    throw InvalidInputError(
        "simulation: shape_weight, volume_weight and bone_clearance_mm must "
        "be non-negative numbers");
  }
  s.options = options;
  s.model = std::move(model);
  s.model.weights.makeCompressed();
  s.driven = std::move(driven);
  const TetMesh& elements = s.model.elements;
  const TetMesh& output = s.model.output;
  const EmbeddingWeights& weights = s.model.weights;
  const Eigen::Index n = elements.V.rows();
  const Eigen::Index outputs = output.V.rows();
  const Eigen::Index tets = elements.T.rows();
  for (const DrivenNode& d : s.driven) {
    if (d.node < 0 || d.node >= (d.element ? n : outputs) || d.bone < 0 ||
        d.bone >= static_cast<int>(bones.size())) {
      throw InvalidInputError("simulation: driven node " + std::to_string(d.node) + " on bone " +
                              std::to_string(d.bone) + " is out of range");
    }
  }
  for (std::size_t b = 0; b < bones.size(); ++b) {
    if (bones[b] == nullptr || bones[b]->empty()) {
      throw InvalidInputError("simulation: bone " + std::to_string(b) + " has no surface");
    }
    s.bones.push_back(std::make_unique<mesh::SignedDistance>(*bones[b]));
    const mesh::IndexedMesh& bone = *bones[b];
    Eigen::Matrix3Xd normals(3, bone.F.rows());
    for (Eigen::Index f = 0; f < bone.F.rows(); ++f) {
      const Vector3d a = bone.V.row(bone.F(f, 0)).transpose();
      const Vector3d e1 = bone.V.row(bone.F(f, 1)).transpose() - a;
      const Vector3d e2 = bone.V.row(bone.F(f, 2)).transpose() - a;
      normals.col(f) = e1.cross(e2).normalized();
    }
    s.bone_normals.push_back(std::move(normals));
  }

  s.gradient.resize(static_cast<std::size_t>(tets));
  s.rotation.assign(static_cast<std::size_t>(tets), Eigen::Quaterniond::Identity());
  s.rest_volume.resize(tets);
  s.mass = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(tets) * 16 + static_cast<std::size_t>(n));
  const double w = options.shape_weight + options.volume_weight;
  double diagonal = 0.0;
  for (Eigen::Index t = 0; t < tets; ++t) {
    const Matrix3d dm = edges(elements.V, elements.T, t);
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
    const Eigen::Matrix4d block = w * volume * g * g.transpose();
    for (int a = 0; a < 4; ++a) {
      s.mass[elements.T(t, a)] += volume / 4.0;
      for (int b = 0; b < 4; ++b)
        triplets.emplace_back(elements.T(t, a), elements.T(t, b), block(a, b));
    }
    diagonal += block.trace() / 4.0;
  }
  s.scale = diagonal / static_cast<double>(tets);
  const double mean_mass = s.mass.mean();
  for (Eigen::Index i = 0; i < n; ++i) {
    triplets.emplace_back(i, i, options.inertia_weight * s.scale * s.mass[i] / mean_mass);
  }

  // The muscles' output boundaries: the volume constraint, and the nodes
  // checked against the bones (driven nodes follow their bone and are not).
  std::uint16_t labels = 0;
  for (const std::uint16_t l : output.label) labels = std::max(labels, l);
  std::vector<Eigen::MatrixX3i> boundaries(labels);
  std::vector<char> on_boundary(static_cast<std::size_t>(outputs), 0);
  std::vector<char> present(labels, 0);
  for (const std::uint16_t l : output.label) present[l - 1] = 1;
  for (std::uint16_t l = 1; l <= labels; ++l) {
    if (present[l - 1] == 0) continue;
    boundaries[l - 1] = label_boundary(output, l).F;
    for (Eigen::Index f = 0; f < boundaries[l - 1].rows(); ++f) {
      for (int c = 0; c < 3; ++c)
        on_boundary[static_cast<std::size_t>(boundaries[l - 1](f, c))] = 1;
    }
  }
  std::vector<char> is_driven(static_cast<std::size_t>(outputs), 0);
  for (const DrivenNode& d : s.driven) {
    if (!d.element) is_driven[static_cast<std::size_t>(d.node)] = 1;
  }
  for (std::size_t b = 0; b < s.bones.size(); ++b) {
    const double reach2 = options.contact_reach_mm * options.contact_reach_mm;
    std::vector<char> near(static_cast<std::size_t>(outputs), 0);
    parallel_for(static_cast<std::size_t>(outputs), options.threads, [&](std::size_t i) {
      if (on_boundary[i] == 0 || is_driven[i] != 0) return;
      near[i] = s.bones[b]
                        ->tree()
                        .closest_point_within(
                            output.V.row(static_cast<Eigen::Index>(i)).transpose(), reach2)
                        .has_value()
                    ? 1
                    : 0;
    });
    for (std::size_t i = 0; i < near.size(); ++i) {
      if (near[i] != 0) s.contacts.push_back({static_cast<int>(i), static_cast<int>(b)});
    }
  }
  for (const DrivenNode& d : s.driven) {
    if (d.element) {
      triplets.emplace_back(d.node, d.node, options.driven_weight * s.scale);
    } else {
      add_point_term(weights, d.node, options.driven_weight * s.scale, triplets);
    }
  }
  for (const State::Contact& c : s.contacts)
    add_point_term(weights, c.node, options.contact_weight * s.scale, triplets);
  if (!(options.interface_weight > 0) || !std::isfinite(options.interface_weight)) {
    throw InvalidInputError("simulation interface_weight must be a positive number");
  }
  s.interfaces = s.model.interfaces;
  {
    std::vector<std::vector<int>> pairs_of(static_cast<std::size_t>(outputs));
    for (std::size_t k = 0; k < s.interfaces.size(); ++k) {
      const InterfacePair& pair = s.interfaces[k];
      if (pair.a < 0 || pair.b < 0 || pair.a >= outputs || pair.b >= outputs || pair.a == pair.b) {
        throw InvalidInputError("simulation: interface pair " + std::to_string(k) +
                                " is out of range");
      }
      add_difference_term(weights, pair.a, pair.b, options.interface_weight * s.scale, triplets);
      pairs_of[static_cast<std::size_t>(pair.a)].push_back(static_cast<int>(k));
    }
    // The interface's own faces: those with every corner on an interface
    // (at the interface's rim a node's other faces would tilt its normal).
    std::vector<char> paired(static_cast<std::size_t>(outputs), 0);
    for (const InterfacePair& pair : s.interfaces) {
      paired[static_cast<std::size_t>(pair.a)] = 1;
      paired[static_cast<std::size_t>(pair.b)] = 1;
    }
    s.interface_faces.resize(s.interfaces.size());
    for (const Eigen::MatrixX3i& faces : boundaries) {
      for (Eigen::Index f = 0; f < faces.rows(); ++f) {
        if (paired[static_cast<std::size_t>(faces(f, 0))] == 0 ||
            paired[static_cast<std::size_t>(faces(f, 1))] == 0 ||
            paired[static_cast<std::size_t>(faces(f, 2))] == 0) {
          continue;
        }
        for (int c = 0; c < 3; ++c) {
          for (const int k : pairs_of[static_cast<std::size_t>(faces(f, c))])
            s.interface_faces[static_cast<std::size_t>(k)].emplace_back(faces.row(f).transpose());
        }
      }
    }
  }
  Eigen::SparseMatrix<double> system(n, n);
  system.setFromTriplets(triplets.begin(), triplets.end());
  s.solver.compute(system);
  if (s.solver.info() != Eigen::Success) {
    throw SolverError("simulation: the system could not be factored (a node in no tetrahedron?)");
  }
  s.x = elements.V;
  s.y = weights * s.x;
  s.incidence_start.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index t = 0; t < tets; ++t) {
    for (int a = 0; a < 4; ++a) ++s.incidence_start[static_cast<std::size_t>(elements.T(t, a)) + 1];
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i)
    s.incidence_start[i + 1] += s.incidence_start[i];
  s.incidence.resize(static_cast<std::size_t>(tets) * 4);
  {
    std::vector<int> next(s.incidence_start.begin(), s.incidence_start.end() - 1);
    for (Eigen::Index t = 0; t < tets; ++t) {
      for (int a = 0; a < 4; ++a) {
        s.incidence[static_cast<std::size_t>(next[static_cast<std::size_t>(elements.T(t, a))]++)] =
            static_cast<int>(t) * 4 + a;
      }
    }
  }
  // Element nodes that carry an attachment: the seeds of the warm start's
  // blend, and held by the volume steps.
  std::vector<DrivenNode> seeds;
  std::vector<char> fixed(static_cast<std::size_t>(n), 0);
  for (const DrivenNode& d : s.driven) {
    if (d.element) {
      seeds.push_back(d);
      fixed[static_cast<std::size_t>(d.node)] = 1;
      continue;
    }
    for (EmbeddingWeights::InnerIterator it(weights, d.node); it; ++it) {
      seeds.push_back({static_cast<int>(it.col()), d.bone});
      fixed[static_cast<std::size_t>(it.col())] = 1;
    }
  }
  // Separate muscles: the warm start carries a muscle across its
  // interfaces by its neighbours' motion: every muscle when they stick, and
  // when they slide only a muscle with nothing driven (the others follow
  // their own bones and slide).
  std::vector<int> part(static_cast<std::size_t>(n));
  std::iota(part.begin(), part.end(), 0);
  const auto root = [&](int i) {
    while (part[static_cast<std::size_t>(i)] != i) {
      part[static_cast<std::size_t>(i)] =
          part[static_cast<std::size_t>(part[static_cast<std::size_t>(i)])];
      i = part[static_cast<std::size_t>(i)];
    }
    return i;
  };
  for (Eigen::Index t = 0; t < tets; ++t) {
    for (int a = 1; a < 4; ++a)
      part[static_cast<std::size_t>(root(elements.T(t, a)))] = root(elements.T(t, 0));
  }
  std::vector<char> part_driven(static_cast<std::size_t>(n), 0);
  for (const DrivenNode& seed : seeds) part_driven[static_cast<std::size_t>(root(seed.node))] = 1;
  std::vector<std::pair<int, int>> links;
  for (const InterfacePair& pair : s.interfaces) {
    const bool link = !options.slide ||
                      part_driven[static_cast<std::size_t>(root(s.model.host(pair.a, 0)))] == 0 ||
                      part_driven[static_cast<std::size_t>(root(s.model.host(pair.b, 0)))] == 0;
    if (!link) continue;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        links.emplace_back(s.model.host(pair.a, i), s.model.host(pair.b, j));
  }
  s.blend = blend_weights(elements, seeds, static_cast<int>(s.bones.size()), links);
  s.label_volume = boundary_volumes(boundaries, s.y);
  s.volumes = std::make_unique<VolumeRestorer>(s.model.weights, std::move(boundaries),
                                               s.label_volume, std::move(fixed));
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
  const TetMesh& elements = s.model.elements;
  const EmbeddingWeights& weights = s.model.weights;
  const Eigen::Index tets = elements.T.rows();
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
  // Each element's rotation (the polar iteration's start) turned by the
  // motion of the bone its first corner follows most.
  std::vector<Eigen::Quaterniond> turn(poses.size());
  for (std::size_t b = 0; b < poses.size(); ++b) turn[b] = Eigen::Quaterniond(delta[b].rotation());
  parallel_for(static_cast<std::size_t>(tets), o.threads, [&](std::size_t t) {
    const auto& blend =
        s.blend[static_cast<std::size_t>(elements.T(static_cast<Eigen::Index>(t), 0))];
    if (blend.empty()) return;
    const auto most = std::ranges::max_element(
        blend, [](const auto& a, const auto& b) { return a.second < b.second; });
    s.rotation[t] = (turn[static_cast<std::size_t>(most->first)] * s.rotation[t]).normalized();
  });
  s.last_poses = poses;
  const double mean_mass = s.mass.mean();
  Eigen::MatrixX3d fixed_rhs(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    fixed_rhs.row(i) = o.inertia_weight * s.scale * s.mass[i] / mean_mass * s.x.row(i);
  }
  for (const DrivenNode& d : s.driven) {
    const Isometry3d& pose = poses[static_cast<std::size_t>(d.bone)];
    if (d.element) {
      const Vector3d target = pose * elements.V.row(d.node).transpose();
      fixed_rhs.row(d.node) += o.driven_weight * s.scale * target.transpose();
      s.x.row(d.node) = target.transpose();  // warm start
    } else {
      const Vector3d target = pose * s.model.output.V.row(d.node).transpose();
      add_point_rhs(weights, d.node, o.driven_weight * s.scale, target, fixed_rhs);
    }
  }
  std::vector<Matrix3d> target_f(static_cast<std::size_t>(tets));
  // Where a checked node should be: itself when it is clear of its bone,
  // else the nearest point of the bone's surface plus the clearance. One
  // closest-point query per node that may have come near its bone since it
  // was last looked up; inside or not from the nearest face's
  // normal when the nearest point is inside that face, else from the
  // winding number (edges and corners, where the normal can mislead).
  std::vector<Eigen::Isometry3d> inverse(poses.size());
  for (std::size_t b = 0; b < poses.size(); ++b) inverse[b] = poses[b].inverse();
  const auto outside_of = [&](std::size_t c) -> Vector3d {
    State::Contact& k = s.contacts[c];
    const auto b = static_cast<std::size_t>(k.bone);
    Vector3d here = s.y.row(k.node).transpose();
    const Vector3d p = inverse[b] * here;
    if (k.clear_within > 0 && (p - k.last_point).squaredNorm() < k.clear_within * k.clear_within) {
      return here;
    }
    const mesh::SignedDistance& bone = *s.bones[b];
    const mesh::AabbTree::ClosestPoint nearest = bone.tree().closest_point(p);
    const double length = std::sqrt(nearest.squared_distance);
    constexpr double kInsideFace = 1e-3;
    const bool inside = nearest.barycentric.minCoeff() > kInsideFace
                            ? (p - nearest.point).dot(s.bone_normals[b].col(nearest.face)) < 0
                            : bone.winding().is_inside(p);
    k.last_point = p;
    k.clear_within = inside ? 0.0 : length - o.bone_clearance_mm;
    if (!inside && length >= o.bone_clearance_mm) return here;
    if (length < 1e-12) return here;  // on the surface: no direction to go
    Vector3d out = (p - nearest.point) / length;
    if (inside) out = -out;  // the way out is towards the surface and beyond
    return poses[b] * (nearest.point + o.bone_clearance_mm * out);
  };
  std::vector<Vector3d> contact_target(s.contacts.size());
  FrameStats stats;
  using StepClock = std::chrono::steady_clock;
  const auto lap = [](StepClock::time_point& since) {
    const StepClock::time_point now = StepClock::now();
    const double elapsed = std::chrono::duration<double>(now - since).count();
    since = now;
    return elapsed;
  };
  // Pair k's offset y_a - y_b split into its part across the interface
  // (along a's surface normal) and its part along the interface.
  const auto interface_offset = [&](std::size_t k) -> std::pair<double, Vector3d> {
    const InterfacePair& pair = s.interfaces[k];
    const Vector3d offset = (s.y.row(pair.a) - s.y.row(pair.b)).transpose();
    Vector3d normal = Vector3d::Zero();
    for (const Eigen::Vector3i& f : s.interface_faces[k]) {
      const Vector3d p0 = s.y.row(f(0)).transpose();
      normal += (s.y.row(f(1)).transpose() - p0).cross(s.y.row(f(2)).transpose() - p0);
    }
    if (normal.norm() < 1e-12) return {offset.norm(), Vector3d::Zero()};
    normal.normalize();
    const double across = normal.dot(offset);
    return {across, offset - across * normal};
  };
  s.y = weights * s.x;
  for (int iteration = 0; iteration < o.iterations; ++iteration) {
    StepClock::time_point since = StepClock::now();
    parallel_for(static_cast<std::size_t>(tets), o.threads, [&](std::size_t t) {
      const auto i = static_cast<Eigen::Index>(t);
      Eigen::Matrix<double, 4, 3> corners;
      for (int a = 0; a < 4; ++a) corners.row(a) = s.x.row(elements.T(i, a));
      const Matrix3d f = corners.transpose() * s.gradient[t];
      Matrix3d rotation;
      Matrix3d volume;
      project(f, s.rotation[t], o.rotation_iterations, rotation, volume);
      target_f[t] = o.shape_weight * rotation + o.volume_weight * volume;
    });
    stats.local_seconds += lap(since);
    parallel_for(s.contacts.size(), o.threads,
                 [&](std::size_t c) { contact_target[c] = outside_of(c); });
    stats.contact_seconds += lap(since);
    // sum_t V_t G_t P_t^T: row a of G_t P^T goes to corner a; each node
    // sums its elements' rows in a fixed order (the same on any thread).
    Eigen::MatrixX3d rhs = fixed_rhs;
    parallel_for(static_cast<std::size_t>(n), o.threads, [&](std::size_t i) {
      for (int k = s.incidence_start[i]; k < s.incidence_start[i + 1]; ++k) {
        const auto t = static_cast<std::size_t>(s.incidence[static_cast<std::size_t>(k)] / 4);
        const int corner = s.incidence[static_cast<std::size_t>(k)] % 4;
        rhs.row(static_cast<Eigen::Index>(i)) +=
            s.rest_volume[static_cast<Eigen::Index>(t)] *
            (s.gradient[t].row(corner) * target_f[t].transpose());
      }
    });
    for (std::size_t c = 0; c < s.contacts.size(); ++c) {
      add_point_rhs(weights, s.contacts[c].node, o.contact_weight * s.scale, contact_target[c],
                    rhs);
    }
    if (o.slide) {
      for (std::size_t k = 0; k < s.interfaces.size(); ++k) {
        const Vector3d along = interface_offset(k).second;
        add_point_rhs(weights, s.interfaces[k].a, o.interface_weight * s.scale, along, rhs);
        add_point_rhs(weights, s.interfaces[k].b, -o.interface_weight * s.scale, along, rhs);
      }
    }
    s.x = s.solver.solve(rhs);
    s.y = weights * s.x;
    stats.solve_seconds += lap(since);
    s.volumes->restore(s.x, s.y, iteration + 1 == o.iterations ? kFinalVolumeSteps : 1, o.threads);
    stats.volume_seconds += lap(since);
  }
  std::vector<double> depth(s.contacts.size(), 0.0);
  parallel_for(s.contacts.size(), o.threads, [&](std::size_t c) {
    const State::Contact& k = s.contacts[c];
    const Vector3d p = inverse[static_cast<std::size_t>(k.bone)] * s.y.row(k.node).transpose();
    depth[c] = std::max(0.0, -s.bones[static_cast<std::size_t>(k.bone)]->at(p));
  });
  for (const double d : depth) {
    stats.max_bone_depth_mm = std::max(stats.max_bone_depth_mm, d);
    stats.nodes_in_bones += d > 0 ? 1 : 0;
  }
  for (std::size_t k = 0; k < s.interfaces.size(); ++k) {
    const auto [across, along] = interface_offset(k);
    stats.max_interface_gap_mm = std::max(stats.max_interface_gap_mm, std::abs(across));
    stats.max_interface_slide_mm = std::max(stats.max_interface_slide_mm, along.norm());
  }
  stats.inverted_per_label.assign(s.label_volume.size(), 0);
  for (Eigen::Index t = 0; t < tets; ++t) {
    if (edges(s.x, elements.T, t).determinant() > 0) continue;
    ++stats.inverted;
    const std::uint16_t label = elements.label[static_cast<std::size_t>(t)];
    if (label >= 1 && label <= stats.inverted_per_label.size())
      ++stats.inverted_per_label[label - 1];
  }
  const std::vector<double> volume = s.volumes->volumes(s.y);
  stats.volume_change.resize(volume.size());
  for (std::size_t l = 0; l < volume.size(); ++l) {
    stats.volume_change[l] = s.label_volume[l] > 0 ? volume[l] / s.label_volume[l] - 1.0 : 0.0;
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

const Eigen::MatrixX3d& TetSimulation::positions() const { return state_->y; }
const Eigen::MatrixX3d& TetSimulation::element_positions() const { return state_->x; }
const EmbeddedModel& TetSimulation::model() const { return state_->model; }
int TetSimulation::checked_nodes() const { return static_cast<int>(state_->contacts.size()); }

}  // namespace mmm::volumetric
