#pragma once
// Least-squares fits the analysis stages share: polynomials of one variable (an
// edge's points along its arc, a section's samples across a gap) and the quadratic
// height field over a plane (a surface's neighbourhood around a point).
#include <Eigen/Core>
#include <vector>

namespace sailshape {

// Polynomials of one variable x, one per column of `coeffs`: Σ_k coeffs(k, j) u^k in
// the shifted, scaled variable u = (x − centre) / scale, which keeps the powers near 1
// over the samples and so the least squares well conditioned.
struct Polynomial {
  Eigen::MatrixXd coeffs;  // (degree + 1) × columns, by rising power of u
  double centre = 0, scale = 1;

  double variable(double x) const { return (x - centre) / scale; }
  Eigen::RowVectorXd at(double x) const;  // one value per column
};

// The least-squares polynomials of `degree` through the rows of `values` (one row per
// entry of x, one polynomial per column), solved by column-pivoting Householder QR on
// the power basis in u. A VectorXd is solved as a vector (Eigen applies Householder
// reflections to a matrix of right-hand sides in blocks, which rounds differently).
// Throws InvalidInput without points, with a row count of values other than x's, or
// a negative degree; scale must not be 0.
Polynomial fitPolynomial(const std::vector<double>& x, const Eigen::MatrixXd& values, int degree, double centre,
                         double scale);
Polynomial fitPolynomial(const std::vector<double>& x, const Eigen::VectorXd& values, int degree, double centre,
                         double scale);
// The same with the samples' range mapped onto u ∈ [−1, 1]: centre its middle, scale
// half its width (at least 1e-9), so the fit covers [centre − scale, centre + scale].
Polynomial fitPolynomialOverRange(const std::vector<double>& x, const Eigen::MatrixXd& values, int degree);

// The quadratic height field h(u, v) = c₀ + c₁u + c₂v + c₃u² + c₄uv + c₅v² over a
// plane's coordinates (u, v), by weighted least squares through its normal equations
// (6×6, LDLT). u and v in units that keep them near 1 over the points (a radius, a
// spread): the normal equations hold their fourth powers. Add the points, then solve.
struct QuadraticHeightField {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

  Matrix6 normal_matrix = Matrix6::Zero();  // Σ w·b·bᵀ, b = basis(u, v)
  Vector6 normal_rhs = Vector6::Zero();     // Σ w·h·b
  double height_ss = 0;                     // Σ w·h² (NaN when built from moments without it)
  Vector6 coeffs = Vector6::Zero();         // c₀ … c₅, set by solve()

  static Vector6 basis(double u, double v) {
    Vector6 b;
    b << 1, u, v, u * u, u * v, v * v;
    return b;
  }
  void add(double u, double v, double h, double w = 1.0) {
    const Vector6 b = basis(u, v), wb = w * b;
    normal_matrix.noalias() += wb * b.transpose();
    normal_rhs += (w * h) * b;
    height_ss += w * h * h;
  }
  // The normal equations from weighted moments accumulated elsewhere (a vectorised
  // loop): uv[0..14] = Σ w·u^a·v^b for 1, u, v, u², uv, v², u³, u²v, uv², v³, u⁴, u³v,
  // u²v², uv³, v⁴, and h[0..5] = Σ w·h·b for the basis b. height_ss is left NaN.
  static QuadraticHeightField fromMoments(const double* uv, const double* h);

  // Solves the normal equations into `coeffs` (set even when it fails); false when the
  // points do not fix the quadratic (the LDLT failed or the solution is not finite).
  bool solve();
  double height(double u, double v) const {
    return coeffs[0] + coeffs[1] * u + coeffs[2] * v + coeffs[3] * u * u + coeffs[4] * u * v + coeffs[5] * v * v;
  }
  // Σ w·(h − height(u, v))² over the points added, after solve(): from the normal
  // equations (Σ w·h² − cᵀ·Σ w·h·b), held within [0, Σ w·h²] against rounding.
  double residualSumOfSquares() const;
};

}  // namespace sailshape
