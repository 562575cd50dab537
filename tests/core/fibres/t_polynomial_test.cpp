// t-polynomials on known curves: a polynomial sampled at known t is recovered
// exactly, a straight path of uneven steps gets t in proportion to its
// length and a degree-1 fit through its ends, a helix is approximated better
// with every degree, a tube's linear radius is exact, and bad input is
// refused naming what is wrong.

#include "core/fibres/t_polynomial.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

TEST(TPolynomialTest, APolynomialSampledAtKnownTIsRecoveredExactly) {
  MatrixXd coefficients(4, 3);
  coefficients << 10, -5, 2,  //
      30, 4, -1,              //
      -12, 7, 8,              //
      5, -3, 0.5;
  const TPolynomial truth(coefficients);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  VectorXd t(30);
  for (Eigen::Index i = 0; i < t.size(); ++i) t[i] = uniform(random);
  const TPolynomialFit fit = fit_t_polynomial(t, truth.at(t), 3);
  EXPECT_EQ(fit.polynomial.degree(), 3);
  EXPECT_LT((fit.polynomial.coefficients() - coefficients).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(fit.mean_resultant_error, 1e-10);
  EXPECT_LT(fit.max_resultant_error, 1e-10);
  // Horner against the powers written out.
  const double s = 0.37;
  const Eigen::Vector3d by_hand =
      coefficients.row(0).transpose() + coefficients.row(1).transpose() * s +
      coefficients.row(2).transpose() * s * s + coefficients.row(3).transpose() * s * s * s;
  EXPECT_LT((truth.at(s) - by_hand).norm(), 1e-12);
  // A higher degree fits the same points as well (its top coefficient ~0).
  const TPolynomialFit higher = fit_t_polynomial(t, truth.at(t), 5);
  EXPECT_LT(higher.mean_resultant_error, 1e-8);
  EXPECT_LT(higher.polynomial.coefficients().row(5).norm(), 1e-5);
}

TEST(TPolynomialTest, AStraightPathOfUnevenStepsGetsTByLengthAndAnExactLine) {
  const Eigen::Vector3d origin(1, 2, 3);
  const Eigen::Vector3d insertion(41, -28, 3);  // 50 mm away
  const VectorXd fractions = (VectorXd(5) << 0.0, 0.1, 0.15, 0.7, 1.0).finished();
  MatrixXd points(5, 3);
  for (Eigen::Index i = 0; i < 5; ++i)
    points.row(i) = (origin + fractions[i] * (insertion - origin)).transpose();
  const VectorXd t = arc_length_parameters(points);
  EXPECT_LT((t - fractions).cwiseAbs().maxCoeff(), 1e-12);
  const TPolynomialFit fit = fit_t_polynomial(points, 1);
  EXPECT_LT(fit.mean_resultant_error, 1e-12);
  EXPECT_LT((fit.polynomial.at(0.0) - origin).norm(), 1e-12);
  EXPECT_LT((fit.polynomial.at(1.0) - insertion).norm(), 1e-12);
  const MatrixXd equidistant = fit.polynomial.sample(6);
  EXPECT_LT((equidistant.row(1).transpose() - (origin + 0.2 * (insertion - origin))).norm(), 1e-12);
}

TEST(TPolynomialTest, AHelixIsApproximatedBetterWithEveryDegree) {
  // Three quarters of a turn, radius 20 mm, rising 30 mm: not a polynomial.
  const int n = 200;
  MatrixXd points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double angle = 1.5 * std::numbers::pi * i / (n - 1);
    points.row(i) << 20 * std::cos(angle), 20 * std::sin(angle), 30.0 * i / (n - 1);
  }
  double previous = std::numeric_limits<double>::infinity();
  for (int degree = 1; degree <= 8; ++degree) {
    const double error = fit_t_polynomial(points, degree).mean_resultant_error;
    EXPECT_LT(error, previous) << "degree " << degree;
    previous = error;
  }
  EXPECT_GT(fit_t_polynomial(points, 1).mean_resultant_error, 2.0);   // a chord misses by mm
  EXPECT_LT(fit_t_polynomial(points, 6).mean_resultant_error, 0.02);  // of a 99 mm path
  // Equation (3) recomputed from the polynomial gives the fit's figure.
  const TPolynomialFit fit = fit_t_polynomial(points, 4);
  EXPECT_NEAR(mean_resultant_error(fit.polynomial, fit.t, points), fit.mean_resultant_error, 1e-12);
}

TEST(TPolynomialTest, ATubesLinearRadiusIsFittedExactly) {
  const int n = 50;
  MatrixXd tube(n, 4);
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    tube.row(i) << 100 * s, 10 * s * s, -5 * s, 4.0 - 2.5 * s;  // a tapering nerve
  }
  const TPolynomialFit fit = fit_t_polynomial(tube, 5);
  EXPECT_EQ(fit.polynomial.dimensions(), 4);
  EXPECT_LT(fit.mean_radius_error, 1e-3);
  EXPECT_NEAR(fit.polynomial.at(0.0)[3], 4.0, 1e-3);
  EXPECT_NEAR(fit.polynomial.at(1.0)[3], 1.5, 1e-3);
  EXPECT_LT(fit.mean_resultant_error, 1e-3);
}

TEST(TPolynomialTest, BadInputIsRefusedNamingWhatIsWrong) {
  MatrixXd points = MatrixXd::Random(10, 3);
  const auto message = [](const auto& call) {
    try {
      call();
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { (void)fit_t_polynomial(points, -1); }).find("degree -1"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)fit_t_polynomial(points, 13); }).find("out of range"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)fit_t_polynomial(points.topRows(3), 3); }).find("needs 4"),
            std::string::npos);
  MatrixXd with_nan = points;
  with_nan(6, 1) = std::nan("");
  EXPECT_NE(message([&] { (void)fit_t_polynomial(with_nan, 3); }).find("point 6"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)fit_t_polynomial(MatrixXd::Ones(5, 3), 1); }).find("zero length"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)fit_t_polynomial(MatrixXd::Random(5, 2), 1); }).find("columns"),
            std::string::npos);
  EXPECT_NE(message([&] {
              (void)fit_t_polynomial(VectorXd::Zero(5), points.topRows(5), 1);
            }).find("distinct t"),
            std::string::npos);
  EXPECT_THROW(TPolynomial{MatrixXd()}, InvalidInputError);
  EXPECT_THROW((void)TPolynomial(MatrixXd::Ones(2, 3)).sample(1), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres
