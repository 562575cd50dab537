#pragma once
// t-polynomials (Audenaert et al. 2010, the second reference document): a
// measured fibre path, or the centreline of a tube with its radius, as one
// polynomial per coordinate of a single parameter t in [0, 1],
//
//   x(t) = a0 + a1 t + ... + an t^n   (likewise y, z and, for tubes, r),
//
// where t grows in proportion to arc length along the measured polyline (0
// at its first point, the origin; 1 at its last, the insertion), fitted by
// least squares (their equation (2)). The fit is judged by the mean
// resultant error (their equation (3)): the mean distance between each
// measured point and the polynomial at that point's t. A fibre of N points
// becomes an (n + 1) by 3 matrix; equidistant points are t = k / (m - 1).

#include <Eigen/Core>

namespace mmm::fibres {

// t of each point of a polyline (N by D, the first three columns x y z in
// mm; others such as a radius do not count): its chord length from the first
// point divided by the total, so t_0 = 0 and t_N-1 = 1. Throws
// InvalidInputError for fewer than two points, fewer than three columns,
// non-finite values or a polyline of zero length.
Eigen::VectorXd arc_length_parameters(const Eigen::MatrixXd& points);

class TPolynomial {
 public:
  TPolynomial() = default;
  // coefficients: (n + 1) by D, row k the coefficients of t^k. Throws
  // InvalidInputError when empty or not finite.
  explicit TPolynomial(Eigen::MatrixXd coefficients);

  [[nodiscard]] int degree() const { return static_cast<int>(coefficients_.rows()) - 1; }
  [[nodiscard]] int dimensions() const { return static_cast<int>(coefficients_.cols()); }
  [[nodiscard]] const Eigen::MatrixXd& coefficients() const { return coefficients_; }

  // The point (D values) at t, by Horner's rule; t outside [0, 1] extrapolates.
  [[nodiscard]] Eigen::VectorXd at(double t) const;
  // At every t: #t by D.
  [[nodiscard]] Eigen::MatrixXd at(const Eigen::VectorXd& t) const;
  // `count` >= 2 points at equidistant t from 0 to 1.
  [[nodiscard]] Eigen::MatrixXd sample(int count) const;

 private:
  Eigen::MatrixXd coefficients_;
};

struct TPolynomialFit {
  TPolynomial polynomial;
  Eigen::VectorXd t;                // of each measured point
  double mean_resultant_error = 0;  // equation (3), over x y z (mm)
  double max_resultant_error = 0;   // the largest of those distances (mm)
  double mean_radius_error = 0;     // tubes (4 columns): mean |r(t) - r| (mm); else 0
};

constexpr int kMaxTPolynomialDegree = 12;

// Least-squares fit of degree `degree` (0..kMaxTPolynomialDegree) to the
// points (N by 3 for a path, N by 4 with a radius for a tube), t from
// arc_length_parameters. Throws InvalidInputError for a degree out of range,
// fewer points than coefficients, or invalid points (as above).
TPolynomialFit fit_t_polynomial(const Eigen::MatrixXd& points, int degree);

// The same with given t (one per point, finite); fewer distinct values of t
// than coefficients is an error.
TPolynomialFit fit_t_polynomial(const Eigen::VectorXd& t, const Eigen::MatrixXd& points,
                                int degree);

// Equation (3): mean distance (x y z) between the points and the polynomial
// at their t.
double mean_resultant_error(const TPolynomial& polynomial, const Eigen::VectorXd& t,
                            const Eigen::MatrixXd& points);

}  // namespace mmm::fibres
