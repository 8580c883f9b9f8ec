// The shared least-squares fits on data with known answers: exact polynomials and
// quadratic surfaces come back to rounding; a noisy surface leaves its noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/core/errors.hpp"
#include "analysis/core/fit.hpp"

namespace sailshape {
namespace {

TEST(Fit, AnExactPolynomialIsRecoveredInItsShiftedVariable) {
  // y = 2 − 3u + 0.5u³ with u = (x − 4) / 2, sampled over x ∈ [1, 7].
  std::vector<double> x;
  Eigen::VectorXd y(31);
  for (int i = 0; i <= 30; ++i) {
    x.push_back(1.0 + 0.2 * i);
    const double u = (x.back() - 4.0) / 2.0;
    y[i] = 2.0 - 3.0 * u + 0.5 * u * u * u;
  }
  const Polynomial p = fitPolynomial(x, y, 3, 4.0, 2.0);
  ASSERT_EQ(p.coeffs.rows(), 4);
  ASSERT_EQ(p.coeffs.cols(), 1);
  EXPECT_NEAR(p.coeffs(0, 0), 2.0, 1e-12);
  EXPECT_NEAR(p.coeffs(1, 0), -3.0, 1e-12);
  EXPECT_NEAR(p.coeffs(2, 0), 0.0, 1e-12);
  EXPECT_NEAR(p.coeffs(3, 0), 0.5, 1e-12);
  EXPECT_NEAR(p.at(5.5)[0], 2.0 - 3.0 * 0.75 + 0.5 * std::pow(0.75, 3), 1e-12);
}

TEST(Fit, OverTheRangeEachColumnGetsItsOwnPolynomial) {
  // Two columns: a line and a parabola in x over [10, 14]: u = (x − 12) / 2.
  std::vector<double> x;
  Eigen::MatrixXd v(9, 2);
  for (int i = 0; i < 9; ++i) {
    x.push_back(14.0 - 0.5 * i);  // any order
    v(i, 0) = 1.0 + 2.0 * x.back();
    v(i, 1) = std::pow(x.back() - 11.0, 2);
  }
  const Polynomial p = fitPolynomialOverRange(x, v, 2);
  EXPECT_DOUBLE_EQ(p.centre, 12.0);
  EXPECT_DOUBLE_EQ(p.scale, 2.0);
  for (double at : {10.0, 11.3, 14.0, 15.0}) {
    const Eigen::RowVectorXd r = p.at(at);
    EXPECT_NEAR(r[0], 1.0 + 2.0 * at, 1e-11);
    EXPECT_NEAR(r[1], std::pow(at - 11.0, 2), 1e-11);
  }
}

TEST(Fit, PolynomialsNeedPointsOneRowEachAndADegree) {
  EXPECT_THROW(fitPolynomial({}, Eigen::VectorXd(), 1, 0.0, 1.0), InvalidInput);
  EXPECT_THROW(fitPolynomialOverRange({}, Eigen::MatrixXd(0, 3), 1), InvalidInput);
  EXPECT_THROW(fitPolynomial({1.0, 2.0}, Eigen::VectorXd(Eigen::VectorXd::Zero(3)), 1, 0.0, 1.0), InvalidInput);
  EXPECT_THROW(fitPolynomial({1.0, 2.0}, Eigen::MatrixXd(Eigen::MatrixXd::Zero(2, 3)), -1, 0.0, 1.0), InvalidInput);
}

TEST(Fit, AnExactQuadraticSurfaceIsRecoveredWithNoResidual) {
  const QuadraticHeightField::Vector6 c = (QuadraticHeightField::Vector6() << 0.3, -0.2, 0.1, 0.05, -0.4, 0.25).finished();
  QuadraticHeightField f;
  for (int i = -5; i <= 5; ++i)
    for (int j = -5; j <= 5; ++j) {
      const double u = 0.2 * i, v = 0.2 * j;
      f.add(u, v, QuadraticHeightField::basis(u, v).dot(c), 1.0 + 0.1 * (i + j + 10));  // weights change nothing
    }
  ASSERT_TRUE(f.solve());
  EXPECT_LT((f.coeffs - c).norm(), 1e-12);
  EXPECT_NEAR(f.height(0.7, -0.3), QuadraticHeightField::basis(0.7, -0.3).dot(c), 1e-12);
  EXPECT_LT(f.residualSumOfSquares(), 1e-20);
}

TEST(Fit, TheSameNormalEquationsFromMomentsSolveAlike) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> at(-1.0, 1.0);
  QuadraticHeightField added;
  double uv[15] = {}, h[6] = {};
  for (int i = 0; i < 200; ++i) {
    const double u = at(rng), v = at(rng), z = 0.1 + 0.2 * u * v - 0.3 * v * v + 0.01 * at(rng), w = 0.5 + 0.5 * at(rng);
    added.add(u, v, z, w);
    const double m[15] = {1, u, v, u * u, u * v, v * v, u * u * u, u * u * v, u * v * v, v * v * v,
                          u * u * u * u, u * u * u * v, u * u * v * v, u * v * v * v, v * v * v * v};
    for (int k = 0; k < 15; ++k) uv[k] += w * m[k];
    for (int k = 0; k < 6; ++k) h[k] += w * z * m[k];
  }
  QuadraticHeightField from = QuadraticHeightField::fromMoments(uv, h);
  ASSERT_TRUE(added.solve());
  ASSERT_TRUE(from.solve());
  EXPECT_LT((added.coeffs - from.coeffs).norm(), 1e-12);
  EXPECT_TRUE(std::isnan(from.residualSumOfSquares()));  // no Σ w·h² in the moments
}

TEST(Fit, ANoisySurfaceLeavesItsNoiseAsTheResidual) {
  // 2,500 points, Gaussian noise σ = 1 mm about a quadratic: the residual per degree
  // of freedom is σ² to within a few percent (its spread is √(2 / 2494) ≈ 2.8 %).
  constexpr double kSigma = 0.001;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> at(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, kSigma);
  QuadraticHeightField f;
  constexpr int kPoints = 2500;
  for (int i = 0; i < kPoints; ++i) {
    const double u = at(rng), v = at(rng);
    f.add(u, v, 0.02 - 0.1 * u * u + 0.03 * u * v + noise(rng));
  }
  ASSERT_TRUE(f.solve());
  EXPECT_NEAR(f.coeffs[3], -0.1, 5 * kSigma);
  EXPECT_NEAR(std::sqrt(f.residualSumOfSquares() / (kPoints - 6)), kSigma, 0.1 * kSigma);
}

}  // namespace
}  // namespace sailshape
