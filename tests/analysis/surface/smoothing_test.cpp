#include "analysis/surface/smoothing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A 2 m × 2 m patch of the plane z = 0 at 2500 points/m², Gaussian noise σ in z.
Cloud noisyPlane(size_t n, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 2.0);
  std::normal_distribution<double> N(0.0, 1.0);
  Cloud cloud;
  for (size_t i = 0; i < n; ++i) cloud.points.emplace_back(U(rng), U(rng), sigma * N(rng));
  return cloud;
}

// A sphere of radius R about the origin at `density` points/m² on a Fibonacci lattice
// (nearly uniform, no edges), with Gaussian radial noise σ.
Cloud noisySphere(double R, double density, double sigma, uint32_t seed) {
  const size_t n = static_cast<size_t>(4 * M_PI * R * R * density);
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  Cloud cloud;
  for (size_t i = 0; i < n; ++i) cloud.points.push_back((R + sigma * N(rng)) * fibonacciDirection(i, n));
  return cloud;
}

double rmsOffPlane(const Cloud& c) {
  double s = 0;
  for (const Vec3& p : c.points) s += p.z() * p.z();
  return std::sqrt(s / static_cast<double>(c.size()));
}

double rmsOffSphere(const Cloud& c, double R) {
  double s = 0;
  for (const Vec3& p : c.points) s += std::pow(p.norm() - R, 2);
  return std::sqrt(s / static_cast<double>(c.size()));
}

// The classes must be a recount of displacement_m, and the summary figures its RMS and max.
void expectConsistentClasses(const Smoothing& s, const SmoothingParams& p, size_t n) {
  ASSERT_EQ(s.displacement_m.size(), n);
  EXPECT_EQ(s.good + s.fair + s.bad, n);
  size_t good = 0, fair = 0, bad = 0;
  double sum2 = 0, max = 0;
  for (float d : s.displacement_m) {
    EXPECT_GE(d, 0.0f);
    (d < p.good_m ? good : d < p.fair_m ? fair : bad)++;
    sum2 += static_cast<double>(d) * d;
    max = std::max(max, static_cast<double>(d));
  }
  EXPECT_EQ(s.good, good);
  EXPECT_EQ(s.fair, fair);
  EXPECT_EQ(s.bad, bad);
  EXPECT_NEAR(s.rms_displacement_m, std::sqrt(sum2 / static_cast<double>(n)), 1e-9);
  EXPECT_DOUBLE_EQ(s.max_displacement_m, max);
}

// Each displacement is the distance between the input and the smoothed point.
void expectDisplacementsMatch(const Cloud& in, const Smoothing& s) {
  ASSERT_EQ(s.cloud.size(), in.size());
  for (size_t i = 0; i < in.size(); ++i)
    ASSERT_NEAR(s.displacement_m[i], (s.cloud.points[i] - in.points[i]).norm(), 1e-6) << i;  // float storage
}

// Fraction of a zero-mean Gaussian of std s within ±x.
double within(double x, double s) { return std::erf(x / (s * std::sqrt(2.0))); }

TEST(SmoothMls, HalvesTheNoiseOfAPlane) {
  const Cloud in = noisyPlane(10000, kSigma, 1);
  // The fixture really has σ of noise: 10000 samples put the RMS within ~1 % of σ.
  ASSERT_NEAR(rmsOffPlane(in), kSigma, 0.03 * kSigma);
  const SmoothingParams p;
  const Smoothing s = smoothMls(in, p);
  expectDisplacementsMatch(in, s);
  expectConsistentClasses(s, p, in.size());
  // A quadratic fit to k = 60 points of a disc leaves the value at its centre with variance
  // 4σ²/k (0.26 σ); Gaussian weights lower the effective k and edge points extrapolate,
  // so σ/2 is the bound the study's "smoothing removes the noise" asks for.
  EXPECT_LT(rmsOffPlane(s.cloud), kSigma / 2);
  // Points move along z only: the plane's normal.
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_NEAR(s.cloud.points[i].x(), in.points[i].x(), 1e-3) << i;
    EXPECT_NEAR(s.cloud.points[i].y(), in.points[i].y(), 1e-3) << i;
  }
}

TEST(SmoothMls, DisplacementClassesFollowTheNoiseDistribution) {
  const Cloud in = noisyPlane(10000, kSigma, 2);
  const SmoothingParams p;  // good < 4 mm, fair < 9 mm
  const Smoothing s = smoothMls(in, p);
  expectConsistentClasses(s, p, in.size());
  // Smoothing a plane removes the noise, so each displacement is the noise minus the small
  // fit error: ≈ Gaussian with std = the RMS displacement (≈ 0.95 σ). Class fractions follow
  // from it; 10000 samples and the non-Gaussian edge points allow ±2 points of percentage.
  const double sd = s.rms_displacement_m;
  EXPECT_NEAR(sd, kSigma, 0.1 * kSigma);
  const double n = static_cast<double>(in.size());
  EXPECT_NEAR(s.good / n, within(p.good_m, sd), 0.02);
  EXPECT_NEAR(s.fair / n, within(p.fair_m, sd) - within(p.good_m, sd), 0.02);
  EXPECT_NEAR(s.bad / n, 1.0 - within(p.fair_m, sd), 0.01);
}

TEST(SmoothMls, HalvesTheNoiseOfASphere) {
  // R = 1 m, a sail's tightest curvature scale, at 2500 points/m² (31416 points).
  const double R = 1.0;
  const Cloud in = noisySphere(R, 2500, kSigma, 3);
  ASSERT_NEAR(rmsOffSphere(in, R), kSigma, 0.03 * kSigma);
  const SmoothingParams p;
  const Smoothing s = smoothMls(in, p);
  expectDisplacementsMatch(in, s);
  expectConsistentClasses(s, p, in.size());
  // As for the plane; the quadratic matches the sphere up to r⁴/(8R³) ≈ 1e-5 m at r ≈ 9 cm.
  EXPECT_LT(rmsOffSphere(s.cloud, R), kSigma / 2);
  // The k-th neighbour of a lattice point is at the radius of a cap holding k points:
  // π r² ρ = k, within the lattice's granularity (±5 %).
  const double r = std::sqrt(p.k_neighbours / (M_PI * 2500));
  EXPECT_NEAR(s.mean_radius_m, r, 0.05 * r);
}

TEST(SmoothMls, PlaneFitsFlattenASphereByTheWeightedCapDepth) {
  // Without noise a quadratic (order 2) leaves a sphere where it is, while a plane
  // (order 1) pulls each point to the Gaussian-weighted mean of its cap: with weights
  // exp(−2ρ²/h²) over a disc of radius h the weighted mean of ρ² is
  // h²·(1/4 − 3/(4e²)) / ((1 − e⁻²)/2) ≈ 0.3435 h², i.e. an inward move of 0.3435 h²/(2R).
  const double R = 0.5;
  const Cloud in = noisySphere(R, 4000, 0.0, 4);
  SmoothingParams p;
  p.k_neighbours = 40;
  const Smoothing quadratic = smoothMls(in, p);
  // The quadratic's residual is the quartic term r⁴/(8R³) ≈ 5e-6 m at r ≈ 5.6 cm.
  EXPECT_LT(quadratic.max_displacement_m, 2e-5);
  EXPECT_EQ(quadratic.good, in.size());
  EXPECT_TRUE(quadratic.warnings.empty());

  p.polynomial_order = 1;
  const Smoothing plane = smoothMls(in, p);
  const double h = plane.mean_radius_m;
  const double expected = (0.25 - 0.75 * std::exp(-2.0)) / ((1 - std::exp(-2.0)) / 2) * h * h / (2 * R);
  // k = 40 discrete points stand for the continuous cap: ±10 %.
  EXPECT_NEAR(plane.rms_displacement_m, expected, 0.1 * expected);
  double inward = 0;
  for (size_t i = 0; i < in.size(); ++i) inward += R - plane.cloud.points[i].norm();
  EXPECT_NEAR(inward / static_cast<double>(in.size()), expected, 0.1 * expected);
}

// A 2 m × 1.5 m sheet bent into a cylinder of radius 1.5 m (a sail's curvature),
// uniform at `density` points/m², Gaussian noise σ along the normal; straight edges
// and four right-angled corners.
Cloud noisyCylinderSheet(double density, double sigma, uint32_t seed) {
  const double R = 1.5;
  const size_t n = static_cast<size_t>(2.0 * 1.5 * density);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, sigma);
  Cloud cloud;
  for (size_t i = 0; i < n; ++i) {
    const double phi = 2.0 / R * (U(rng) - 0.5), y = 1.5 * U(rng), r = R + N(rng);
    cloud.points.emplace_back(r * std::sin(phi), y, r * std::cos(phi));
  }
  return cloud;
}

double radialError(const Vec3& p) { return std::hypot(p.x(), p.z()) - 1.5; }

TEST(SmoothMls, AnchoredFitsStayWithinATenthOfSigmaOfPlainMls) {
  const Cloud in = noisyCylinderSheet(5000, kSigma, 9);
  SmoothingParams plain;
  plain.anchor_ratio = 0;
  const Smoothing exact = smoothMls(in, plain);
  const Smoothing anchored = smoothMls(in, SmoothingParams{});  // anchor_ratio 0.5 by default
  ASSERT_EQ(anchored.cloud.size(), in.size());
  EXPECT_EQ(exact.fitted_surfaces, in.size());
  // Inside the sheet one fit stands for the points around each anchor (one per cube
  // half a radius wide); the edge band, about a radius wide and ~30 % of this small
  // sheet, keeps a fit per point.
  EXPECT_LT(anchored.fitted_surfaces, in.size() * 6 / 10);
  EXPECT_GT(anchored.fitted_surfaces, in.size() / 10);
  // The quadratic carries the surface across half a radius: the two results differ
  // by a small part of the noise left after smoothing (σ/2 at most, see above).
  double sum2 = 0, max = 0, err_exact = 0, err_anchored = 0;
  size_t corner_points = 0;
  for (size_t i = 0; i < in.size(); ++i) {
    const double d = (anchored.cloud.points[i] - exact.cloud.points[i]).norm();
    sum2 += d * d;
    max = std::max(max, d);
    err_exact += std::pow(radialError(exact.cloud.points[i]), 2);
    err_anchored += std::pow(radialError(anchored.cloud.points[i]), 2);
    // Within 5 cm of a corner: anchors never stand in for these points.
    const double phi = std::atan2(in.points[i].x(), in.points[i].z());
    const bool corner = std::abs(std::abs(phi) - 1.0 / 1.5) * 1.5 < 0.05 &&
                        (in.points[i].y() < 0.05 || in.points[i].y() > 1.45);
    if (corner) {
      ++corner_points;
      EXPECT_EQ(anchored.cloud.points[i], exact.cloud.points[i]) << i;
    }
  }
  EXPECT_GT(corner_points, 20u);
  EXPECT_LT(std::sqrt(sum2 / static_cast<double>(in.size())), 0.1 * kSigma);
  EXPECT_LT(max, kSigma / 2);
  // Against the known surface the anchored result is as good as plain MLS (±10 %).
  EXPECT_LT(std::sqrt(err_anchored / static_cast<double>(in.size())),
            1.1 * std::sqrt(err_exact / static_cast<double>(in.size())));
  EXPECT_NEAR(anchored.mean_radius_m, exact.mean_radius_m, 0.02 * exact.mean_radius_m);
}

TEST(SmoothMls, GivesTheSameResultEveryRun) {
  // Per-point results written by index and sums taken in index order: thread
  // timing cannot change a bit.
  const Cloud in = noisyCylinderSheet(3000, kSigma, 10);
  const Smoothing a = smoothMls(in, SmoothingParams{});
  const Smoothing b = smoothMls(in, SmoothingParams{});
  EXPECT_EQ(a.cloud.points, b.cloud.points);
  EXPECT_EQ(a.displacement_m, b.displacement_m);
  EXPECT_EQ(a.mean_radius_m, b.mean_radius_m);
  EXPECT_EQ(a.fitted_surfaces, b.fitted_surfaces);
}

TEST(SmoothMls, WarnsWhenTooManyPointsMoveBeyondFair) {
  // Classes tighter than the noise: nearly every point of a σ = 4 mm plane moves more
  // than fair_m = 1 mm (|Z| > 0.25 holds for 80 % of a Gaussian).
  const Cloud in = noisyPlane(5000, kSigma, 5);
  SmoothingParams p;
  p.good_m = 0.0005;
  p.fair_m = 0.001;
  const Smoothing s = smoothMls(in, p);
  expectConsistentClasses(s, p, in.size());
  EXPECT_GT(s.bad, in.size() * 3 / 4);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("moved more than fair_m"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find(std::to_string(s.bad)), std::string::npos) << s.warnings[0];
}

TEST(SmoothMls, CarriesAttributesOver) {
  Cloud in = noisyPlane(500, kSigma, 6);
  for (size_t i = 0; i < in.size(); ++i) {
    in.intensity.push_back(static_cast<float>(i));
    in.alpha_rad.push_back(0.001 * static_cast<double>(i));
    in.beta_rad.push_back(-0.002 * static_cast<double>(i));
  }
  in.viewpoint = Vec3(1, 2, 3);
  const Smoothing s = smoothMls(in, SmoothingParams{});
  EXPECT_EQ(s.cloud.intensity, in.intensity);
  EXPECT_EQ(s.cloud.alpha_rad, in.alpha_rad);
  EXPECT_EQ(s.cloud.beta_rad, in.beta_rad);
  ASSERT_TRUE(s.cloud.viewpoint.has_value());
  EXPECT_EQ(*s.cloud.viewpoint, Vec3(1, 2, 3));
}

TEST(SmoothMls, TakesMoreNeighboursInADenseCloud) {
  // 64,000 points on 4 m²: 16,000 points/m², four times the reference density,
  // so k doubles (√4); the median k-th neighbour distance estimates the density
  // to a few per cent (edges pull it down a little).
  const Cloud dense = noisyPlane(64000, kSigma, 3);
  SmoothingParams p;
  p.max_radius_ratio = 0;  // the 8,000-point patch below would meet the size limit (next tests)
  const Smoothing scaled = smoothMls(dense, p);
  EXPECT_NEAR(static_cast<double>(scaled.k_used), 2.0 * p.k_neighbours, 0.15 * 2.0 * p.k_neighbours);
  SmoothingParams fixed = p;
  fixed.reference_density_per_m2 = 0;
  const Smoothing plain = smoothMls(dense, fixed);
  EXPECT_EQ(plain.k_used, static_cast<size_t>(p.k_neighbours));
  // The value left at a point varies as 1/k: twice the neighbours, √2 less noise.
  EXPECT_LT(rmsOffPlane(scaled.cloud), 0.85 * rmsOffPlane(plain.cloud));
  // Below the reference density k stays as set: 8,000 points on 4 m².
  EXPECT_EQ(smoothMls(noisyPlane(8000, kSigma, 4), p).k_used, static_cast<size_t>(p.k_neighbours));
}

TEST(SmoothMls, MeasuresTheNoiseAndTakesFewerNeighboursOnACleanCloud) {
  // Off quadratics through 24 neighbours a plane with σ noise leaves σ (the fit's six
  // coefficients are counted); a clean one leaves nothing, and then k falls to 40:
  // there is no noise to average and a wide neighbourhood only adds the bias.
  SmoothingParams p;
  p.max_radius_ratio = 0;  // k = 200 on this patch spans more than the size limit allows
  const Smoothing noisy = smoothMls(noisyPlane(8000, kSigma, 5), p);
  EXPECT_NEAR(noisy.measured_noise_m, kSigma, 0.1 * kSigma);  // 256 samples of 18 degrees of freedom: ±4 %
  EXPECT_EQ(noisy.k_used, static_cast<size_t>(p.k_neighbours));
  const Smoothing clean = smoothMls(noisyPlane(8000, 0.0, 5), p);
  EXPECT_LT(clean.measured_noise_m, 1e-6);
  EXPECT_EQ(clean.k_used, 40u);
  // Half the sensor's σ is where it starts: k shrinks with √(noise / (σ/2)).
  const Smoothing quarter = smoothMls(noisyPlane(8000, kSigma / 4, 5), p);
  EXPECT_NEAR(static_cast<double>(quarter.k_used), p.k_neighbours * std::sqrt(0.5), 0.06 * p.k_neighbours);
  SmoothingParams fixed = p;
  fixed.adapt_to_noise = false;
  EXPECT_EQ(smoothMls(noisyPlane(8000, 0.0, 5), fixed).k_used, static_cast<size_t>(p.k_neighbours));
}

TEST(SmoothMls, HoldsTheRadiusToAFractionOfTheSailsSize) {
  // 8,000 points on the 2 m × 2 m patch: 2,000 points/m², so 200 neighbours span
  // √(200 / (π · 2000)) = 0.178 m. The limit is 0.07 × √(4 m²) = 0.14 m, widened for
  // noise: 4 mm on a 2 m patch is 2.1 times the reference's 4 mm on √18 m², so
  // 0.14 × 2.1^0.2 = 0.163 m. Held there, the fits take π · 2000 · 0.163² ≈ 167
  // neighbours: π · N · radius² / area (edges thin the density a little, so the
  // count comes out a few lower).
  const SmoothingParams p;
  const Cloud sparse = noisyPlane(8000, kSigma, 4);
  const Smoothing held = smoothMls(sparse, p);
  const double relative_noise = (held.measured_noise_m / 2.0) / (p.good_m / std::sqrt(18.0));
  const double max_radius = p.max_radius_ratio * std::pow(relative_noise, 0.2) * 2.0;
  const double expected_k = M_PI * 2000 * max_radius * max_radius;
  EXPECT_NEAR(static_cast<double>(held.k_used), expected_k, 0.08 * expected_k);
  EXPECT_LT(held.k_used, static_cast<size_t>(p.k_neighbours));
  // A clean cloud's limit is not widened: 0.14 m, π · 2000 · 0.14² ≈ 123 neighbours
  // (the noise rule, off here, would take fewer still).
  SmoothingParams limit_only = p;
  limit_only.adapt_to_noise = false;
  const double clean_k = M_PI * 2000 * std::pow(p.max_radius_ratio * 2.0, 2);
  EXPECT_NEAR(static_cast<double>(smoothMls(noisyPlane(8000, 0.0, 4), limit_only).k_used), clean_k, 0.08 * clean_k);
  SmoothingParams unlimited = p;
  unlimited.max_radius_ratio = 0;
  EXPECT_EQ(smoothMls(sparse, unlimited).k_used, static_cast<size_t>(p.k_neighbours));
  // A larger limit than the radius leaves k alone; a tiny one stops at 40 neighbours.
  SmoothingParams wide = p;
  wide.max_radius_ratio = 0.1;
  EXPECT_EQ(smoothMls(sparse, wide).k_used, static_cast<size_t>(p.k_neighbours));
  SmoothingParams tiny = p;
  tiny.max_radius_ratio = 0.01;
  EXPECT_EQ(smoothMls(sparse, tiny).k_used, 40u);
}

TEST(SmoothMls, RejectsBadParametersAndSmallClouds) {
  const Cloud in = noisyPlane(100, kSigma, 7);
  auto with = [](auto change) {
    SmoothingParams p;
    change(p);
    return p;
  };
  for (int k : {5, 257})
    expectInvalidInput([&] { smoothMls(in, with([k](auto& p) { p.k_neighbours = k; })); },
                       {"[smoothMls]", "k_neighbours must be in [6, 256] (got " + std::to_string(k) + ")"});
  for (int order : {0, 3})
    expectInvalidInput([&] { smoothMls(in, with([order](auto& p) { p.polynomial_order = order; })); },
                       {"[smoothMls]", "polynomial_order must be 1 or 2"});
  expectInvalidInput([&] { smoothMls(in, with([](auto& p) { p.good_m = 0; })); }, {"[smoothMls]", "good_m"});
  expectInvalidInput([&] { smoothMls(in, with([](auto& p) { p.good_m = std::nan(""); })); }, {"[smoothMls]"});
  expectInvalidInput([&] { smoothMls(in, with([](auto& p) { p.fair_m = 0.003; })); },  // below good_m = 4 mm
                     {"[smoothMls]", "good_m <= fair_m"});
  expectInvalidInput([&] { smoothMls(in, with([](auto& p) { p.k_neighbours = 101; })); },
                     {"[smoothMls]", "100 points", "k_neighbours = 101"});
  expectInvalidInput([&] { smoothMls(Cloud{}, SmoothingParams{}); }, {"[smoothMls]", "0 points"});
  for (double rho : {-1.0, std::nan("")})
    expectInvalidInput([&] { smoothMls(in, with([rho](auto& p) { p.reference_density_per_m2 = rho; })); },
                       {"[smoothMls]", "reference_density_per_m2 must be >= 0"});
  for (double ratio : {-0.1, std::nan("")})
    expectInvalidInput([&] { smoothMls(in, with([ratio](auto& p) { p.max_radius_ratio = ratio; })); },
                       {"[smoothMls]", "max_radius_ratio must be >= 0"});
  // The limits themselves are accepted.
  EXPECT_EQ(smoothMls(in, with([](auto& p) { p.k_neighbours = 6; })).cloud.size(), in.size());
  EXPECT_EQ(smoothMls(noisyPlane(300, kSigma, 8), with([](auto& p) { p.k_neighbours = 256; })).cloud.size(), 300u);
}

}  // namespace
}  // namespace sailshape
