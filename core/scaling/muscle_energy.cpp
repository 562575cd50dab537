#include "core/scaling/muscle_energy.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <utility>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/laplacian.h"
#include "core/mesh/mass_properties.h"

namespace mmm::scaling {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

// The coarse bone levels differ from the full surfaces by a few mm (chords
// across curvature): vertices this much beyond the band on the coarse level
// cannot be in it on the full one.
constexpr double kCoarseMarginMm = 8.0;

// Depth now beyond the depth at rest scaled with the bone (mm): an overlap
// the atlas already has is not new, and grows with the bone like any length.
double excess_depth(double signed_distance, double rest_signed_distance, double bone_scale) {
  return std::max(0.0, -signed_distance) - bone_scale * std::max(0.0, -rest_signed_distance);
}

// Spreads the low 21 bits of v over every third bit.
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// Rows of V sorted along the Morton curve of a 2^21 grid over their box.
std::vector<Eigen::Index> morton_order(const Eigen::MatrixX3d& V) {
  const Eigen::RowVector3d low = V.colwise().minCoeff();
  const double extent = std::max((V.colwise().maxCoeff() - low).maxCoeff(), 1e-9);
  const auto cells = static_cast<double>((1U << 21U) - 1U);
  std::vector<std::pair<std::uint64_t, Eigen::Index>> keyed(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    std::uint64_t code = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto cell = static_cast<std::uint64_t>((V(i, axis) - low[axis]) / extent * cells);
      code |= spread_bits(cell) << axis;
    }
    keyed[static_cast<std::size_t>(i)] = {code, i};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<Eigen::Index> order;
  order.reserve(keyed.size());
  for (const auto& entry : keyed) order.push_back(entry.second);
  return order;
}

}  // namespace

PreparedMuscle prepare_muscle(const std::string& name, const mesh::IndexedMesh& surface,
                              const std::vector<BoneAtRest>& bones,
                              const MuscleEnergyOptions& options) {
  mesh::validate_indices_and_coordinates(surface);
  if (bones.empty()) throw InvalidInputError("muscle energy '" + name + "': no bones");
  PreparedMuscle muscle;
  muscle.name = name;
  muscle.rest = surface.V;
  muscle.faces = surface.F;
  const Eigen::Index n = surface.V.rows();
  const auto bone_count = static_cast<Eigen::Index>(bones.size());
  std::vector<mesh::AabbTree> coarse;
  coarse.reserve(bones.size());
  for (const BoneAtRest& bone : bones) coarse.emplace_back(*bone.coarse);

  muscle.blend.resize(n, bone_count);
  const double eps2 = options.blend_radius_mm * options.blend_radius_mm;
  std::vector<double> coarse_distance(bones.size());
  // The distance to a surface is 1-Lipschitz: the previous vertex's answer
  // plus the step bounds this one's, which prunes most of each tree (the
  // answer is exact either way).
  // Visiting the vertices in Morton (Z-curve) order keeps consecutive ones
  // close, so that bound is tight.
  Vector3d previous = surface.V.row(0).transpose();
  std::vector<double> previous_distance(bones.size(), -1.0);
  for (const Eigen::Index i : morton_order(surface.V)) {
    const Vector3d p = surface.V.row(i).transpose();
    const double step = (p - previous).norm();
    previous = p;
    double total = 0.0;
    for (Eigen::Index b = 0; b < bone_count; ++b) {
      const auto bb = static_cast<std::size_t>(b);
      std::optional<mesh::AabbTree::ClosestPoint> closest;
      if (previous_distance[bb] >= 0.0) {
        const double bound = previous_distance[bb] + step + 1e-9;
        closest = coarse[bb].closest_point_within(p, bound * bound);
      }
      if (!closest) closest = coarse[bb].closest_point(p);
      const double d2 = closest->squared_distance;
      previous_distance[bb] = std::sqrt(d2);
      coarse_distance[bb] = previous_distance[bb];
      muscle.blend(i, b) = 1.0 / (d2 + eps2);
      total += muscle.blend(i, b);
    }
    muscle.blend.row(i) /= total;
    // Every bone this vertex is near, on the full surfaces; the nearest.
    double best = std::numeric_limits<double>::infinity();
    int best_bone = -1;
    for (Eigen::Index b = 0; b < bone_count; ++b) {
      if (coarse_distance[static_cast<std::size_t>(b)] > options.band_mm + kCoarseMarginMm) {
        continue;
      }
      // Unsigned first (a pruned closest-point query); the sign (a winding
      // number, the dearer half) only for vertices within the band.
      const mesh::SignedDistance& distance = *bones[static_cast<std::size_t>(b)].distance;
      const std::optional<mesh::AabbTree::ClosestPoint> closest =
          distance.tree().closest_point_within(p, options.band_mm * options.band_mm);
      if (!closest) continue;
      const double unsigned_distance = std::sqrt(closest->squared_distance);
      const double sd = distance.winding().is_inside(p) ? -unsigned_distance : unsigned_distance;
      muscle.band.push_back(static_cast<int>(i));
      muscle.band_bone.push_back(static_cast<int>(b));
      muscle.band_rest_distance.push_back(sd);
      if (sd < best) {
        best = sd;
        best_bone = static_cast<int>(b);
      }
    }
    if (best_bone >= 0 && best <= options.contact_distance_mm) {
      muscle.attached.push_back(static_cast<int>(i));
      muscle.attached_bone.push_back(best_bone);
      muscle.attached_anchor.push_back(
          bones[static_cast<std::size_t>(best_bone)].anchors->anchor(p));
    }
  }

  const SparseMatrix L = mesh::cotangent_laplacian(surface.V, surface.F);
  SparseMatrix K = options.laplacian_weight * SparseMatrix(L.transpose() * L);
  VectorXd diagonal = VectorXd::Constant(n, options.gauge_weight * K.diagonal().mean());
  std::vector<bool> in_band(static_cast<std::size_t>(n), false);
  for (const int i : muscle.band) in_band[static_cast<std::size_t>(i)] = true;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (in_band[static_cast<std::size_t>(i)]) diagonal[i] += options.band_weight;
  }
  for (const int i : muscle.attached) diagonal[i] += options.attachment_weight;
  K += SparseMatrix(diagonal.asDiagonal());
  muscle.factor = std::make_shared<SparseCholesky>(K);
  if (muscle.factor->info() != Eigen::Success) {
    throw SolverError("muscle energy '" + name + "': the sparse Cholesky factorisation failed");
  }
  muscle.rest_volume_mm3 = mesh::signed_volume(surface);
  return muscle;
}

MuscleSolution solve_muscle(const PreparedMuscle& muscle, const std::vector<ScaledBone>& bones,
                            const MuscleEnergyOptions& options) {
  if (static_cast<Eigen::Index>(bones.size()) != muscle.blend.cols()) {
    throw InvalidInputError("muscle energy '" + muscle.name + "': " + std::to_string(bones.size()) +
                            " scaled bones given, prepared with " +
                            std::to_string(muscle.blend.cols()));
  }
  const Eigen::Index n = muscle.rest.rows();
  // X1: the blend of the bones' affine maps.
  Eigen::MatrixX3d start = Eigen::MatrixX3d::Zero(n, 3);
  for (std::size_t b = 0; b < bones.size(); ++b) {
    const Eigen::Affine3d& map = *bones[b].affine;
    const Eigen::MatrixX3d mapped =
        (muscle.rest * map.linear().transpose()).rowwise() + map.translation().transpose();
    start += muscle.blend.col(static_cast<Eigen::Index>(b)).asDiagonal() * mapped;
  }
  Eigen::MatrixX3d attached_rhs = Eigen::MatrixX3d::Zero(n, 3);
  MuscleSolution solution;
  solution.attached_vertices = static_cast<int>(muscle.attached.size());
  solution.band_vertices =
      static_cast<int>(std::set<int>(muscle.band.begin(), muscle.band.end()).size());
  double attached_sq = 0.0;
  for (std::size_t a = 0; a < muscle.attached.size(); ++a) {
    const int i = muscle.attached[a];
    const Vector3d target =
        reconstruct(muscle.attached_anchor[a],
                    *bones[static_cast<std::size_t>(muscle.attached_bone[a])].vertices);
    attached_rhs.row(i) =
        options.attachment_weight * (target - start.row(i).transpose()).transpose();
  }
  std::vector<double> bone_scale;
  bone_scale.reserve(bones.size());
  for (const ScaledBone& bone : bones) {
    bone_scale.push_back(std::cbrt(std::abs(bone.affine->linear().determinant())));
  }
  // Band targets, as offsets from X1 (0 until a vertex must be pushed out).
  Eigen::MatrixX3d band_offset =
      Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(muscle.band.size()), 3);
  for (int iteration = 0;; ++iteration) {
    Eigen::MatrixX3d rhs = attached_rhs;
    for (std::size_t k = 0; k < muscle.band.size(); ++k) {
      rhs.row(muscle.band[k]) +=
          options.band_weight * band_offset.row(static_cast<Eigen::Index>(k));
    }
    solution.vertices = start;
    for (int c = 0; c < 3; ++c) {
      solution.vertices.col(c) += muscle.factor->solve(VectorXd(rhs.col(c)));
    }
    int penetrating = 0;
    double worst = 0.0;
    for (std::size_t k = 0; k < muscle.band.size(); ++k) {
      const int i = muscle.band[k];
      const mesh::SignedDistance& bone =
          *bones[static_cast<std::size_t>(muscle.band_bone[k])].distance;
      const Vector3d x = solution.vertices.row(i).transpose();
      const double sd = bone.at(x);
      const double excess = excess_depth(sd, muscle.band_rest_distance[k],
                                         bone_scale[static_cast<std::size_t>(muscle.band_bone[k])]);
      if (excess <= options.penetration_tolerance_mm) continue;
      ++penetrating;
      worst = std::max(worst, excess);
      const Vector3d towards = bone.tree().closest_point(x).point - x;
      if (towards.norm() > 0.0) {
        band_offset.row(static_cast<Eigen::Index>(k)) +=
            ((excess + options.penetration_margin_mm) * towards.normalized()).transpose();
      }
    }
    if (iteration == 0) {
      solution.penetrating_before = penetrating;
      solution.excess_depth_before_mm = worst;
    }
    solution.penetrating_after = penetrating;
    solution.excess_depth_after_mm = worst;
    solution.penetration_iterations = iteration;
    if (penetrating == 0 || iteration >= options.max_penetration_iterations) break;
  }
  for (const int i : muscle.attached) {
    const Vector3d target =
        start.row(i).transpose() + attached_rhs.row(i).transpose() / options.attachment_weight;
    attached_sq += (solution.vertices.row(i).transpose() - target).squaredNorm();
  }
  if (!muscle.attached.empty()) {
    solution.attachment_rms_mm =
        std::sqrt(attached_sq / static_cast<double>(muscle.attached.size()));
  }
  const mesh::IndexedMesh placed{solution.vertices, muscle.faces};
  solution.volume_ratio = mesh::signed_volume(placed) / muscle.rest_volume_mm3;
  return solution;
}

}  // namespace mmm::scaling
