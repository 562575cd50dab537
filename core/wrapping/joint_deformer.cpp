#include "core/wrapping/joint_deformer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_map>

#include "core/errors.h"
#include "core/parallel_for.h"
#include "core/scaling/sparse_cholesky.h"
#include "core/wrapping/deformer_math.h"

namespace mmm::wrapping {
namespace {

using detail::frobenius_dot;
using Eigen::MatrixX3d;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// Vertex `vertex` of body `body` tied to the point of body `other`'s surface
// with barycentric weights `weights` on the corners `corners`.
struct Coupling {
  int body = -1;
  int vertex = -1;
  int other = -1;
  Eigen::Vector3i corners = Eigen::Vector3i::Zero();
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
};

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<std::size_t> parent_;
};

void check(const std::vector<JointBody>& bodies, const JointOptions& options) {
  const MuscleContactOptions& c = options.coupling;
  if (!(c.weight > 0.0) || !std::isfinite(c.weight) || !(c.tolerance_mm >= 0.0) ||
      !(c.reach_mm > 0.0) || !(options.local_radius_mm >= 0.0) || options.max_rounds < 1 ||
      options.threads < 1) {
    throw InvalidInputError(
        "joint deformer: options need a coupling weight > 0, tolerance >= 0, reach > 0, "
        "a local radius >= 0, max_rounds >= 1 and threads >= 1");
  }
  for (std::size_t m = 0; m < bodies.size(); ++m) {
    const JointBody& body = bodies[m];
    const std::string which = "joint deformer: body " + std::to_string(m);
    if (body.deformer == nullptr) throw InvalidInputError(which + " has no deformer");
    const auto n = body.deformer->rest().V.rows();
    if (body.start.rows() != n || body.right_hand_side.rows() != n || !body.start.allFinite() ||
        !body.right_hand_side.allFinite()) {
      throw InvalidInputError(which + ": start and right-hand side must be " + std::to_string(n) +
                              " finite rows");
    }
    for (const Contact& contact : body.contacts) {
      if (contact.vertex < 0 || contact.vertex >= n || !contact.target.allFinite() ||
          !(contact.weight >= 0.0 && std::isfinite(contact.weight)))
        throw InvalidInputError(which + ": a contact is out of range or not finite");
    }
  }
}

// A group's volume steps (one solve with a column per body and coordinate
// each) stop when no vertex moves further than kSettledMm, or after
// kMaxVolumeSteps: the volumes are exact after each.
constexpr double kSettledMm = 1e-2;
constexpr int kMaxVolumeSteps = 6;

double pin_weight(const JointBody& body, const Contact& contact) {
  return contact.weight > 0.0 ? contact.weight : body.deformer->options().contact_weight;
}

// The bodies of one connected group of couplings, stacked.
struct Group {
  std::vector<int> bodies;
  std::vector<Eigen::Index> offsets;  // first row of each body
  Eigen::Index rows = 0;
};

// Everything a round knows: positions, pins, couplings and per-body flags.
struct JointState {
  std::vector<MatrixX3d> x;
  std::vector<std::vector<Contact>> pins;
  std::vector<std::vector<char>> taken;  // per body and vertex: pinned or coupled
  std::vector<Coupling> couplings;
  std::vector<int> volume_iterations;
  std::vector<char> volume_ok;
};

// The volume constraints of a group: vol(x_m) = vol(X_m) for each body m of
// the stacked positions x.
class GroupVolumes {
 public:
  GroupVolumes(const std::vector<JointBody>& bodies, const Group& group) : group_(group) {
    for (const int m : group.bodies)
      deformers_.push_back(bodies[static_cast<std::size_t>(m)].deformer);
  }

  // #rows by 3 M: column 3 k + c holds coordinate c of body k's volume
  // gradient in its rows, zero elsewhere.
  [[nodiscard]] MatrixXd gradients(const MatrixX3d& x) const {
    MatrixXd G = MatrixXd::Zero(group_.rows, 3 * size());
    for (Eigen::Index k = 0; k < size(); ++k)
      G.block(offset(k), 3 * k, rows(k), 3) = enclosed_volume_gradient(part(x, k), faces(k));
    return G;
  }

  // u - sum_l lambda_l D_l, D_l the three columns of body l.
  [[nodiscard]] static MatrixX3d positions(const MatrixX3d& u, const MatrixXd& directions,
                                           const VectorXd& lambda) {
    MatrixX3d x = u;
    for (Eigen::Index l = 0; l < lambda.size(); ++l)
      x -= lambda[l] * directions.middleCols(3 * l, 3);
    return x;
  }

  // The multipliers that give every body its rest volume at
  // positions(u, directions, lambda), by Newton from `start` (the volumes
  // are cubic in lambda); nullopt when it does not converge.
  [[nodiscard]] std::optional<VectorXd> multipliers(const MatrixX3d& u, const MatrixXd& directions,
                                                    const VectorXd& start) const {
    constexpr int kMaxNewton = 50;
    VectorXd lambda = start;
    for (int iteration = 0; iteration < kMaxNewton; ++iteration) {
      const MatrixX3d x = positions(u, directions, lambda);
      VectorXd residual(size());
      MatrixXd jacobian(size(), size());
      for (Eigen::Index k = 0; k < size(); ++k) {
        const MatrixX3d xk = part(x, k);
        residual[k] = enclosed_volume(xk, faces(k)) - deformers_[index(k)]->rest_volume();
        const MatrixX3d g = enclosed_volume_gradient(xk, faces(k));
        for (Eigen::Index l = 0; l < size(); ++l)
          jacobian(k, l) = -frobenius_dot(g, directions.block(offset(k), 3 * l, rows(k), 3));
      }
      if (within_tolerance(residual)) return lambda;
      // A body held whole in a restricted solve keeps its volume and its
      // multiplier.
      for (Eigen::Index k = 0; k < size(); ++k) {
        if (jacobian.row(k).isZero(0.0)) jacobian(k, k) = 1.0;
      }
      const VectorXd step = jacobian.partialPivLu().solve(residual);
      if (!step.allFinite()) return std::nullopt;
      lambda -= step;
    }
    return std::nullopt;
  }

  [[nodiscard]] bool within_tolerance(const MatrixX3d& x) const {
    VectorXd residual(size());
    for (Eigen::Index k = 0; k < size(); ++k)
      residual[k] = enclosed_volume(part(x, k), faces(k)) - deformers_[index(k)]->rest_volume();
    return within_tolerance(residual);
  }

 private:
  [[nodiscard]] bool within_tolerance(const VectorXd& residual) const {
    for (Eigen::Index k = 0; k < size(); ++k) {
      const VolumeDeformer& d = *deformers_[index(k)];
      if (!(std::abs(residual[k]) <= d.options().volume_tolerance * d.rest_volume())) return false;
    }
    return true;
  }
  [[nodiscard]] Eigen::Index size() const { return static_cast<Eigen::Index>(deformers_.size()); }
  [[nodiscard]] static std::size_t index(Eigen::Index k) { return static_cast<std::size_t>(k); }
  [[nodiscard]] Eigen::Index offset(Eigen::Index k) const { return group_.offsets[index(k)]; }
  [[nodiscard]] Eigen::Index rows(Eigen::Index k) const {
    return deformers_[index(k)]->rest().V.rows();
  }
  [[nodiscard]] const Eigen::MatrixX3i& faces(Eigen::Index k) const {
    return deformers_[index(k)]->rest().F;
  }
  [[nodiscard]] MatrixX3d part(const MatrixX3d& x, Eigen::Index k) const {
    return x.middleRows(offset(k), rows(k));
  }

  const Group& group_;
  std::vector<const VolumeDeformer*> deformers_;
};

// A group's energy: the stacked matrix K and right-hand side b.
struct GroupEnergy {
  Eigen::SparseMatrix<double> matrix;
  MatrixX3d rhs;
};

GroupEnergy assemble(const std::vector<JointBody>& bodies, const Group& group,
                     const std::vector<const Coupling*>& couplings, double coupling_weight,
                     const JointState& state) {
  std::vector<Eigen::Index> offset(bodies.size(), -1);
  for (std::size_t k = 0; k < group.bodies.size(); ++k)
    offset[static_cast<std::size_t>(group.bodies[k])] = group.offsets[k];
  std::vector<Eigen::Triplet<double>> entries;
  GroupEnergy energy;
  energy.rhs = MatrixX3d::Zero(group.rows, 3);
  for (std::size_t k = 0; k < group.bodies.size(); ++k) {
    const auto m = static_cast<std::size_t>(group.bodies[k]);
    const JointBody& body = bodies[m];
    const Eigen::SparseMatrix<double>& A = body.deformer->energy_matrix();
    const Eigen::Index base = group.offsets[k];
    for (Eigen::Index column = 0; column < A.outerSize(); ++column) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, column); it; ++it)
        entries.emplace_back(base + it.row(), base + it.col(), it.value());
    }
    energy.rhs.middleRows(base, A.rows()) = body.right_hand_side;
    for (const Contact& pin : state.pins[m]) {
      const double w = pin_weight(body, pin);
      entries.emplace_back(base + pin.vertex, base + pin.vertex, w);
      energy.rhs.row(base + pin.vertex) += w * pin.target.transpose();
    }
  }
  for (const Coupling* coupling : couplings) {
    const auto other = offset[static_cast<std::size_t>(coupling->other)];
    const std::array<Eigen::Index, 4> index = {
        offset[static_cast<std::size_t>(coupling->body)] + coupling->vertex,
        other + coupling->corners[0], other + coupling->corners[1], other + coupling->corners[2]};
    const std::array<double, 4> coefficient = {1.0, -coupling->weights[0], -coupling->weights[1],
                                               -coupling->weights[2]};
    for (std::size_t i = 0; i < 4; ++i) {
      for (std::size_t j = 0; j < 4; ++j)
        entries.emplace_back(index[i], index[j], coupling_weight * coefficient[i] * coefficient[j]);
    }
  }
  energy.matrix.resize(group.rows, group.rows);
  energy.matrix.setFromTriplets(entries.begin(), entries.end());
  return energy;
}

// K restricted to the free rows (all when `free` is empty), the others held
// at x: solves return zero on the held rows.
class RestrictedSolver {
 public:
  RestrictedSolver(const GroupEnergy& energy, const MatrixX3d& x, const std::vector<char>& free)
      : held_(MatrixX3d::Zero(x.rows(), 3)) {
    if (free.empty()) {
      factor_.compute(energy.matrix);
      check();
      unconstrained_ = factor_.solve(energy.rhs);
      return;
    }
    std::vector<Eigen::Triplet<double>> selection;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      if (free[static_cast<std::size_t>(i)] != 0) {
        selection.emplace_back(static_cast<Eigen::Index>(selection.size()), i, 1.0);
      } else {
        held_.row(i) = x.row(i);
      }
    }
    select_.resize(static_cast<Eigen::Index>(selection.size()), x.rows());
    select_.setFromTriplets(selection.begin(), selection.end());
    const Eigen::SparseMatrix<double> reduced =
        select_ * energy.matrix * Eigen::SparseMatrix<double>(select_.transpose());
    factor_.compute(reduced);
    check();
    const MatrixX3d reduced_rhs = select_ * (energy.rhs - energy.matrix * held_);
    unconstrained_ = held_ + select_.transpose() * MatrixX3d(factor_.solve(reduced_rhs));
  }

  // The minimiser of the energy without volume constraints (held rows: x).
  [[nodiscard]] const MatrixX3d& unconstrained() const { return unconstrained_; }

  // K_ff^-1 on the free rows of `columns`; zero on the held rows.
  [[nodiscard]] MatrixXd solve(const MatrixXd& columns) const {
    if (select_.rows() == 0) return factor_.solve(columns);
    return select_.transpose() * MatrixXd(factor_.solve(MatrixXd(select_ * columns)));
  }

 private:
  void check() const {
    if (factor_.info() != Eigen::Success)
      throw InvalidInputError("joint deformer: the coupled energy matrix could not be factored");
  }

  MatrixX3d held_;
  Eigen::SparseMatrix<double> select_;  // free rows <- all rows (empty: all free)
  scaling::SparseCholesky factor_;
  MatrixX3d unconstrained_;
};

// Solves one group (only its rows flagged in `free`, all when empty): the
// coupled energy, then Gauss-Newton on the volumes with one multiplier per
// body. Writes the group's positions.
void solve_group(const std::vector<JointBody>& bodies, const Group& group,
                 const std::vector<const Coupling*>& couplings, double coupling_weight,
                 const std::vector<char>& free, JointState& state) {
  MatrixX3d x(group.rows, 3);
  for (std::size_t k = 0; k < group.bodies.size(); ++k) {
    const MatrixX3d& before = state.x[static_cast<std::size_t>(group.bodies[k])];
    x.middleRows(group.offsets[k], before.rows()) = before;
  }
  const RestrictedSolver solver(assemble(bodies, group, couplings, coupling_weight, state), x,
                                free);
  const MatrixX3d& unconstrained = solver.unconstrained();
  const GroupVolumes volumes(bodies, group);
  // Linearised first where the volumes are right (x: the positions before
  // this solve), not at the unconstrained answer, which pressed surfaces may
  // have emptied.
  // Gauss-Newton: directions K^-1 g_l from the gradients at x, then the
  // multipliers that give every body its volume exactly along them (Newton
  // on lambda, no further solve). Repeated, linearised where the volumes are
  // right and the surfaces pressed, until the positions settle.
  int steps = 0;
  VectorXd lambda = VectorXd::Zero(static_cast<Eigen::Index>(group.bodies.size()));
  while (steps < kMaxVolumeSteps) {
    const MatrixXd directions = solver.solve(volumes.gradients(x));
    const std::optional<VectorXd> exact = volumes.multipliers(unconstrained, directions, lambda);
    if (!exact) break;
    const MatrixX3d moved = GroupVolumes::positions(unconstrained, directions, *exact);
    const double change = (moved - x).cwiseAbs().maxCoeff();
    lambda = *exact;
    x = moved;
    ++steps;
    if (change < kSettledMm) break;
  }
  const bool volumes_ok = volumes.within_tolerance(x);
  for (std::size_t k = 0; k < group.bodies.size(); ++k) {
    const auto m = static_cast<std::size_t>(group.bodies[k]);
    state.x[m] = x.middleRows(group.offsets[k], state.x[m].rows());
    state.volume_iterations[m] += steps;
    state.volume_ok[m] = volumes_ok ? 1 : 0;
  }
}

// The groups (connected by couplings) that hold a body flagged in `dirty`.
std::vector<Group> dirty_groups(const std::vector<JointBody>& bodies,
                                const std::vector<Coupling>& couplings,
                                const std::vector<char>& dirty) {
  DisjointSets sets(bodies.size());
  for (const Coupling& coupling : couplings)
    sets.join(static_cast<std::size_t>(coupling.body), static_cast<std::size_t>(coupling.other));
  std::vector<char> root_dirty(bodies.size(), 0);
  for (std::size_t m = 0; m < bodies.size(); ++m) {
    if (dirty[m] != 0) root_dirty[sets.find(m)] = 1;
  }
  std::vector<int> group_of_root(bodies.size(), -1);
  std::vector<Group> groups;
  for (std::size_t m = 0; m < bodies.size(); ++m) {
    const std::size_t root = sets.find(m);
    if (root_dirty[root] == 0) continue;
    if (group_of_root[root] < 0) {
      group_of_root[root] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    Group& group = groups[static_cast<std::size_t>(group_of_root[root])];
    group.bodies.push_back(static_cast<int>(m));
    group.offsets.push_back(group.rows);
    group.rows += bodies[m].deformer->rest().V.rows();
  }
  return groups;
}

// New pins and couplings on the current surfaces; flags the bodies that
// gained any in `dirty`. True when there were any.
bool find_new(const std::vector<JointBody>& bodies, const JointOptions& options, JointState& state,
              std::vector<char>& dirty, std::vector<Eigen::Vector3d>& seeds) {
  seeds.clear();
  std::vector<const Eigen::MatrixX3i*> faces;
  faces.reserve(bodies.size());
  for (const JointBody& body : bodies) faces.push_back(&body.deformer->rest().F);
  const MuscleSurfaces surfaces(state.x, faces, options.threads);
  std::vector<std::vector<Contact>> pins(bodies.size());
  std::vector<std::vector<MuscleOverlap>> overlaps(bodies.size());
  parallel_for(bodies.size(), options.threads, [&](std::size_t m) {
    if (bodies[m].query) pins[m] = bodies[m].query(state.x[m], state.taken[m]);
    std::vector<char> taken = state.taken[m];
    for (const Contact& pin : pins[m]) taken[static_cast<std::size_t>(pin.vertex)] = 1;
    overlaps[m] =
        muscle_overlaps(static_cast<int>(m), state.x[m], taken, surfaces, options.coupling);
  });
  std::fill(dirty.begin(), dirty.end(), 0);
  bool any = false;
  for (std::size_t m = 0; m < bodies.size(); ++m) {
    for (const Contact& pin : pins[m]) {
      if (pin.vertex < 0 || pin.vertex >= static_cast<int>(state.taken[m].size()) ||
          state.taken[m][static_cast<std::size_t>(pin.vertex)] != 0)
        continue;
      state.taken[m][static_cast<std::size_t>(pin.vertex)] = 1;
      state.pins[m].push_back(pin);
      seeds.emplace_back(state.x[m].row(pin.vertex).transpose());
      dirty[m] = 1;
      any = true;
    }
    for (const MuscleOverlap& overlap : overlaps[m]) {
      state.taken[m][static_cast<std::size_t>(overlap.vertex)] = 1;
      seeds.emplace_back(state.x[m].row(overlap.vertex).transpose());
      const Eigen::MatrixX3i& F = *faces[static_cast<std::size_t>(overlap.other)];
      state.couplings.push_back({static_cast<int>(m), overlap.vertex, overlap.other,
                                 F.row(overlap.face).transpose(), overlap.barycentric});
      dirty[m] = 1;
      dirty[static_cast<std::size_t>(overlap.other)] = 1;
      any = true;
    }
  }
  return any;
}

// The rows of `group` within `radius` of a seed (a point where a coupling or
// a pin was added); empty (all rows) when that is most of them.
std::vector<char> rows_near(const Group& group, const JointState& state,
                            const std::vector<Eigen::Vector3d>& seeds, double radius) {
  // Seeds hashed on a grid of cells `radius` wide: a row looks in the 27
  // cells around its own.
  const auto cell = [radius](const Eigen::Vector3d& p) {
    return Eigen::Vector3i((p / radius).array().floor().cast<int>());
  };
  const auto key = [](const Eigen::Vector3i& c) {
    constexpr std::int64_t kSpan = 1 << 20;
    return ((static_cast<std::int64_t>(c.x()) + kSpan / 2) * kSpan +
            (static_cast<std::int64_t>(c.y()) + kSpan / 2)) *
               kSpan +
           (static_cast<std::int64_t>(c.z()) + kSpan / 2);
  };
  std::unordered_map<std::int64_t, std::vector<Eigen::Vector3d>> grid;
  for (const Eigen::Vector3d& seed : seeds) grid[key(cell(seed))].push_back(seed);
  std::vector<char> free(static_cast<std::size_t>(group.rows), 0);
  Eigen::Index count = 0;
  for (std::size_t k = 0; k < group.bodies.size(); ++k) {
    const MatrixX3d& x = state.x[static_cast<std::size_t>(group.bodies[k])];
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      const Eigen::Vector3d p = x.row(v).transpose();
      const Eigen::Vector3i c = cell(p);
      bool near = false;
      for (int dx = -1; dx <= 1 && !near; ++dx) {
        for (int dy = -1; dy <= 1 && !near; ++dy) {
          for (int dz = -1; dz <= 1 && !near; ++dz) {
            const auto found = grid.find(key(c + Eigen::Vector3i(dx, dy, dz)));
            if (found == grid.end()) continue;
            for (const Eigen::Vector3d& seed : found->second) {
              if ((seed - p).squaredNorm() <= radius * radius) {
                near = true;
                break;
              }
            }
          }
        }
      }
      if (near) {
        free[static_cast<std::size_t>(group.offsets[k] + v)] = 1;
        ++count;
      }
    }
  }
  if (2 * count > group.rows) return {};
  return free;
}

}  // namespace

JointResult solve_jointly(const std::vector<JointBody>& bodies, const JointOptions& options) {
  check(bodies, options);
  JointState state;
  state.volume_iterations.assign(bodies.size(), 0);
  state.volume_ok.assign(bodies.size(), 1);
  for (const JointBody& body : bodies) {
    state.x.push_back(body.start);
    state.pins.push_back(body.contacts);
    std::vector<char> taken(static_cast<std::size_t>(body.start.rows()), 0);
    for (const Contact& pin : body.contacts) taken[static_cast<std::size_t>(pin.vertex)] = 1;
    state.taken.push_back(std::move(taken));
  }
  JointResult result;
  std::vector<char> dirty(bodies.size(), 0);
  std::vector<char> moved(bodies.size(), 0);
  std::vector<Eigen::Vector3d> seeds;
  bool pending = find_new(bodies, options, state, dirty, seeds);
  while (pending) {
    if (result.rounds >= options.max_rounds) {
      // What the last search found is left unsolved: those bodies did not
      // converge.
      result.converged = false;
      break;
    }
    const std::vector<Group> groups = dirty_groups(bodies, state.couplings, dirty);
    std::vector<int> group_of(bodies.size(), -1);
    for (std::size_t g = 0; g < groups.size(); ++g) {
      for (const int m : groups[g].bodies) {
        group_of[static_cast<std::size_t>(m)] = static_cast<int>(g);
        moved[static_cast<std::size_t>(m)] = 1;
      }
      result.largest_group =
          std::max(result.largest_group, static_cast<int>(groups[g].bodies.size()));
    }
    std::vector<std::vector<const Coupling*>> group_couplings(groups.size());
    for (const Coupling& coupling : state.couplings) {
      const int g = group_of[static_cast<std::size_t>(coupling.body)];
      if (g >= 0) group_couplings[static_cast<std::size_t>(g)].push_back(&coupling);
    }
    // After the first solve, only near what the last round added.
    const bool local = result.rounds > 0 && options.local_radius_mm > 0.0;
    parallel_for(groups.size(), options.threads, [&](std::size_t g) {
      const std::vector<char> free =
          local ? rows_near(groups[g], state, seeds, options.local_radius_mm) : std::vector<char>{};
      solve_group(bodies, groups[g], group_couplings[g], options.coupling.weight, free, state);
    });
    ++result.rounds;
    pending = find_new(bodies, options, state, dirty, seeds);
  }
  result.couplings.assign(bodies.size(), 0);
  for (const Coupling& coupling : state.couplings)
    ++result.couplings[static_cast<std::size_t>(coupling.body)];
  for (std::size_t m = 0; m < bodies.size(); ++m) {
    const VolumeDeformer& deformer = *bodies[m].deformer;
    DeformResult body;
    body.volume = enclosed_volume(state.x[m], deformer.rest().F);
    body.volume_error = (body.volume - deformer.rest_volume()) / deformer.rest_volume();
    body.volume_iterations = state.volume_iterations[m];
    body.contact_rounds = moved[m] != 0 ? result.rounds : 0;
    body.converged = state.volume_ok[m] != 0 && !(pending && dirty[m] != 0);
    body.contacts = std::move(state.pins[m]);
    body.x = std::move(state.x[m]);
    result.converged = result.converged && state.volume_ok[m] != 0;
    result.bodies.push_back(std::move(body));
  }
  return result;
}

}  // namespace mmm::wrapping
