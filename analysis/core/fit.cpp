#include "analysis/core/fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <limits>
#include <string>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

// Row i: u_i⁰ … u_i^degree.
Eigen::MatrixXd powerBasis(const std::vector<double>& x, int degree, double centre, double scale) {
  Eigen::MatrixXd A(static_cast<Eigen::Index>(x.size()), degree + 1);
  for (size_t i = 0; i < x.size(); ++i) {
    const double u = (x[i] - centre) / scale;
    double uk = 1;
    for (int k = 0; k <= degree; ++k, uk *= u) A(static_cast<Eigen::Index>(i), k) = uk;
  }
  return A;
}

template <typename Values>
Polynomial leastSquares(const std::vector<double>& x, const Values& values, int degree, double centre, double scale) {
  if (x.empty() || static_cast<Eigen::Index>(x.size()) != values.rows() || degree < 0)
    throw InvalidInput("[fitPolynomial] need points, one row of values per point and a degree >= 0 (got " +
                       std::to_string(x.size()) + " points, " + std::to_string(values.rows()) + " rows, degree " +
                       std::to_string(degree) + ")");
  Polynomial p;
  p.centre = centre;
  p.scale = scale;
  p.coeffs = powerBasis(x, degree, centre, scale).colPivHouseholderQr().solve(values);
  return p;
}

}  // namespace

Eigen::RowVectorXd Polynomial::at(double x) const {
  const double u = variable(x);
  Eigen::RowVectorXd v = Eigen::RowVectorXd::Zero(coeffs.cols());
  double uk = 1;
  for (Eigen::Index k = 0; k < coeffs.rows(); ++k, uk *= u) v += uk * coeffs.row(k);
  return v;
}

Polynomial fitPolynomial(const std::vector<double>& x, const Eigen::MatrixXd& values, int degree, double centre,
                         double scale) {
  return leastSquares(x, values, degree, centre, scale);
}

Polynomial fitPolynomial(const std::vector<double>& x, const Eigen::VectorXd& values, int degree, double centre,
                         double scale) {
  return leastSquares(x, values, degree, centre, scale);
}

Polynomial fitPolynomialOverRange(const std::vector<double>& x, const Eigen::MatrixXd& values, int degree) {
  if (x.empty()) throw InvalidInput("[fitPolynomial] no points");
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return fitPolynomial(x, values, degree, 0.5 * (*lo + *hi), std::max(1e-9, 0.5 * (*hi - *lo)));
}

QuadraticHeightField QuadraticHeightField::fromMoments(const double* uv, const double* h) {
  // Entry (i, j) is the moment of basis_i · basis_j.
  constexpr int kMoment[6][6] = {{0, 1, 2, 3, 4, 5},   {1, 3, 4, 6, 7, 8},    {2, 4, 5, 7, 8, 9},
                                 {3, 6, 7, 10, 11, 12}, {4, 7, 8, 11, 12, 13}, {5, 8, 9, 12, 13, 14}};
  QuadraticHeightField f;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) f.normal_matrix(i, j) = uv[kMoment[i][j]];
  f.normal_rhs = Eigen::Map<const Vector6>(h);
  f.height_ss = std::numeric_limits<double>::quiet_NaN();
  return f;
}

bool QuadraticHeightField::solve() {
  const Eigen::LDLT<Matrix6> ldlt(normal_matrix);
  coeffs = ldlt.solve(normal_rhs);
  return ldlt.info() == Eigen::Success && coeffs.allFinite();
}

double QuadraticHeightField::residualSumOfSquares() const {
  return std::clamp(height_ss - coeffs.dot(normal_rhs), 0.0, height_ss);
}

}  // namespace sailshape
