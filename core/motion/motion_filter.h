#pragma once
// The Kalman-like filter that makes per-frame inverse kinematics a
// physically plausible motion (the role of Tak & Ko 2005's filter in the
// reference method), in its simplest sound form:
//
//   state      x = (q, qdot), 2 #coordinates
//   process    constant velocity with white acceleration noise of spectral
//              density sigma_a^2 per coordinate:
//                x_k = F x_k-1 + w,  F = [I dt I; 0 I],
//                Q = sigma_a^2 [dt^3/3 dt^2/2; dt^2/2 dt]
//   measure    the markers (and coordinate tasks) through the skeleton,
//              each with noise sigma_m / sqrt(weight) mm
//   update     iterated extended Kalman: the chain fit with the predicted
//              q as a Gaussian prior (its marginal information scaled into
//              the fit's mm^2 units) is the MAP estimate; the posterior
//              information adds J^T W J / sigma_m^2 at the solution
//   smoother   optionally, a Rauch-Tung-Striebel pass backwards over the
//              whole trial (offline data: no lag)
//
// Missing markers lower the measurement information of their segment; the
// prior then carries it through the gap instead of failing the frame.
// Joint limits are applied by the fit (bounds) and again after smoothing.

#include <Eigen/Core>
#include <vector>

#include "core/motion/chain_fit.h"
#include "core/motion/skeleton.h"

namespace mmm::motion {

enum class FilterMode { kNone, kForward, kSmoother };

struct MotionFilterOptions {
  FilterMode mode = FilterMode::kSmoother;
  // sigma_a, rad/s^2 per sqrt(Hz). Walking (subject01_walk1 against
  // OpenSim's unfiltered IK, bench/run motion): 30 moves no leg angle by
  // more than 0.05 degree RMS while halving synthetic 3 mm marker noise.
  double angular_acceleration_sd = 30.0;
  double linear_acceleration_sd = 3000.0;    // sigma_a, mm/s^2 per sqrt(Hz)
  double marker_noise_mm = 5.0;              // sigma_m of a weight-1 marker
  double initial_angle_sd = 1.0;             // rad, before the first frame
  double initial_length_sd = 1000.0;         // mm
  double initial_angular_velocity_sd = 10;   // rad/s
  double initial_linear_velocity_sd = 5000;  // mm/s
};

class MotionFilter {
 public:
  MotionFilter(const Skeleton& skeleton, MotionFilterOptions options);

  // The prior for the next frame, dt seconds after the last update (or the
  // broad initial prior around `start` before the first update).
  ChainPrior predict(double dt, const Eigen::VectorXd& start);
  // Folds in the fit of the predicted frame.
  void update(const ChainFitResult& fit);
  // RTS smoothing over every frame updated so far: the smoothed q per
  // frame (#frames by #coordinates), clamped to the clamped ranges.
  [[nodiscard]] Eigen::MatrixXd smoothed() const;
  [[nodiscard]] Eigen::MatrixXd filtered() const;

 private:
  const Skeleton* skeleton_;
  MotionFilterOptions options_;
  int n_;
  bool started_ = false;
  Eigen::VectorXd x_;  // after the last update
  Eigen::MatrixXd p_;
  Eigen::VectorXd x_predicted_;
  Eigen::MatrixXd p_predicted_;
  Eigen::MatrixXd f_;
  // Per frame, for the smoother.
  std::vector<Eigen::VectorXd> filtered_x_, predicted_x_;
  std::vector<Eigen::MatrixXd> filtered_p_, predicted_p_, transitions_;
};

}  // namespace mmm::motion
