#include "core/motion/motion_filter.h"

#include <Eigen/Dense>
#include <algorithm>

#include "core/errors.h"

namespace mmm::motion {

MotionFilter::MotionFilter(const Skeleton& skeleton, MotionFilterOptions options)
    : skeleton_(&skeleton), options_(options), n_(skeleton.num_coordinates()) {
  if (!(options.marker_noise_mm > 0) || !(options.angular_acceleration_sd > 0) ||
      !(options.linear_acceleration_sd > 0)) {
    throw InvalidInputError(
        "motion filter: marker noise and acceleration noise must be positive numbers");
  }
}

ChainPrior MotionFilter::predict(double dt, const Eigen::VectorXd& start) {
  const int m = 2 * n_;
  if (!started_) {
    x_predicted_ = Eigen::VectorXd::Zero(m);
    x_predicted_.head(n_) = start;
    p_predicted_ = Eigen::MatrixXd::Zero(m, m);
    for (int c = 0; c < n_; ++c) {
      const bool angle =
          skeleton_->coordinates[static_cast<std::size_t>(c)].unit == CoordinateUnit::kAngle;
      const double sd = angle ? options_.initial_angle_sd : options_.initial_length_sd;
      const double vsd =
          angle ? options_.initial_angular_velocity_sd : options_.initial_linear_velocity_sd;
      p_predicted_(c, c) = sd * sd;
      p_predicted_(n_ + c, n_ + c) = vsd * vsd;
    }
    f_ = Eigen::MatrixXd::Identity(m, m);
  } else {
    if (!(dt > 0)) throw InvalidInputError("motion filter: frame times must increase");
    f_ = Eigen::MatrixXd::Identity(m, m);
    f_.topRightCorner(n_, n_) = dt * Eigen::MatrixXd::Identity(n_, n_);
    Eigen::MatrixXd q = Eigen::MatrixXd::Zero(m, m);
    for (int c = 0; c < n_; ++c) {
      const bool angle =
          skeleton_->coordinates[static_cast<std::size_t>(c)].unit == CoordinateUnit::kAngle;
      const double sd = angle ? options_.angular_acceleration_sd : options_.linear_acceleration_sd;
      const double s2 = sd * sd;
      q(c, c) = s2 * dt * dt * dt / 3.0;
      q(c, n_ + c) = q(n_ + c, c) = s2 * dt * dt / 2.0;
      q(n_ + c, n_ + c) = s2 * dt;
    }
    x_predicted_ = f_ * x_;
    p_predicted_ = f_ * p_ * f_.transpose() + q;
  }
  // The marginal prior on q, in the fit's units (cost = markers in mm^2
  // with weight; a weight-1 marker has variance sigma_m^2).
  const Eigen::MatrixXd information_q =
      p_predicted_.topLeftCorner(n_, n_).ldlt().solve(Eigen::MatrixXd::Identity(n_, n_));
  const double s2 = options_.marker_noise_mm * options_.marker_noise_mm;
  const Eigen::MatrixXd scaled = 0.5 * s2 * (information_q + information_q.transpose());
  ChainPrior prior;
  prior.mean = x_predicted_.head(n_);
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() == Eigen::Success) {
    prior.sqrt_information = llt.matrixU();
  } else {  // numerically semi-definite: eigen square root
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
    prior.sqrt_information = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() *
                             eigen.eigenvectors().transpose();
  }
  return prior;
}

void MotionFilter::update(const ChainFitResult& fit) {
  const int m = 2 * n_;
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(m, m);
  const Eigen::MatrixXd p_qq = p_predicted_.topLeftCorner(n_, n_);
  const Eigen::MatrixXd p_vq = p_predicted_.bottomLeftCorner(n_, n_);
  Eigen::VectorXd x = x_predicted_;
  x.head(n_) = fit.q;
  x.tail(n_) += p_vq * p_qq.ldlt().solve(fit.q - x_predicted_.head(n_));
  Eigen::MatrixXd information = p_predicted_.ldlt().solve(identity);
  const double s2 = options_.marker_noise_mm * options_.marker_noise_mm;
  information.topLeftCorner(n_, n_) += fit.information / s2;
  p_ = information.ldlt().solve(identity);
  p_ = 0.5 * (p_ + p_.transpose());
  x_ = x;
  started_ = true;
  filtered_x_.push_back(x_);
  filtered_p_.push_back(p_);
  predicted_x_.push_back(x_predicted_);
  predicted_p_.push_back(p_predicted_);
  transitions_.push_back(f_);
}

Eigen::MatrixXd MotionFilter::filtered() const {
  Eigen::MatrixXd q(static_cast<Eigen::Index>(filtered_x_.size()), n_);
  for (std::size_t k = 0; k < filtered_x_.size(); ++k) {
    q.row(static_cast<Eigen::Index>(k)) = filtered_x_[k].head(n_).transpose();
  }
  return q;
}

Eigen::MatrixXd MotionFilter::smoothed() const {
  const std::size_t frames = filtered_x_.size();
  Eigen::MatrixXd q(static_cast<Eigen::Index>(frames), n_);
  if (frames == 0) return q;
  Eigen::VectorXd next = filtered_x_.back();
  q.row(static_cast<Eigen::Index>(frames - 1)) = next.head(n_).transpose();
  for (std::size_t k = frames - 1; k-- > 0;) {
    const Eigen::MatrixXd& f = transitions_[k + 1];
    const Eigen::MatrixXd gain =
        predicted_p_[k + 1].ldlt().solve(f * filtered_p_[k]).transpose();  // P F^T Pp^-1
    next = filtered_x_[k] + gain * (next - predicted_x_[k + 1]);
    q.row(static_cast<Eigen::Index>(k)) = next.head(n_).transpose();
  }
  for (int c = 0; c < n_; ++c) {
    const SkeletonCoordinate& coordinate = skeleton_->coordinates[static_cast<std::size_t>(c)];
    if (coordinate.locked) {
      q.col(c).setConstant(coordinate.default_value);
    } else if (coordinate.clamped && coordinate.lower < coordinate.upper) {
      q.col(c) = q.col(c).cwiseMax(coordinate.lower).cwiseMin(coordinate.upper);
    }
  }
  return q;
}

}  // namespace mmm::motion
