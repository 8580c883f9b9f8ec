#include "analysis/spatial/normals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/sail_generator.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A side × side square of the plane through `origin` with unit normal `normal`,
// n points uniform over it, Gaussian noise σ along the normal.
struct Plane {
  Cloud cloud;
  Vec3 origin, normal;
  double density_per_m2 = 0;
};

Plane noisyPlane(size_t n, double side, double sigma, uint32_t seed, Vec3 normal = Vec3(1, 2, 3).normalized()) {
  Plane plane;
  plane.normal = normal.normalized();
  plane.origin = Vec3(0.5, -0.2, 1.0);
  const Vec3 e1 = plane.normal.unitOrthogonal(), e2 = plane.normal.cross(e1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-0.5 * side, 0.5 * side);
  std::normal_distribution<double> N(0.0, 1.0);
  for (size_t i = 0; i < n; ++i)
    plane.cloud.points.push_back(plane.origin + U(rng) * e1 + U(rng) * e2 + sigma * N(rng) * plane.normal);
  plane.density_per_m2 = static_cast<double>(n) / (side * side);
  return plane;
}

double angleBetweenLines(const Vec3& a, const Vec3& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

double quantile(std::vector<double> v, double q) {
  const size_t i = static_cast<size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(i), v.end());
  return v[i];
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// n points of the Fibonacci lattice on a sphere.
Cloud fibonacciSphere(size_t n, double radius, const Vec3& centre) {
  Cloud cloud;
  for (size_t i = 0; i < n; ++i) cloud.points.push_back(centre + radius * fibonacciDirection(i, n));
  return cloud;
}

TEST(EstimateNormals, ExactPlaneGivesItsNormalAndZeroCurvature) {
  const Plane plane = noisyPlane(2000, 1.0, 0.0, 1);
  NormalParams p;
  p.orientation = "none";
  const NormalEstimation est = estimateNormals(plane.cloud, p);
  ASSERT_EQ(est.normals.normals.size(), plane.cloud.size());
  ASSERT_EQ(est.normals.curvature.size(), plane.cloud.size());
  EXPECT_EQ(est.orientation, "none");
  EXPECT_EQ(est.flipped, 0u);
  EXPECT_TRUE(est.warnings.empty());
  for (size_t i = 0; i < plane.cloud.size(); ++i) {
    EXPECT_NEAR(est.normals.normals[i].norm(), 1.0, 1e-12);
    // Only rounding separates the points from the plane (coordinates ~1 m, 1e-16 relative).
    EXPECT_LT(angleBetweenLines(est.normals.normals[i], plane.normal), 1e-6) << i;
    EXPECT_LT(est.normals.curvature[i], 1e-12) << i;
  }
}

TEST(EstimateNormals, NoisyPlaneNormalErrorFollowsTheLeastSquaresNoiseModel) {
  // 2 m × 2 m at 2500 points/m² (a full-scale scan's density), σ = 4 mm, k = 30.
  const Plane plane = noisyPlane(10000, 2.0, kSigma, 2);
  NormalParams p;
  p.k_neighbours = 30;
  p.orientation = "none";
  const NormalEstimation est = estimateNormals(plane.cloud, p);
  // k neighbours fill a disc of radius r with π r² ρ = k; its in-plane spread is r/2
  // per axis, so each tilt component of the fitted normal has σ_t = σ / (√k · r/2)
  // and the tilt angle is Rayleigh(σ_t): mean σ_t·√(π/2), 99th percentile σ_t·√(2 ln 100).
  const double k = p.k_neighbours;
  const double r = std::sqrt(k / (M_PI * plane.density_per_m2));
  const double sigma_t = kSigma / (std::sqrt(k) * r / 2.0);
  std::vector<double> err;
  for (const Vec3& nrm : est.normals.normals) err.push_back(angleBetweenLines(nrm, plane.normal));
  const double mean_expected = sigma_t * std::sqrt(M_PI / 2.0);
  // Random neighbourhoods spread less evenly than the ideal disc (and edge points see a
  // half disc), which fattens the error by 10–20 %: allow +25 % on the mean, +30 % on the tail.
  EXPECT_NEAR(mean(err), mean_expected, 0.25 * mean_expected) << "σ_t = " << sigma_t / kRadPerDeg << " deg";
  EXPECT_LT(quantile(err, 0.99), 1.3 * sigma_t * std::sqrt(2.0 * std::log(100.0)));
  // Guard against the model itself being loose: the bound is a couple of degrees.
  EXPECT_LT(mean_expected, 2.0 * kRadPerDeg);
}

TEST(EstimateNormals, NoisyPlaneCurvatureIsTheNoiseOverTheNeighbourhoodSpread) {
  const Plane plane = noisyPlane(10000, 2.0, kSigma, 3);
  NormalParams p;
  p.k_neighbours = 30;
  const NormalEstimation est = estimateNormals(plane.cloud, p);
  // λ0 ≈ σ² (k−3)/k (residual of a 3-parameter fit), λ1 + λ2 ≈ r²/2 (uniform disc),
  // so the surface variation is ≈ 2σ²(k−3)/(k r²).
  const double k = p.k_neighbours;
  const double r2 = k / (M_PI * plane.density_per_m2);
  const double expected = 2.0 * kSigma * kSigma * (k - 3) / (k * r2);
  // Median over 10000 points of a ratio of χ²-like sums of ~k terms: ±20 %.
  EXPECT_NEAR(quantile(est.normals.curvature, 0.5), expected, 0.2 * expected);
}

// A sphere of radius R sampled at density ρ: a k-ball centred on the surface cuts a
// cap of area exactly π r² with cos θ0 = 1 − a, a = r²/(2R²) = 2k/N. Uniform on the
// cap, cos θ is uniform on [1 − a, 1]: the normal variance is R²a²/12 and the
// tangential one R²a(3 − a)/3, so the surface variation is a / (12 − 3a) ≈ k / (6N).
class SphereCurvature : public ::testing::TestWithParam<double> {};

TEST_P(SphereCurvature, MatchesTheSurfaceVariationOfASphericalCap) {
  const double R = GetParam();
  const double density = 4000;  // points per m²
  const size_t n = static_cast<size_t>(4 * M_PI * R * R * density);
  const Cloud sphere = fibonacciSphere(n, R, Vec3(1.0, 2.0, 3.0));
  NormalParams p;
  p.k_neighbours = 20;
  p.orientation = "none";
  const NormalEstimation est = estimateNormals(sphere, p);
  const double a = 2.0 * p.k_neighbours / static_cast<double>(n);
  const double expected = a / (12.0 - 3.0 * a);
  // k = 20 discrete points stand for the continuous cap: ±10 % on the median.
  EXPECT_NEAR(quantile(est.normals.curvature, 0.5), expected, 0.1 * expected) << "R = " << R;
  // The normal is radial: the cap is symmetric about it, so only lattice irregularity tilts it.
  std::vector<double> err;
  for (size_t i = 0; i < n; ++i)
    err.push_back(angleBetweenLines(est.normals.normals[i], sphere.points[i] - Vec3(1.0, 2.0, 3.0)));
  const double cap_angle = std::acos(1.0 - a);
  EXPECT_LT(quantile(err, 0.99), 0.25 * cap_angle) << "cap half-angle " << cap_angle / kRadPerDeg << " deg";
}

INSTANTIATE_TEST_SUITE_P(Radii, SphereCurvature, ::testing::Values(0.5, 1.0));

TEST(EstimateNormals, SphereCurvatureScalesAsOneOverRSquaredAtFixedDensity) {
  // Same density and k: r is the same, so the variation a/(12 − 3a) with a = r²/(2R²)
  // quadruples when R halves.
  const double density = 4000;
  std::vector<double> medians;
  for (double R : {1.0, 0.5}) {
    const size_t n = static_cast<size_t>(4 * M_PI * R * R * density);
    NormalParams p;
    p.orientation = "none";
    medians.push_back(quantile(estimateNormals(fibonacciSphere(n, R, Vec3::Zero()), p).normals.curvature, 0.5));
  }
  // Each median is within a few % of the continuous value (test above): ratio 4 ± 10 %.
  EXPECT_NEAR(medians[1] / medians[0], 4.0, 0.4);
}

TEST(EstimateNormals, ViewpointOrientationPointsEveryNormalTowardsTheScanner) {
  Plane plane = noisyPlane(5000, 1.5, kSigma, 4);
  NormalParams none;
  none.orientation = "none";
  const NormalEstimation raw = estimateNormals(plane.cloud, none);
  size_t away_from_front = 0;
  const Vec3 front = plane.origin + 3.0 * plane.normal + Vec3(0.3, -0.2, 0.1);
  for (size_t i = 0; i < plane.cloud.size(); ++i)
    if (raw.normals.normals[i].dot(front - plane.cloud.points[i]) < 0) ++away_from_front;

  plane.cloud.viewpoint = front;
  const NormalEstimation towards = estimateNormals(plane.cloud, NormalParams{});
  EXPECT_EQ(towards.orientation, "viewpoint");
  EXPECT_TRUE(towards.warnings.empty());
  EXPECT_EQ(towards.flipped, away_from_front);
  for (size_t i = 0; i < plane.cloud.size(); ++i) {
    EXPECT_GT(towards.normals.normals[i].dot(front - plane.cloud.points[i]), 0.0) << i;
    // Orientation flips, it does not change the line.
    EXPECT_NEAR(std::abs(towards.normals.normals[i].dot(raw.normals.normals[i])), 1.0, 1e-12);
    EXPECT_EQ(towards.normals.curvature[i], raw.normals.curvature[i]);
  }

  // From the other side every normal is reversed: each one is flipped in exactly one run.
  plane.cloud.viewpoint = plane.origin - 3.0 * plane.normal;
  const NormalEstimation behind = estimateNormals(plane.cloud, NormalParams{});
  EXPECT_EQ(towards.flipped + behind.flipped, plane.cloud.size());
  for (size_t i = 0; i < plane.cloud.size(); ++i)
    EXPECT_NEAR(behind.normals.normals[i].dot(towards.normals.normals[i]), -1.0, 1e-12) << i;
}

TEST(EstimateNormals, PropagationOrientsACylinderConsistently) {
  // A mast-sized tube: radius 0.3 m, 1.5 m long, 20000 points, σ = 4 mm radial noise.
  const double R = 0.3, length = 1.5;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  Cloud tube;
  std::vector<Vec3> radial;
  for (int i = 0; i < 20000; ++i) {
    const double phi = 2 * M_PI * U(rng);
    const Vec3 out(std::cos(phi), std::sin(phi), 0.0);
    tube.points.push_back((R + kSigma * N(rng)) * out + Vec3(0, 0, length * U(rng)));
    radial.push_back(out);
  }
  NormalParams p;
  p.k_neighbours = 30;
  p.orientation = "propagate";
  const NormalEstimation est = estimateNormals(tube, p);
  EXPECT_EQ(est.orientation, "propagate");
  EXPECT_TRUE(est.warnings.empty());
  size_t outward = 0;
  std::vector<double> err;
  for (size_t i = 0; i < tube.size(); ++i) {
    if (est.normals.normals[i].dot(radial[i]) > 0) ++outward;
    err.push_back(angleBetweenLines(est.normals.normals[i], radial[i]));
  }
  // One connected patch: all outward or all inward, no exception.
  EXPECT_TRUE(outward == 0 || outward == tube.size()) << outward << " of " << tube.size() << " outward";
  // The tilt model of the plane test, at this density (≈ 7100 /m²): the 99th percentile
  // of Rayleigh(σ_t), +30 % for random neighbourhoods. A neighbourhood is symmetric about
  // the radial line, so the tube's bend adds no tilt.
  const double density = static_cast<double>(tube.size()) / (2 * M_PI * R * length);
  const double r = std::sqrt(p.k_neighbours / (M_PI * density));
  const double sigma_t = kSigma / (std::sqrt(p.k_neighbours) * r / 2.0);
  EXPECT_LT(quantile(err, 0.99), 1.3 * sigma_t * std::sqrt(2.0 * std::log(100.0)));
  // Propagation flips exactly the normals that "none" left pointing the other way
  // (the eigen solver's sign is arbitrary, so there are some each way).
  NormalParams none = p;
  none.orientation = "none";
  const NormalEstimation raw = estimateNormals(tube, none);
  size_t raw_outward = 0;
  for (size_t i = 0; i < tube.size(); ++i)
    if (raw.normals.normals[i].dot(radial[i]) > 0) ++raw_outward;
  EXPECT_GT(raw_outward, 0u);
  EXPECT_LT(raw_outward, tube.size());
  EXPECT_EQ(est.flipped, outward == 0 ? raw_outward : tube.size() - raw_outward);
}

TEST(EstimateNormals, WithoutAViewpointFallsBackToPropagationOnASail) {
  SailDesign design = exampleDesign(SailType::Main);
  ScanSimulation sim;
  sim.points = 30000;
  sim.noise_sigma_m = kSigma;
  sim.seed = 6;
  Cloud sail = sampleSail(design, sim);
  ASSERT_TRUE(sail.viewpoint.has_value());
  // The scanner sees one side of the sail: viewpoint orientation is the consistent answer.
  const NormalEstimation reference = estimateNormals(sail, NormalParams{});
  ASSERT_EQ(reference.orientation, "viewpoint");

  sail.viewpoint.reset();
  const NormalEstimation est = estimateNormals(sail, NormalParams{});
  EXPECT_EQ(est.orientation, "propagate");
  ASSERT_EQ(est.warnings.size(), 1u);
  EXPECT_NE(est.warnings[0].find("no viewpoint"), std::string::npos) << est.warnings[0];
  size_t agree = 0;
  for (size_t i = 0; i < sail.size(); ++i)
    if (est.normals.normals[i].dot(reference.normals.normals[i]) > 0) ++agree;
  EXPECT_TRUE(agree == 0 || agree == sail.size()) << agree << " of " << sail.size() << " agree with the viewpoint";
}

TEST(EstimateNormals, RobustRefitKeepsAPlaneNormalBesideAPerpendicularWall) {
  // A floor (z = 0, 1 cm grid, 1 mm noise) meeting a wall (x = 0.2): floor points
  // 2–4 cm from the wall have up to about a third of their 30 neighbours on it,
  // and the plain fit tilts their normals by more than 10°. The down-weighted
  // refit removes a good part of that tilt (measured: 13° → 9° at the worst
  // point). It does not reach the noise level (< 1°): starting from the tilted
  // plane, the reweighting settles on a compromise; a better start is future work.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.001);
  Cloud c;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j < 40; ++j) c.points.emplace_back(0.01 * i, 0.01 * j, noise(rng));
  const size_t floor_points = c.points.size();
  for (int i = 1; i <= 20; ++i)
    for (int j = 0; j < 40; ++j) c.points.emplace_back(0.2 + noise(rng), 0.01 * j, 0.01 * i);
  c.viewpoint = Vec3(-1, 0.2, 1);
  NormalParams plain;
  plain.k_neighbours = 30;
  plain.robust = false;
  NormalParams robust = plain;
  robust.robust = true;
  const Normals a = estimateNormals(c, plain).normals, b = estimateNormals(c, robust).normals;
  double worst_plain = 0, worst_robust = 0;
  for (size_t i = 0; i < floor_points; ++i) {
    const Vec3& p = c.points[i];
    if (p.x() < 0.155 || p.x() > 0.185 || p.y() < 0.05 || p.y() > 0.34) continue;  // 2–4 cm from the wall
    worst_plain = std::max(worst_plain, std::acos(std::min(1.0, std::abs(a.normals[i].z()))) * kDegPerRad);
    worst_robust = std::max(worst_robust, std::acos(std::min(1.0, std::abs(b.normals[i].z()))) * kDegPerRad);
  }
  EXPECT_GT(worst_plain, 10.0);
  EXPECT_LT(worst_robust, 0.8 * worst_plain);
}

TEST(EstimateNormals, ReusingANeighbourTableGivesTheSameResult) {
  const Plane plane = noisyPlane(3000, 1.0, kSigma, 8);
  NormalParams p;
  p.k_neighbours = 12;
  p.orientation = "propagate";
  const NeighbourTable table = nearestNeighbours(plane.cloud.points, 25);  // more columns than needed
  const NormalEstimation a = estimateNormals(plane.cloud, p);
  const NormalEstimation b = estimateNormals(plane.cloud, table, p);
  EXPECT_EQ(a.flipped, b.flipped);
  for (size_t i = 0; i < plane.cloud.size(); ++i) {
    EXPECT_NEAR((a.normals.normals[i] - b.normals.normals[i]).norm(), 0.0, 1e-12) << i;
    EXPECT_NEAR(a.normals.curvature[i], b.normals.curvature[i], 1e-12) << i;
  }
}

TEST(EstimateNormals, ReportsProgress) {
  const Plane plane = noisyPlane(1000, 1.0, kSigma, 9);
  double last_normals = -1;
  Progress progress;
  progress.callback = [&](std::string_view stage, double f) {
    if (stage == "normals") last_normals = f;
  };
  estimateNormals(plane.cloud, NormalParams{}, progress);
  EXPECT_DOUBLE_EQ(last_normals, 1.0);
}

TEST(EstimateNormals, RejectsBadParametersAndMismatchedTables) {
  const Plane plane = noisyPlane(50, 1.0, kSigma, 10);
  NormalParams p;
  p.k_neighbours = 2;
  expectInvalidInput([&] { estimateNormals(plane.cloud, p); }, {"[estimateNormals]", "k_neighbours must be >= 3", "2"});
  p = NormalParams{};
  p.orientation = "inwards";
  expectInvalidInput([&] { estimateNormals(plane.cloud, p); }, {"[estimateNormals]", "'inwards'"});
  p = NormalParams{};
  p.k_neighbours = 51;
  expectInvalidInput([&] { estimateNormals(plane.cloud, p); }, {"[estimateNormals]", "50 points", "51"});
  expectInvalidInput([&] { estimateNormals(Cloud{}, NormalParams{}); }, {"[estimateNormals]", "0 points"});

  // Tables: too few columns, or built for another cloud.
  const NeighbourTable narrow = nearestNeighbours(plane.cloud.points, 10);
  expectInvalidInput([&] { estimateNormals(plane.cloud, narrow, NormalParams{}); },
                     {"[estimateNormals]", "neighbour table", "k = 10"});
  const NeighbourTable other = nearestNeighbours(noisyPlane(60, 1.0, kSigma, 11).cloud.points, 20);
  expectInvalidInput([&] { estimateNormals(plane.cloud, other, NormalParams{}); },
                     {"[estimateNormals]", "60 rows", "50 points"});
  p = NormalParams{};
  p.k_neighbours = 2;
  expectInvalidInput([&] { estimateNormals(plane.cloud, narrow, p); }, {"k_neighbours must be >= 3"});
}

}  // namespace
}  // namespace sailshape
