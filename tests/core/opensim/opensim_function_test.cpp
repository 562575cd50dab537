#include "core/opensim/opensim_function.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::opensim {
namespace {

// Values of order 1 computed through a few dozen flops: double round-off
// stays below 1e-12.
constexpr double kSplineRoundOff = 1e-12;

std::vector<double> sample_range(double lo, double hi, int count) {
  std::vector<double> xs;
  xs.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) xs.push_back(lo + (hi - lo) * i / (count - 1));
  return xs;
}

TEST(SimmSplineTest, ReproducesCubicFromUnevenPoints) {
  // The FMM end conditions match the third derivative of the cubic through
  // the end 4 points, so data on a cubic gives back that cubic exactly.
  const auto f = [](double x) { return 2.0 * x * x * x - x * x + 0.5 * x - 1.0; };
  const auto df = [](double x) { return 6.0 * x * x - 2.0 * x + 0.5; };
  const std::vector<double> x = {-1.0, -0.7, 0.1, 0.4, 1.2, 1.5, 2.0};
  std::vector<double> y;
  y.reserve(x.size());
  for (const double xi : x) y.push_back(f(xi));
  const SimmSpline spline(x, y);
  for (const double t : sample_range(-1.0, 2.0, 61)) {
    // |f| <= 16 on [-1, 2]: scale the round-off bound.
    EXPECT_NEAR(spline.evaluate(t), f(t), 16 * kSplineRoundOff) << "x = " << t;
    EXPECT_NEAR(spline.derivative(t), df(t), 1e-10) << "x = " << t;  // |f'| <= 21, solve noise
  }
}

TEST(SimmSplineTest, ReproducesQuadraticFromThreePoints) {
  // With 3 points both end rows force a zero third derivative: a parabola.
  const auto f = [](double x) { return 3.0 * x * x - 2.0 * x + 0.25; };
  const SimmSpline spline({0.0, 0.3, 1.0}, {f(0.0), f(0.3), f(1.0)});
  for (const double t : sample_range(0.0, 1.0, 21)) {
    EXPECT_NEAR(spline.evaluate(t), f(t), kSplineRoundOff) << "x = " << t;
    EXPECT_NEAR(spline.derivative(t), 6.0 * t - 2.0, 1e-11) << "x = " << t;  // slope ~ 4
  }
}

TEST(SimmSplineTest, LinearDataGivesStraightLine) {
  const std::vector<double> x = {-2.0, -1.5, 0.0, 0.1, 0.7, 3.0};
  std::vector<double> y;
  y.reserve(x.size());
  for (const double xi : x) y.push_back(0.5 * xi - 0.2);
  const SimmSpline spline(x, y);
  for (const double t : sample_range(-3.0, 4.0, 71)) {  // includes the extrapolated ends
    EXPECT_NEAR(spline.evaluate(t), 0.5 * t - 0.2, kSplineRoundOff) << "x = " << t;
    EXPECT_NEAR(spline.derivative(t), 0.5, kSplineRoundOff) << "x = " << t;
  }
}

TEST(SimmSplineTest, TwoPointsGiveTheLineThroughThem) {
  const SimmSpline spline({1.0, 3.0}, {2.0, 6.0});
  EXPECT_DOUBLE_EQ(spline.evaluate(2.0), 4.0);
  EXPECT_DOUBLE_EQ(spline.evaluate(5.0), 10.0);
  EXPECT_DOUBLE_EQ(spline.derivative(0.0), 2.0);
}

TEST(SimmSplineTest, PassesThroughEveryKnotExactly) {
  const std::vector<double> x = {-2.0944,   -1.22173, -0.523599, -0.349066,
                                 -0.174533, 0.159149, 2.0944};
  const std::vector<double> y = {-0.4226, -0.4082, -0.399, -0.3976, -0.3966, -0.395264, -0.396};
  const SimmSpline spline(x, y);
  for (std::size_t k = 0; k < x.size(); ++k) {
    // At a knot the local offset is exactly 0, so the stored ordinate comes back bit for bit.
    EXPECT_EQ(spline.evaluate(x[k]), y[k]) << "knot " << k;
  }
}

TEST(SimmSplineTest, IsTwiceContinuouslyDifferentiableAtKnots) {
  const std::vector<double> x = {0.0, 0.5, 1.3, 2.0, 2.2, 3.5};
  const std::vector<double> y = {1.0, -0.3, 0.8, 0.1, 0.4, 2.0};
  const SimmSpline spline(x, y);
  const double h = 1e-7;
  for (std::size_t k = 1; k + 1 < x.size(); ++k) {
    // Values differ by ~slope * h (~1e-6) across h; slopes by ~S'' * h.
    EXPECT_NEAR(spline.evaluate(x[k] - h), spline.evaluate(x[k] + h), 1e-5);
    EXPECT_NEAR(spline.derivative(x[k] - h), spline.derivative(x[k] + h), 1e-5);
    // Second derivative from one-sided differences of the slope: O(h) truncation.
    const double left = (spline.derivative(x[k] - h) - spline.derivative(x[k] - 2 * h)) / h;
    const double right = (spline.derivative(x[k] + 2 * h) - spline.derivative(x[k] + h)) / h;
    EXPECT_NEAR(left, right, 1e-3) << "knot " << k;
  }
}

TEST(SimmSplineTest, ExtrapolatesAlongTheEndTangents) {
  const SimmSpline spline({0.0, 1.0, 2.0, 4.0}, {0.0, 1.0, 0.0, 2.0});
  const double slope_lo = spline.derivative(0.0);
  const double slope_hi = spline.derivative(4.0);
  EXPECT_NEAR(spline.evaluate(-1.5), -1.5 * slope_lo, kSplineRoundOff);
  EXPECT_NEAR(spline.evaluate(6.0), 2.0 + 2.0 * slope_hi, kSplineRoundOff);
  EXPECT_EQ(spline.derivative(-1.5), slope_lo);
  EXPECT_EQ(spline.derivative(6.0), slope_hi);
}

// Independent formulation: unknown second derivatives M_i solved densely,
// end rows (M1 - M0) / h0 = 6 f[x0..x3] (and the mirror one), evaluated in
// the symmetric (a, b) form instead of the coefficient form.
double dense_reference(const std::vector<double>& x, const std::vector<double>& y, double t) {
  const auto n = static_cast<Eigen::Index>(x.size());
  const auto xi = [&](Eigen::Index i) { return x[static_cast<std::size_t>(i)]; };
  const auto yi = [&](Eigen::Index i) { return y[static_cast<std::size_t>(i)]; };
  const auto divided3 = [&](Eigen::Index i) {
    const auto d1 = [&](Eigen::Index j) { return (yi(j + 1) - yi(j)) / (xi(j + 1) - xi(j)); };
    const auto d2 = [&](Eigen::Index j) { return (d1(j + 1) - d1(j)) / (xi(j + 2) - xi(j)); };
    return (d2(i + 1) - d2(i)) / (xi(i + 3) - xi(i));
  };
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    const double h0 = xi(i) - xi(i - 1);
    const double h1 = xi(i + 1) - xi(i);
    a(i, i - 1) = h0;
    a(i, i) = 2.0 * (h0 + h1);
    a(i, i + 1) = h1;
    r(i) = 6.0 * ((yi(i + 1) - yi(i)) / h1 - (yi(i) - yi(i - 1)) / h0);
  }
  const double h_first = xi(1) - xi(0);
  const double h_last = xi(n - 1) - xi(n - 2);
  a(0, 0) = -1.0 / h_first;
  a(0, 1) = 1.0 / h_first;
  r(0) = 6.0 * divided3(0);
  a(n - 1, n - 2) = -1.0 / h_last;
  a(n - 1, n - 1) = 1.0 / h_last;
  r(n - 1) = 6.0 * divided3(n - 4);
  const Eigen::VectorXd m = a.fullPivLu().solve(r);
  Eigen::Index k = 0;
  while (k + 2 < n && t > xi(k + 1)) ++k;
  const double h = xi(k + 1) - xi(k);
  const double wa = (xi(k + 1) - t) / h;
  const double wb = (t - xi(k)) / h;
  return wa * yi(k) + wb * yi(k + 1) +
         ((wa * wa * wa - wa) * m(k) + (wb * wb * wb - wb) * m(k + 1)) * h * h / 6.0;
}

// gait2392 knee_r translation1 (x, anterior) and translation2 (y, vertical)
// of the tibia in the femur frame as functions of knee_angle_r (rad -> m).
const std::vector<double> kKneeX1 = {-2.0944,   -1.74533, -1.39626, -1.0472,  -0.698132, -0.349066,
                                     -0.174533, 0.197344, 0.337395, 0.490178, 1.52146,   2.0944};
const std::vector<double> kKneeY1 = {-0.0032, 0.00179,   0.00411,   0.0041,    0.00212,   -0.001,
                                     -0.0031, -0.005227, -0.005435, -0.005574, -0.005435, -0.00525};
const std::vector<double> kKneeX2 = {-2.0944,   -1.22173, -0.523599, -0.349066,
                                     -0.174533, 0.159149, 2.0944};
const std::vector<double> kKneeY2 = {-0.4226, -0.4082, -0.399, -0.3976, -0.3966, -0.395264, -0.396};

TEST(SimmSplineTest, MatchesDenseSolveOnGaitKneeSplines) {
  const SimmSpline t1(kKneeX1, kKneeY1);
  const SimmSpline t2(kKneeX2, kKneeY2);
  for (const double q : sample_range(-2.0944, 2.0944, 97)) {
    // Values ~0.4 m from two well-conditioned solves: agreement to round-off.
    EXPECT_NEAR(t1.evaluate(q), dense_reference(kKneeX1, kKneeY1, q), kSplineRoundOff) << q;
    EXPECT_NEAR(t2.evaluate(q), dense_reference(kKneeX2, kKneeY2, q), kSplineRoundOff) << q;
  }
}

TEST(SimmSplineTest, GaitKneeSplineValuesCheckedByHand) {
  const SimmSpline t1(kKneeX1, kKneeY1);
  const SimmSpline t2(kKneeX2, kKneeY2);
  // Knots, read off the file: at -0.349066 rad the tibia sits 1 mm behind,
  // at 0.159149 rad 395.264 mm below the femur origin.
  EXPECT_EQ(t1.evaluate(-0.349066), -0.001);
  EXPECT_EQ(t2.evaluate(0.159149), -0.395264);
  // Between knots: solved with exact rational arithmetic (Python Fraction,
  // the M_i formulation of dense_reference) from the decimal knots:
  //   translation1(0) = -0.0044998565175360132, between -0.0031 and -0.005227;
  //   translation2(0) = -0.39582069644835033,   between -0.3966 and -0.395264;
  //   translation1(-1) = 0.0039252685084184957, translation2(-1) = -0.40480003999257308;
  //   translation2(-pi/2) = -0.41399219775507551.
  // The decimal knots differ from their doubles by < 1e-17 relative, so the
  // double evaluation agrees to round-off.
  EXPECT_NEAR(t1.evaluate(0.0), -0.0044998565175360132, kSplineRoundOff);
  EXPECT_NEAR(t2.evaluate(0.0), -0.39582069644835033, kSplineRoundOff);
  EXPECT_NEAR(t1.evaluate(-1.0), 0.0039252685084184957, kSplineRoundOff);
  EXPECT_NEAR(t2.evaluate(-1.0), -0.40480003999257308, kSplineRoundOff);
  EXPECT_NEAR(t2.evaluate(-std::numbers::pi / 2), -0.41399219775507551, kSplineRoundOff);
}

TEST(SimmSplineTest, RejectsBadTables) {
  EXPECT_THROW(SimmSpline({0.0, 1.0, 2.0}, {0.0, 1.0}), InvalidInputError);
  EXPECT_THROW(SimmSpline({0.0, 2.0, 1.0}, {0.0, 1.0, 2.0}), InvalidInputError);
  EXPECT_THROW(SimmSpline({0.0, 1.0, 1.0}, {0.0, 1.0, 2.0}), InvalidInputError);
  EXPECT_THROW(SimmSpline({0.0}, {1.0}), InvalidInputError);
  EXPECT_THROW(SimmSpline({0.0, std::numeric_limits<double>::quiet_NaN()}, {0.0, 1.0}),
               InvalidInputError);
  try {
    [[maybe_unused]] const SimmSpline spline({0.0, 2.0, 1.0}, {0.0, 1.0, 2.0});
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("x[2]"), std::string::npos) << error.what();
  }
}

TEST(PiecewiseLinearFunctionTest, InterpolatesAndExtendsEndSegments) {
  const PiecewiseLinearFunction f({0.0, 1.0, 3.0}, {0.0, 2.0, 1.0});
  EXPECT_DOUBLE_EQ(f.evaluate(0.5), 1.0);
  EXPECT_DOUBLE_EQ(f.evaluate(2.0), 1.5);
  EXPECT_DOUBLE_EQ(f.evaluate(3.0), 1.0);
  EXPECT_DOUBLE_EQ(f.evaluate(-1.0), -2.0);  // slope 2 continued
  EXPECT_DOUBLE_EQ(f.evaluate(5.0), 0.0);    // slope -1/2 continued
  EXPECT_DOUBLE_EQ(f.derivative(0.5), 2.0);
  EXPECT_DOUBLE_EQ(f.derivative(2.0), -0.5);
  EXPECT_DOUBLE_EQ(f.derivative(9.0), -0.5);
  EXPECT_THROW(PiecewiseLinearFunction({1.0, 0.0}, {0.0, 1.0}), InvalidInputError);
}

TEST(FunctionTest, EvaluatesEveryKind) {
  const Function constant = Constant{2.5};
  EXPECT_EQ(constant.evaluate(7.0), 2.5);
  EXPECT_EQ(constant.derivative(7.0), 0.0);
  EXPECT_EQ(constant.type_name(), "Constant");

  const Function linear = LinearFunction{-2.0, 0.5};
  EXPECT_DOUBLE_EQ(linear.evaluate(3.0), -5.5);
  EXPECT_DOUBLE_EQ(linear.derivative(3.0), -2.0);

  // Highest order first: 2 x^2 - 3 x + 1.
  const Function polynomial = PolynomialFunction{{2.0, -3.0, 1.0}};
  EXPECT_DOUBLE_EQ(polynomial.evaluate(2.0), 3.0);
  EXPECT_DOUBLE_EQ(polynomial.derivative(2.0), 5.0);
  EXPECT_EQ(Function(PolynomialFunction{}).evaluate(1.0), 0.0);

  const Function spline = SimmSpline({0.0, 1.0}, {1.0, 3.0});
  EXPECT_EQ(spline.type_name(), "SimmSpline");
  ASSERT_NE(spline.get_if<SimmSpline>(), nullptr);
  EXPECT_EQ(spline.get_if<LinearFunction>(), nullptr);

  const Function scaled = MultiplierFunction(spline, 1.5);
  EXPECT_DOUBLE_EQ(scaled.evaluate(0.5), 3.0);
  EXPECT_DOUBLE_EQ(scaled.derivative(0.5), 3.0);
  EXPECT_EQ(scaled.type_name(), "MultiplierFunction");

  // Copies share the immutable inner function; reassigning a copy leaves the original alone.
  Function copy = scaled;
  EXPECT_DOUBLE_EQ(copy.evaluate(0.25), scaled.evaluate(0.25));
  copy = Constant{1.0};
  EXPECT_EQ(copy.evaluate(0.25), 1.0);
  EXPECT_DOUBLE_EQ(scaled.evaluate(0.25), 2.25);

  EXPECT_EQ(Function().evaluate(3.0), 0.0);
}

}  // namespace
}  // namespace mmm::opensim
