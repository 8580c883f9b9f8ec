// The best-fit plane and the quadratic height field over it, which sail picking,
// the noise measurement, plane detection, the surface projection and the design
// comparison all read.
#include "analysis/spatial/principal_axes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

namespace sailshape {
namespace {

// A known pose: rotated about a skew axis and moved off the origin.
const Eigen::Isometry3d& pose() {
  static const Eigen::Isometry3d t = [] {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.rotate(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    m.pretranslate(Vec3(4.0, -2.5, 7.0));
    return m;
  }();
  return t;
}

// A grid of nu × nv points over [-a, a] × [-b, b] with heights h(x, y), in the frame
// of pose(): x long, y across, z the height.
template <typename Height>
std::vector<Vec3> grid(int nu, int nv, double a, double b, Height h) {
  std::vector<Vec3> pts;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = -a + 2 * a * i / (nu - 1), y = -b + 2 * b * j / (nv - 1);
      pts.push_back(pose() * Vec3(x, y, h(x, y)));
    }
  return pts;
}

// Variance of n evenly spaced values over [-a, a].
double evenVariance(int n, double a) { return a * a * (n + 1) / (3.0 * (n - 1)); }

std::vector<uint32_t> all(size_t n) {
  std::vector<uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  return idx;
}

TEST(PrincipalAxes, AFlatRectangleGivesItsCentreNormalAndSpreadsInAnyPose) {
  const std::vector<Vec3> pts = grid(41, 11, 2.0, 0.5, [](double, double) { return 0.0; });
  const PrincipalAxes pa = principalAxes(pts);
  const Eigen::Matrix3d r = pose().linear();
  EXPECT_LT((pa.mean - pose().translation()).norm(), 1e-12);
  EXPECT_NEAR(std::abs(pa.axes.col(0).dot(r.col(2))), 1.0, 1e-12);  // normal
  EXPECT_NEAR(std::abs(pa.axes.col(2).dot(r.col(0))), 1.0, 1e-12);  // long direction
  EXPECT_NEAR(std::abs(pa.axes.col(1).dot(r.col(1))), 1.0, 1e-12);
  EXPECT_NEAR(pa.variance[0], 0.0, 1e-15);
  EXPECT_NEAR(pa.variance[1], evenVariance(11, 0.5), 1e-12);
  EXPECT_NEAR(pa.variance[2], evenVariance(41, 2.0), 1e-12);
}

TEST(PrincipalAxes, IndicesSelectTheirPointsOnly) {
  std::vector<Vec3> pts = grid(21, 21, 1.0, 1.0, [](double, double) { return 0.0; });
  const size_t n = pts.size();
  pts.push_back(Vec3(100, 100, 100));  // not selected: must not pull the mean
  const PrincipalAxes pa = principalAxes(pts, all(n));
  EXPECT_LT((pa.mean - pose().translation()).norm(), 1e-12);
  EXPECT_NEAR(pa.variance[0], 0.0, 1e-15);
}

TEST(QuadraticHeightFieldSpread, ABowlIsAllBendAndNoResidual) {
  // h = 0.05 x² + 0.02 y²: symmetric, so its best-fit plane is parallel to z = 0 and
  // the quadratic over it takes up every height.
  auto h = [](double x, double y) { return 0.05 * x * x + 0.02 * y * y; };
  const std::vector<Vec3> pts = grid(41, 21, 2.0, 1.0, h);
  const PrincipalAxes pa = principalAxes(pts);
  const HeightFieldSpread s = quadraticHeightFieldSpread(pts, all(pts.size()), pa);
  double mean_h = 0;
  for (int i = 0; i < 41; ++i)
    for (int j = 0; j < 21; ++j) mean_h += h(-2.0 + 4.0 * i / 40, -1.0 + 2.0 * j / 20);
  mean_h /= 41 * 21;
  double ss = 0;
  for (int i = 0; i < 41; ++i)
    for (int j = 0; j < 21; ++j) ss += std::pow(h(-2.0 + 4.0 * i / 40, -1.0 + 2.0 * j / 20) - mean_h, 2);
  EXPECT_EQ(s.points, pts.size());
  EXPECT_NEAR(s.plane_ss_m2, ss, 1e-9 * ss);
  EXPECT_LT(s.residual_ss_m2, 1e-12 * ss);
}

TEST(QuadraticHeightFieldSpread, NoiseOffABentSurfaceIsTheResidual) {
  // A bent patch with 4 mm Gaussian heights: the residual's RMS (6 degrees of freedom
  // taken by the fit) is σ, within 3 % (the estimate's own spread over 20,000 points
  // is 1/√(2n) = 0.5 %), and the bend is the surface's own RMS about its mean.
  const double sigma = 0.004;
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, sigma);
  auto h = [](double x, double y) { return 0.08 * x * x - 0.03 * x * y + 0.01 * y * y; };
  std::vector<Vec3> pts;
  for (const Vec3& p : grid(200, 100, 2.0, 1.0, h)) pts.push_back(p);
  const Vec3 normal = pose().linear().col(2);
  for (Vec3& p : pts) p += noise(rng) * normal;
  const std::vector<uint32_t> idx = all(pts.size());
  const HeightFieldSpread s = quadraticHeightFieldSpread(pts, idx, principalAxes(pts, idx));
  const double n = static_cast<double>(s.points);
  EXPECT_NEAR(std::sqrt(s.residual_ss_m2 / (n - 6)), sigma, 0.03 * sigma);
  // The bend: 0.08 x² - 0.03 xy + 0.01 y² about its mean over the grid.
  double mean_h = 0, ss = 0;
  std::vector<double> hs;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 100; ++j) hs.push_back(h(-2.0 + 4.0 * i / 199, -1.0 + 2.0 * j / 99));
  for (double v : hs) mean_h += v / static_cast<double>(hs.size());
  for (double v : hs) ss += (v - mean_h) * (v - mean_h);
  const double bend = std::sqrt((s.plane_ss_m2 - s.residual_ss_m2) / n);
  EXPECT_NEAR(bend, std::sqrt(ss / n), 0.01 * std::sqrt(ss / n));
}

}  // namespace
}  // namespace sailshape
