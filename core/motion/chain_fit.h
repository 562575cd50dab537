#pragma once
// Inverse kinematics of one frame: the coordinates q that bring the model's
// markers closest to the measured ones, as a Ceres problem,
//
//   min_q  sum_i w_i |x_i(q) - m_i|^2                 markers (mm)
//        + sum_c w_c s_c^2 (q_c - v_c)^2               coordinate tasks
//        + |L (q - q_prior)|^2                         temporal prior (optional)
//   s.t.   lower_c <= q_c <= upper_c                   clamped coordinates (joint limits)
//          q_c = default_c                             locked coordinates
//
// with OpenSim's weights (s_c = 1000 per rad, 1 per mm, so a coordinate
// weight means what it means in OpenSim, where marker errors are in m). The
// Jacobian is the skeleton's exact one; Levenberg-Marquardt starts from the
// given q (the previous frame's answer), so a frame usually takes 2-5
// iterations. Missing markers (NaN) simply drop out: their segment keeps
// whatever the other markers, the joint chain and the prior say.
//
// One ChainFitter holds one Ceres problem for a whole trial; fit() only
// swaps the frame's data, so nothing is allocated per frame.

#include <Eigen/Core>
#include <memory>

#include "core/motion/skeleton.h"
#include "core/motion/tracking_setup.h"

namespace mmm::motion {

struct ChainFitOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-12;   // relative decrease of the cost
  double parameter_tolerance = 1e-10;  // relative step
  double gradient_tolerance = 1e-12;
  bool respect_limits = true;  // clamped coordinates' ranges as bounds
};

// A Gaussian prior on q in the cost's units (mm^2): |L (q - mean)|^2.
struct ChainPrior {
  Eigen::VectorXd mean;
  Eigen::MatrixXd sqrt_information;  // L, #coordinates square
};

struct ChainFitResult {
  Eigen::VectorXd q;
  Eigen::VectorXd marker_errors;  // #bound markers, mm; NaN when missing in the frame
  double rms_mm = 0.0;            // unweighted RMS over the markers present
  double max_mm = 0.0;
  int markers_used = 0;
  int iterations = 0;
  bool converged = true;
  // J^T W J of the marker and coordinate tasks at q (the measurement's
  // information about q, in the cost's units): what a Kalman update adds.
  Eigen::MatrixXd information;
};

class ChainFitter {
 public:
  ChainFitter(const Skeleton& skeleton, TrackingSetup setup, ChainFitOptions options = {});
  ~ChainFitter();
  ChainFitter(const ChainFitter&) = delete;
  ChainFitter& operator=(const ChainFitter&) = delete;

  // targets  #setup.markers by 3 measured positions (mm), row i for
  //          setup().markers[i]; a row with a NaN is a missing marker
  // start    #coordinates, where the search begins (clamped into the limits;
  //          locked coordinates take their default)
  // prior    optional temporal prior
  // Throws InvalidInputError for wrong sizes or a non-finite start, and
  // SolverError when Ceres fails (its report in the message).
  ChainFitResult fit(const Eigen::MatrixX3d& targets, const Eigen::VectorXd& start,
                     const ChainPrior* prior = nullptr);

  // Marker errors and information at q without solving (for smoothed q).
  ChainFitResult evaluate(const Eigen::MatrixX3d& targets, const Eigen::VectorXd& q);

  [[nodiscard]] const TrackingSetup& setup() const;
  [[nodiscard]] const Skeleton& skeleton() const;

  struct Impl;  // the Ceres problem and the frame's data (chain_fit.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmm::motion
