#include "core/motion/chain_fit.h"

#include <ceres/ceres.h>

#include <cmath>

#include "core/errors.h"

namespace mmm::motion {
namespace {

// A coordinate task's residual per unit of coordinate: OpenSim measures
// marker errors in m and angles in rad; our markers are in mm.
constexpr double kAngleTaskScale = 1000.0;
constexpr double kLengthTaskScale = 1.0;

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

struct ChainFitter::Impl {
  Impl(const Skeleton& s, TrackingSetup t, ChainFitOptions o)
      : skeleton(&s), setup(std::move(t)), options(o), pose(s) {}

  [[nodiscard]] int num_residuals() const {
    return 3 * static_cast<int>(setup.markers.size()) + static_cast<int>(setup.coordinates.size());
  }

  // Weighted residuals r (#num_residuals) and, when jacobian != nullptr, dr/dq.
  void residuals(const Eigen::VectorXd& at, Eigen::Ref<Eigen::VectorXd> r,
                 Eigen::MatrixXd* jacobian) {
    pose.set(at);
    if (jacobian != nullptr) jacobian->setZero(num_residuals(), skeleton->num_coordinates());
    Eigen::Index row = 0;
    for (std::size_t i = 0; i < setup.markers.size(); ++i, row += 3) {
      const BoundMarker& bound = setup.markers[i];
      const Eigen::Vector3d target = targets.row(static_cast<Eigen::Index>(i)).transpose();
      if (!target.allFinite()) {
        r.segment<3>(row).setZero();
        continue;
      }
      const double w = std::sqrt(bound.weight);
      const Eigen::Vector3d x = pose.marker(bound.model);
      r.segment<3>(row) = w * (x - target);
      if (jacobian != nullptr) {
        const int body = skeleton->markers[static_cast<std::size_t>(bound.model)].body;
        pose.add_point_jacobian(body, x, w, *jacobian, row);
      }
    }
    for (const BoundCoordinateTask& task : setup.coordinates) {
      const double scale = std::sqrt(task.weight) *
                           (skeleton->coordinates[static_cast<std::size_t>(task.coordinate)].unit ==
                                    CoordinateUnit::kAngle
                                ? kAngleTaskScale
                                : kLengthTaskScale);
      r(row) = scale * (at(task.coordinate) - task.value);
      if (jacobian != nullptr) (*jacobian)(row, task.coordinate) = scale;
      ++row;
    }
  }

  ChainFitResult result_at(const Eigen::VectorXd& at) {
    ChainFitResult result;
    result.q = at;
    Eigen::VectorXd r(num_residuals());
    Eigen::MatrixXd jacobian;
    residuals(at, r, &jacobian);
    result.information = jacobian.transpose() * jacobian;
    result.marker_errors.resize(static_cast<Eigen::Index>(setup.markers.size()));
    double squares = 0.0;
    for (std::size_t i = 0; i < setup.markers.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(i);
      if (!targets.row(row).allFinite()) {
        result.marker_errors(row) = std::nan("");
        continue;
      }
      const double error = r.segment<3>(3 * row).norm() / std::sqrt(setup.markers[i].weight);
      result.marker_errors(row) = error;
      squares += error * error;
      result.max_mm = std::max(result.max_mm, error);
      ++result.markers_used;
    }
    result.rms_mm = result.markers_used > 0 ? std::sqrt(squares / result.markers_used) : 0.0;
    return result;
  }

  const Skeleton* skeleton;
  TrackingSetup setup;
  ChainFitOptions options;
  SkeletonPose pose;
  Eigen::MatrixX3d targets;
  Eigen::VectorXd q;  // the parameter block
  Eigen::VectorXd prior_mean;
  Eigen::MatrixXd prior_root;  // zero when there is no prior
  Eigen::MatrixXd jacobian_buffer;
  std::unique_ptr<ceres::Problem> problem;
};

namespace {

class TrackingCost final : public ceres::CostFunction {
 public:
  explicit TrackingCost(ChainFitter::Impl* impl) : impl_(impl) {
    set_num_residuals(impl->num_residuals());
    mutable_parameter_block_sizes()->push_back(impl->skeleton->num_coordinates());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = impl_->skeleton->num_coordinates();
    const Eigen::VectorXd at = Eigen::Map<const Eigen::VectorXd>(parameters[0], n);
    Eigen::Map<Eigen::VectorXd> r(residuals, num_residuals());
    const bool want = jacobians != nullptr && jacobians[0] != nullptr;
    impl_->residuals(at, r, want ? &impl_->jacobian_buffer : nullptr);
    if (want) {
      Eigen::Map<RowMajorMatrix>(jacobians[0], num_residuals(), n) = impl_->jacobian_buffer;
    }
    return true;
  }

 private:
  ChainFitter::Impl* impl_;
};

class PriorCost final : public ceres::CostFunction {
 public:
  explicit PriorCost(ChainFitter::Impl* impl) : impl_(impl) {
    const int n = impl->skeleton->num_coordinates();
    set_num_residuals(n);
    mutable_parameter_block_sizes()->push_back(n);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = impl_->skeleton->num_coordinates();
    const Eigen::Map<const Eigen::VectorXd> at(parameters[0], n);
    Eigen::Map<Eigen::VectorXd>(residuals, n) = impl_->prior_root * (at - impl_->prior_mean);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<RowMajorMatrix>(jacobians[0], n, n) = impl_->prior_root;
    }
    return true;
  }

 private:
  ChainFitter::Impl* impl_;
};

}  // namespace

ChainFitter::ChainFitter(const Skeleton& skeleton, TrackingSetup setup, ChainFitOptions options)
    : impl_(std::make_unique<Impl>(skeleton, std::move(setup), options)) {
  Impl& s = *impl_;
  const int n = skeleton.num_coordinates();
  if (n == 0) throw InvalidInputError("skeleton '" + skeleton.name + "' has no coordinates");
  s.q = skeleton.default_coordinates();
  s.prior_mean = Eigen::VectorXd::Zero(n);
  s.prior_root = Eigen::MatrixXd::Zero(n, n);
  s.targets = Eigen::MatrixX3d::Constant(static_cast<Eigen::Index>(s.setup.markers.size()), 3,
                                         std::nan(""));
  s.problem = std::make_unique<ceres::Problem>();
  double* block = s.q.data();
  s.problem->AddResidualBlock(new TrackingCost(&s), nullptr, block);
  s.problem->AddResidualBlock(new PriorCost(&s), nullptr, block);
  std::vector<int> locked;
  for (int c = 0; c < n; ++c) {
    const SkeletonCoordinate& coordinate = skeleton.coordinates[static_cast<std::size_t>(c)];
    if (coordinate.locked) {
      locked.push_back(c);
    } else if (options.respect_limits && coordinate.clamped &&
               coordinate.lower < coordinate.upper) {
      s.problem->SetParameterLowerBound(block, c, coordinate.lower);
      s.problem->SetParameterUpperBound(block, c, coordinate.upper);
    }
  }
  if (static_cast<int>(locked.size()) == n) {
    s.problem->SetParameterBlockConstant(block);
  } else if (!locked.empty()) {
    s.problem->SetManifold(block, new ceres::SubsetManifold(n, locked));
  }
}

ChainFitter::~ChainFitter() = default;

const TrackingSetup& ChainFitter::setup() const { return impl_->setup; }
const Skeleton& ChainFitter::skeleton() const { return *impl_->skeleton; }

ChainFitResult ChainFitter::fit(const Eigen::MatrixX3d& targets, const Eigen::VectorXd& start,
                                const ChainPrior* prior) {
  Impl& s = *impl_;
  const Skeleton& skeleton = *s.skeleton;
  const int n = skeleton.num_coordinates();
  if (targets.rows() != static_cast<Eigen::Index>(s.setup.markers.size())) {
    throw InvalidInputError("chain fit: " + std::to_string(targets.rows()) +
                            " marker targets given, the setup tracks " +
                            std::to_string(s.setup.markers.size()));
  }
  if (start.size() != n || !start.allFinite()) {
    throw InvalidInputError("chain fit: the start needs " + std::to_string(n) +
                            " finite coordinate values");
  }
  s.targets = targets;
  for (int c = 0; c < n; ++c) {
    const SkeletonCoordinate& coordinate = skeleton.coordinates[static_cast<std::size_t>(c)];
    double value = coordinate.locked ? coordinate.default_value : start(c);
    if (!coordinate.locked && s.options.respect_limits && coordinate.clamped &&
        coordinate.lower < coordinate.upper) {
      value = std::clamp(value, coordinate.lower, coordinate.upper);
    }
    s.q(c) = value;
  }
  if (prior != nullptr) {
    if (prior->mean.size() != n || prior->sqrt_information.rows() != n ||
        prior->sqrt_information.cols() != n || !prior->mean.allFinite() ||
        !prior->sqrt_information.allFinite()) {
      throw InvalidInputError("chain fit: the prior needs a finite mean of " + std::to_string(n) +
                              " values and a finite " + std::to_string(n) + " by " +
                              std::to_string(n) + " square-root information");
    }
    s.prior_mean = prior->mean;
    s.prior_root = prior->sqrt_information;
  } else {
    s.prior_root.setZero();
  }
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = s.options.max_iterations;
  options.function_tolerance = s.options.function_tolerance;
  options.parameter_tolerance = s.options.parameter_tolerance;
  options.gradient_tolerance = s.options.gradient_tolerance;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, s.problem.get(), &summary);
  if (!summary.IsSolutionUsable() || !s.q.allFinite()) {
    throw SolverError("chain fit: " + summary.BriefReport());
  }
  const Eigen::VectorXd solution = s.q;
  ChainFitResult result = s.result_at(solution);
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  return result;
}

ChainFitResult ChainFitter::evaluate(const Eigen::MatrixX3d& targets, const Eigen::VectorXd& q) {
  Impl& s = *impl_;
  if (targets.rows() != static_cast<Eigen::Index>(s.setup.markers.size()) ||
      q.size() != s.skeleton->num_coordinates()) {
    throw InvalidInputError("chain fit: evaluate needs one target row per tracked marker and " +
                            std::to_string(s.skeleton->num_coordinates()) + " coordinates");
  }
  s.targets = targets;
  return s.result_at(q);
}

}  // namespace mmm::motion
