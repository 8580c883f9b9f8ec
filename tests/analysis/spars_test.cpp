// Finding a spar whose measured place is off by a known amount, beside a sail.
#include "analysis/spars.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/errors.hpp"
#include "tests/analysis/fixtures.hpp"

namespace sailshape {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The half of a 25 mm mast a scanner at −y sees, sampled 2 mm apart with σ = 4 mm
// range noise along −y, its axis at `axis_xy`; and a sail plane y = 0 running
// aft from 10 mm behind the mast (x ≤ axis.x − 0.035), sampled on the same grid.
Cloud mastBesideSail(const Eigen::Vector2d& axis_xy, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, kSigma);
  Cloud c;
  const double r = 0.025;
  for (double z = 0.1; z < 2.0; z += 0.01) {
    for (double phi = kPi + 0.2; phi < 2 * kPi - 0.2; phi += 0.002 / r)
      c.points.emplace_back(axis_xy.x() + r * std::cos(phi), axis_xy.y() + r * std::sin(phi) + N(rng), z);
    for (double x = axis_xy.x() - 0.035; x > axis_xy.x() - 1.0; x -= 0.01) c.points.emplace_back(x, N(rng), z);
  }
  return c;
}

TEST(FitSpar, FindsAMastTwoCentimetresFromItsMeasuredPlaceBesideTheSail) {
  const Eigen::Vector2d truth(0.047, -0.013);  // 12 mm aft-forward and 13 mm sideways of the nominal
  const Cloud cloud = mastBesideSail(truth, 3);
  Spar nominal{"mast", Vec3(0.035, 0, 0), Vec3::UnitZ(), 2.2, 0.025};
  const SparFit f = fitSpar(cloud, nominal);
  ASSERT_TRUE(f.found) << f.message;
  // Hundreds of points on the surface, each to σ: the axis to well under σ.
  EXPECT_NEAR(f.spar.base.x(), truth.x(), kSigma / 2);
  EXPECT_NEAR(f.spar.base.y(), truth.y(), kSigma / 2);
  EXPECT_NEAR(f.offset.z(), 0.0, 1e-12);  // moved sideways only
  EXPECT_GT(f.support, 1000u);
  // Points within 2σ of the surface: their RMS is about σ·0.88 (a normal cut at 2σ), not more.
  EXPECT_LT(f.rms_m, kSigma);
  // The sail beside it is not inside the fitted spar plus a 3σ clearance.
  for (double x = truth.x() - 0.035; x > truth.x() - 0.2; x -= 0.01)
    EXPECT_GT(distanceToSpar(Vec3(x, 0, 1.0), f.spar), 0.0);
}

TEST(FitSpar, ASparOutOfViewKeepsItsMeasuredPlaceAndSaysSo) {
  Cloud sail_only;
  for (double z = 0.1; z < 2.0; z += 0.01)
    for (double x = -0.2; x > -1.0; x -= 0.01) sail_only.points.emplace_back(x, 0.0, z);
  Spar nominal{"mast", Vec3(0.035, 0, 0), Vec3::UnitZ(), 2.2, 0.025};
  const SparFit f = fitSpar(sail_only, nominal);
  EXPECT_FALSE(f.found);
  EXPECT_EQ(f.spar.base, nominal.base);
  EXPECT_NE(f.message.find("mast"), std::string::npos);
}

TEST(FitSpar, RejectsASparWithoutAxisLengthOrRadius) {
  const Cloud c = mastBesideSail(Eigen::Vector2d(0.035, 0), 1);
  EXPECT_THROW(fitSpar(c, Spar{"mast", Vec3::Zero(), Vec3::Zero(), 2.0, 0.025}), InvalidInput);
  EXPECT_THROW(fitSpar(c, Spar{"mast", Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.025}), InvalidInput);
  EXPECT_THROW(fitSpar(c, Spar{"mast", Vec3::Zero(), Vec3::UnitZ(), 2.0, 0.0}), InvalidInput);
  SparFitParams bad;
  bad.search_m = 0;
  EXPECT_THROW(fitSpar(c, Spar{"mast", Vec3::Zero(), Vec3::UnitZ(), 2.0, 0.025}, bad), InvalidInput);
}

}  // namespace
}  // namespace sailshape
