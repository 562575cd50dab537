#include "core/wrapping/volume_deformer.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <mutex>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/mesh/laplacian.h"
#include "core/scaling/sparse_cholesky.h"
#include "core/wrapping/deformer_math.h"

namespace mmm::wrapping {
namespace {

using Eigen::MatrixX3d;
using Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;
using detail::frobenius_dot;

void check_options(const DeformerOptions& options) {
  const bool valid = options.stiffness_length_mm > 0 &&
                     std::isfinite(options.stiffness_length_mm) && options.contact_weight > 0 &&
                     std::isfinite(options.contact_weight) && options.volume_tolerance > 0 &&
                     options.max_volume_iterations >= 1 && options.max_contact_rounds >= 1;
  if (!valid) {
    throw InvalidInputError(
        "volume deformer: options need stiffness_length_mm > 0, contact_weight > 0, "
        "volume_tolerance > 0, max_volume_iterations >= 1 and max_contact_rounds >= 1");
  }
}

double mean_edge_length(const mesh::IndexedMesh& mesh) {
  double sum = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      sum += (mesh.V.row(mesh.F(f, corner)) - mesh.V.row(mesh.F(f, (corner + 1) % 3))).norm();
    }
  }
  return sum / static_cast<double>(3 * mesh.F.rows());
}

}  // namespace

double enclosed_volume(const MatrixX3d& x, const Eigen::MatrixX3i& F) {
  double six_volume = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = x.row(F(f, 0));
    const Eigen::Vector3d b = x.row(F(f, 1));
    const Eigen::Vector3d c = x.row(F(f, 2));
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

MatrixX3d enclosed_volume_gradient(const MatrixX3d& x, const Eigen::MatrixX3i& F) {
  MatrixX3d gradient = MatrixX3d::Zero(x.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = x.row(F(f, 0));
    const Eigen::Vector3d b = x.row(F(f, 1));
    const Eigen::Vector3d c = x.row(F(f, 2));
    gradient.row(F(f, 0)) += b.cross(c).transpose() / 6.0;
    gradient.row(F(f, 1)) += c.cross(a).transpose() / 6.0;
    gradient.row(F(f, 2)) += a.cross(b).transpose() / 6.0;
  }
  return gradient;
}

struct VolumeDeformer::State {
  mesh::IndexedMesh rest;
  DeformerOptions options;
  SparseMatrix laplacian;
  MatrixX3d rest_detail;  // L X
  double rest_volume = 0.0;
  double tie_weight = 0.0;
  SparseMatrix matrix;  // A
  scaling::SparseCholesky factor;
  // A + c E E^T, refactored (same pattern: only the diagonal changes) when
  // there are too many contacts for the Woodbury update to pay.
  scaling::SparseCholesky contact_factor;
  bool contact_pattern_analysed = false;
  std::mutex solve_mutex;  // CHOLMOD's workspace is shared by the solves of one factor
};

VolumeDeformer::VolumeDeformer(const mesh::IndexedMesh& rest, const DeformerOptions& options)
    : state_(std::make_unique<State>()) {
  check_options(options);
  mesh::validate_indices_and_coordinates(rest);
  if (rest.F.rows() < 4)
    throw InvalidInputError("volume deformer: the surface has fewer than 4 faces");
  State& s = *state_;
  s.rest = rest;
  s.options = options;
  s.rest_volume = enclosed_volume(rest.V, rest.F);
  if (!(s.rest_volume > 0)) {
    throw InvalidInputError("volume deformer: the surface encloses no positive volume (" +
                            std::to_string(s.rest_volume) +
                            " mm^3); hint: it must be closed and outward oriented");
  }
  s.laplacian = mesh::cotangent_laplacian(rest.V, rest.F);
  s.rest_detail = s.laplacian * rest.V;
  s.tie_weight = std::pow(mean_edge_length(rest) / options.stiffness_length_mm, 4.0);
  const auto n = rest.V.rows();
  SparseMatrix identity(n, n);
  identity.setIdentity();
  s.matrix = SparseMatrix(s.laplacian.transpose() * s.laplacian) + s.tie_weight * identity;
  s.factor.compute(s.matrix);
  if (s.factor.info() != Eigen::Success) {
    throw InvalidInputError(
        "volume deformer: the energy matrix could not be factored; hint: "
        "the surface has unreferenced vertices or degenerate faces");
  }
}

VolumeDeformer::~VolumeDeformer() = default;
VolumeDeformer::VolumeDeformer(VolumeDeformer&&) noexcept = default;
VolumeDeformer& VolumeDeformer::operator=(VolumeDeformer&&) noexcept = default;

const mesh::IndexedMesh& VolumeDeformer::rest() const { return state_->rest; }
double VolumeDeformer::rest_volume() const { return state_->rest_volume; }
double VolumeDeformer::tie_weight() const { return state_->tie_weight; }

namespace {

// Up to this many contacts, (A + c E E^T)^-1 is applied by the Woodbury
// identity on A's factor: A_C^-1 R = A^-1 R - Z S^-1 (A^-1 R)_C with
// Z = A^-1 E and S = I / c + Z_C (one back-substitution per contact); beyond
// it, A + c E E^T is factored anew (numeric factorisation only: same pattern).
constexpr std::size_t kWoodburyContacts = 64;

class ContactSolver {
 public:
  ContactSolver(VolumeDeformer::State& state, Eigen::Index n) : state_(state), n_(n) {}

  void add(const std::vector<Contact>& added) {
    if (added.empty()) return;
    contacts_.insert(contacts_.end(), added.begin(), added.end());
    if (contacts_.size() > kWoodburyContacts) {
      refactor();
      return;
    }
    const auto k = static_cast<Eigen::Index>(contacts_.size());
    const auto old_k = k - static_cast<Eigen::Index>(added.size());
    MatrixXd selector = MatrixXd::Zero(n_, k - old_k);
    for (Eigen::Index j = 0; j < k - old_k; ++j)
      selector(added[static_cast<std::size_t>(j)].vertex, j) = 1.0;
    const MatrixXd new_columns = state_.factor.solve(selector);
    Z_.conservativeResize(n_, k);
    Z_.rightCols(k - old_k) = new_columns;
    MatrixXd S(k, k);
    for (Eigen::Index i = 0; i < k; ++i)
      S.row(i) = Z_.row(contacts_[static_cast<std::size_t>(i)].vertex);
    S = 0.5 * (S + S.transpose()).eval();
    for (Eigen::Index i = 0; i < k; ++i)
      S(i, i) += 1.0 / weight(contacts_[static_cast<std::size_t>(i)]);
    capacitance_.compute(S);
  }

  [[nodiscard]] MatrixX3d solve(const MatrixX3d& rhs) const {
    if (refactored_) return state_.contact_factor.solve(rhs);
    MatrixX3d u = state_.factor.solve(rhs);
    if (contacts_.empty()) return u;
    MatrixXd at_contacts(static_cast<Eigen::Index>(contacts_.size()), 3);
    for (std::size_t i = 0; i < contacts_.size(); ++i) {
      at_contacts.row(static_cast<Eigen::Index>(i)) = u.row(contacts_[i].vertex);
    }
    u -= Z_ * capacitance_.solve(at_contacts);
    return u;
  }

  [[nodiscard]] MatrixX3d pull() const {
    MatrixX3d result = MatrixX3d::Zero(n_, 3);
    for (const Contact& contact : contacts_) {
      result.row(contact.vertex) += weight(contact) * contact.target.transpose();
    }
    return result;
  }

  [[nodiscard]] const std::vector<Contact>& contacts() const { return contacts_; }

 private:
  [[nodiscard]] double weight(const Contact& contact) const {
    return contact.weight > 0.0 ? contact.weight : state_.options.contact_weight;
  }

  void refactor() {
    SparseMatrix matrix = state_.matrix;
    for (const Contact& contact : contacts_)
      matrix.coeffRef(contact.vertex, contact.vertex) += weight(contact);
    if (!state_.contact_pattern_analysed) {
      state_.contact_factor.analyzePattern(matrix);
      state_.contact_pattern_analysed = true;
    }
    state_.contact_factor.factorize(matrix);
    if (state_.contact_factor.info() != Eigen::Success) {
      throw InvalidInputError(
          "volume deformer: the energy matrix with contacts could not be factored");
    }
    refactored_ = true;
  }

  VolumeDeformer::State& state_;
  Eigen::Index n_;
  bool refactored_ = false;
  std::vector<Contact> contacts_;
  MatrixXd Z_;
  Eigen::LLT<MatrixXd> capacitance_;
};

}  // namespace

MatrixX3d VolumeDeformer::right_hand_side(const MatrixX3d& targets,
                                          const std::vector<Eigen::Matrix3d>& rotations) const {
  const State& s = *state_;
  const auto n = s.rest.V.rows();
  if (targets.rows() != n || !targets.allFinite()) {
    throw InvalidInputError("volume deformer: targets must be " + std::to_string(n) +
                            " finite rows, got " + std::to_string(targets.rows()));
  }
  if (!rotations.empty() && static_cast<Eigen::Index>(rotations.size()) != n) {
    throw InvalidInputError("volume deformer: " + std::to_string(rotations.size()) +
                            " rotations for " + std::to_string(n) + " vertices");
  }
  MatrixX3d detail = s.rest_detail;
  if (!rotations.empty()) {
    for (Eigen::Index i = 0; i < n; ++i) {
      detail.row(i) =
          (rotations[static_cast<std::size_t>(i)] * s.rest_detail.row(i).transpose()).transpose();
    }
  }
  return s.laplacian * detail + s.tie_weight * targets;
}

const Eigen::SparseMatrix<double>& VolumeDeformer::energy_matrix() const { return state_->matrix; }
const DeformerOptions& VolumeDeformer::options() const { return state_->options; }

DeformResult VolumeDeformer::solve(const MatrixX3d& targets,
                                   const std::vector<Eigen::Matrix3d>& rotations,
                                   std::vector<Contact> contacts, const ContactQuery& query) const {
  State& s = *state_;
  const auto n = s.rest.V.rows();
  std::vector<char> active(static_cast<std::size_t>(n), 0);
  auto accept = [&](std::vector<Contact>& candidates) {
    std::vector<Contact> fresh;
    for (const Contact& contact : candidates) {
      if (contact.vertex < 0 || contact.vertex >= n || !contact.target.allFinite() ||
          !(contact.weight >= 0.0 && std::isfinite(contact.weight))) {
        throw InvalidInputError("volume deformer: contact at vertex " +
                                std::to_string(contact.vertex) +
                                " is out of range or not finite, or its weight is negative");
      }
      auto& flag = active[static_cast<std::size_t>(contact.vertex)];
      if (flag == 0) {
        flag = 1;
        fresh.push_back(contact);
      }
    }
    return fresh;
  };

  const MatrixX3d fixed_rhs = right_hand_side(targets, rotations);

  const std::lock_guard lock(s.solve_mutex);
  ContactSolver solver(s, n);
  solver.add(accept(contacts));
  DeformResult result;
  MatrixX3d x = targets;
  for (int round = 0;; ++round) {
    const MatrixX3d unconstrained = solver.solve(fixed_rhs + solver.pull());
    x = unconstrained;
    bool volume_ok = false;
    for (int iteration = 0; iteration < s.options.max_volume_iterations; ++iteration) {
      const double volume = enclosed_volume(x, s.rest.F);
      if (std::abs(volume - s.rest_volume) <= s.options.volume_tolerance * s.rest_volume) {
        volume_ok = true;
        break;
      }
      const MatrixX3d gradient = enclosed_volume_gradient(x, s.rest.F);
      const MatrixX3d direction = solver.solve(gradient);
      const double slope = frobenius_dot(gradient, direction);
      if (!(std::abs(slope) > 0)) break;
      const double lambda =
          (frobenius_dot(gradient, unconstrained - x) - (s.rest_volume - volume)) / slope;
      x = unconstrained - lambda * direction;
      ++result.volume_iterations;
    }
    if (!volume_ok) {
      volume_ok = std::abs(enclosed_volume(x, s.rest.F) - s.rest_volume) <=
                  s.options.volume_tolerance * s.rest_volume;
    }
    result.converged = volume_ok;
    if (!query) break;
    std::vector<Contact> found = query(x, active);
    std::vector<Contact> fresh = accept(found);
    if (fresh.empty()) break;
    if (round + 1 >= s.options.max_contact_rounds) {
      result.converged = false;
      break;
    }
    solver.add(fresh);
    result.contact_rounds = round + 1;
  }
  result.volume = enclosed_volume(x, s.rest.F);
  result.volume_error = (result.volume - s.rest_volume) / s.rest_volume;
  result.contacts = solver.contacts();
  result.x = std::move(x);
  return result;
}

}  // namespace mmm::wrapping
