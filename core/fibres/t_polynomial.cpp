#include "core/fibres/t_polynomial.h"

#include <Eigen/QR>
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

void check_polynomial_points(const Eigen::MatrixXd& points, const std::string& what) {
  if (points.cols() < 3) {
    throw InvalidInputError(what + ": points need x y z columns (3, or 4 with a radius), got " +
                            std::to_string(points.cols()));
  }
  if (!points.allFinite()) {
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      if (!points.row(i).allFinite()) {
        throw InvalidInputError(what + ": point " + std::to_string(i) +
                                " is not finite (NaN or infinite)");
      }
    }
  }
}

// Rows of the design matrix of equation (2): 1, t, t^2, ... t^n.
Eigen::MatrixXd vandermonde(const Eigen::VectorXd& t, int degree) {
  Eigen::MatrixXd design(t.size(), degree + 1);
  design.col(0).setOnes();
  for (int k = 1; k <= degree; ++k) design.col(k) = design.col(k - 1).cwiseProduct(t);
  return design;
}

}  // namespace

Eigen::VectorXd arc_length_parameters(const Eigen::MatrixXd& points) {
  check_polynomial_points(points, "t-polynomial");
  if (points.rows() < 2) throw InvalidInputError("t-polynomial: a path needs at least two points");
  Eigen::VectorXd t(points.rows());
  t[0] = 0.0;
  for (Eigen::Index i = 1; i < points.rows(); ++i)
    t[i] = t[i - 1] + (points.row(i).head<3>() - points.row(i - 1).head<3>()).norm();
  const double length = t[t.size() - 1];
  if (!(length > 0.0)) {
    throw InvalidInputError(
        "t-polynomial: the path has zero length (all points equal); hint: a fibre needs distinct "
        "points from origin to insertion");
  }
  return t / length;
}

TPolynomial::TPolynomial(Eigen::MatrixXd coefficients) : coefficients_(std::move(coefficients)) {
  if (coefficients_.size() == 0 || !coefficients_.allFinite())
    throw InvalidInputError("t-polynomial: coefficients must be non-empty and finite");
}

Eigen::VectorXd TPolynomial::at(double t) const {
  Eigen::VectorXd value = coefficients_.row(coefficients_.rows() - 1).transpose();
  for (Eigen::Index k = coefficients_.rows() - 2; k >= 0; --k)
    value = value * t + coefficients_.row(k).transpose();
  return value;
}

Eigen::MatrixXd TPolynomial::at(const Eigen::VectorXd& t) const {
  Eigen::MatrixXd values(t.size(), coefficients_.cols());
  for (Eigen::Index i = 0; i < t.size(); ++i) values.row(i) = at(t[i]).transpose();
  return values;
}

Eigen::MatrixXd TPolynomial::sample(int count) const {
  if (count < 2) throw InvalidInputError("t-polynomial: sample at least two points");
  return at(Eigen::VectorXd::LinSpaced(count, 0.0, 1.0));
}

double mean_resultant_error(const TPolynomial& polynomial, const Eigen::VectorXd& t,
                            const Eigen::MatrixXd& points) {
  if (t.size() != points.rows() || polynomial.dimensions() != points.cols()) {
    throw InvalidInputError("t-polynomial: " + std::to_string(t.size()) + " values of t for " +
                            std::to_string(points.rows()) + " points of " +
                            std::to_string(points.cols()) + " columns (polynomial has " +
                            std::to_string(polynomial.dimensions()) + ")");
  }
  if (t.size() == 0) return 0.0;
  const Eigen::MatrixXd predicted = polynomial.at(t);
  return (predicted.leftCols<3>() - points.leftCols<3>()).rowwise().norm().mean();
}

TPolynomialFit fit_t_polynomial(const Eigen::MatrixXd& points, int degree) {
  return fit_t_polynomial(arc_length_parameters(points), points, degree);
}

TPolynomialFit fit_t_polynomial(const Eigen::VectorXd& t, const Eigen::MatrixXd& points,
                                int degree) {
  if (degree < 0 || degree > kMaxTPolynomialDegree) {
    throw InvalidInputError("t-polynomial: degree " + std::to_string(degree) +
                            " is out of range 0.." + std::to_string(kMaxTPolynomialDegree) +
                            "; hint: 3 or 4 suffice for muscle fibres (the reference document)");
  }
  check_polynomial_points(points, "t-polynomial");
  if (t.size() != points.rows()) {
    throw InvalidInputError("t-polynomial: " + std::to_string(t.size()) + " values of t for " +
                            std::to_string(points.rows()) + " points");
  }
  if (!t.allFinite()) throw InvalidInputError("t-polynomial: t is not finite");
  std::vector<double> distinct(t.data(), t.data() + t.size());
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  if (static_cast<int>(distinct.size()) < degree + 1) {
    throw InvalidInputError("t-polynomial: degree " + std::to_string(degree) + " needs " +
                            std::to_string(degree + 1) + " points at distinct t, got " +
                            std::to_string(distinct.size()));
  }
  const Eigen::MatrixXd design = vandermonde(t, degree);
  TPolynomialFit fit;
  fit.polynomial = TPolynomial(design.colPivHouseholderQr().solve(points));
  fit.t = t;
  const Eigen::MatrixXd predicted = fit.polynomial.at(t);
  const Eigen::VectorXd distances =
      (predicted.leftCols<3>() - points.leftCols<3>()).rowwise().norm();
  fit.mean_resultant_error = distances.mean();
  fit.max_resultant_error = distances.maxCoeff();
  if (points.cols() >= 4)
    fit.mean_radius_error = (predicted.col(3) - points.col(3)).cwiseAbs().mean();
  return fit;
}

}  // namespace mmm::fibres
