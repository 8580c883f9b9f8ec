#include "analysis/segmentation/cleaning.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A 2 m × 2 m plane z = 0 at 2500 points/m² with σ = 4 mm noise, and outliers
// 0.5 m off it (alternately above and below) at random places over it.
struct PlaneWithOutliers {
  Cloud cloud;
  std::set<uint32_t> outliers;
  size_t inliers = 0;
};

PlaneWithOutliers planeWithOutliers(size_t inliers, size_t outliers, uint32_t seed) {
  PlaneWithOutliers s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 2.0);
  std::uniform_int_distribution<size_t> slot(0, inliers + outliers - 1);
  std::normal_distribution<double> N(0.0, 1.0);
  // Outliers go to random slots so they are not simply the last indices.
  while (s.outliers.size() < outliers) s.outliers.insert(static_cast<uint32_t>(slot(rng)));
  for (uint32_t i = 0; i < inliers + outliers; ++i) {
    if (s.outliers.count(i))
      s.cloud.points.emplace_back(U(rng), U(rng), (i % 2 ? 0.5 : -0.5) + kSigma * N(rng));
    else
      s.cloud.points.emplace_back(U(rng), U(rng), kSigma * N(rng));
  }
  s.inliers = inliers;
  return s;
}

// Checks that `c` is a partition of the cloud, removes every injected outlier and keeps ≥ 99 % of inliers.
void expectOutliersFound(const Cleaning& c, const PlaneWithOutliers& s) {
  ASSERT_EQ(c.kept.size() + c.removed.size(), s.cloud.size());
  EXPECT_TRUE(std::is_sorted(c.kept.begin(), c.kept.end()));
  EXPECT_TRUE(std::is_sorted(c.removed.begin(), c.removed.end()));
  std::set<uint32_t> all(c.kept.begin(), c.kept.end());
  all.insert(c.removed.begin(), c.removed.end());
  EXPECT_EQ(all.size(), s.cloud.size());
  size_t outliers_removed = 0;
  for (uint32_t i : c.removed) outliers_removed += s.outliers.count(i);
  EXPECT_EQ(outliers_removed, s.outliers.size()) << "every injected outlier must go";
  const size_t inliers_kept = c.kept.size();  // no outlier is kept, by the line above
  EXPECT_GE(static_cast<double>(inliers_kept), 0.99 * static_cast<double>(s.inliers));
}

TEST(RemoveStatisticalOutliers, FindsPointsHalfAMetreOffAPlane) {
  const PlaneWithOutliers s = planeWithOutliers(10000, 50, 1);
  const Cleaning c = removeStatisticalOutliers(s.cloud);
  expectOutliersFound(c, s);
  // Inliers' mean distance to 20 neighbours is ≈ (2/3)·r20 with π r20² ρ = 20, i.e. ≈ 3.4 cm;
  // an outlier's is ≥ its distance to the nearest other outlier (~0.2–0.5 m). The threshold
  // mean + 3 std lands between: above any inlier, far below 0.5 m.
  const double r20 = std::sqrt(20.0 / (M_PI * 2500.0));
  EXPECT_GT(c.threshold_m, 2.0 / 3.0 * r20);
  EXPECT_LT(c.threshold_m, 0.25);
  EXPECT_TRUE(c.warnings.empty());
}

TEST(RemoveStatisticalOutliers, RemovesOnlyTheFarTailOfACleanPlane) {
  // Without outliers mean + 3 std removes only the far tail of the inliers' own
  // distribution: edge and corner points, a fraction of a percent.
  const PlaneWithOutliers s = planeWithOutliers(10000, 0, 2);
  const Cleaning c = removeStatisticalOutliers(s.cloud);
  EXPECT_LE(c.removed.size(), s.cloud.size() / 100);
  EXPECT_EQ(c.kept.size() + c.removed.size(), s.cloud.size());
}

TEST(RemoveStatisticalOutliers, ThresholdIsMeanPlusRatioTimesStd) {
  // Five points on a line at 0, 1, 2, 3, 10 m; k = 1: mean distances to the nearest
  // neighbour are 1, 1, 1, 1, 7 → mean 2.2, population std 2.4; ratio 1 → threshold 4.6.
  Cloud cloud;
  for (double x : {0.0, 1.0, 2.0, 3.0, 10.0}) cloud.points.emplace_back(x, 0.0, 0.0);
  StatisticalOutlierParams p;
  p.k_neighbours = 1;
  p.std_ratio = 1.0;
  const Cleaning c = removeStatisticalOutliers(cloud, p);
  EXPECT_NEAR(c.threshold_m, 4.6, 1e-6);  // distances pass through float: 1e-7 relative
  EXPECT_EQ(c.kept, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(c.removed, (std::vector<uint32_t>{4}));
}

TEST(RemoveStatisticalOutliers, RejectsBadParametersAndSmallClouds) {
  const PlaneWithOutliers s = planeWithOutliers(30, 0, 3);
  StatisticalOutlierParams p;
  p.k_neighbours = 0;
  expectInvalidInput([&] { removeStatisticalOutliers(s.cloud, p); },
                     {"[removeStatisticalOutliers]", "k_neighbours must be >= 1 (got 0)"});
  for (double r : {0.0, -1.0, std::nan("")}) {
    p = StatisticalOutlierParams{};
    p.std_ratio = r;
    expectInvalidInput([&] { removeStatisticalOutliers(s.cloud, p); }, {"[removeStatisticalOutliers]", "std_ratio"});
  }
  p = StatisticalOutlierParams{};
  p.k_neighbours = 30;  // needs 31 points: itself and 30 others
  expectInvalidInput([&] { removeStatisticalOutliers(s.cloud, p); },
                     {"[removeStatisticalOutliers]", "30 points", "k_neighbours = 30"});
  p.k_neighbours = 29;  // exactly enough
  const Cleaning c = removeStatisticalOutliers(s.cloud, p);
  EXPECT_EQ(c.kept.size() + c.removed.size(), 30u);
}

TEST(RemoveRadiusOutliers, FindsPointsHalfAMetreOffAPlane) {
  const PlaneWithOutliers s = planeWithOutliers(10000, 50, 4);
  const Cleaning c = removeRadiusOutliers(s.cloud);
  expectOutliersFound(c, s);
  // radius 0 → 4 × the median nearest-neighbour spacing, exactly (float distances: 1e-7).
  const double median_spacing = medianSpacing(nearestNeighbours(s.cloud.points, 2));
  EXPECT_NEAR(c.threshold_m, 4.0 * median_spacing, 1e-6);
  // In the plane a Poisson sample at ρ = 2500 /m² has median spacing sqrt(ln 2 / (π ρ))
  // ≈ 9.4 mm; the two points' noise adds Δz (variance 2σ²) in quadrature. A median of a
  // quadrature sum is not the quadrature of medians: ±5 %.
  const double in_plane = std::sqrt(std::log(2.0) / (M_PI * 2500.0));
  const double expected = 4.0 * std::sqrt(in_plane * in_plane + 2 * kSigma * kSigma);
  EXPECT_NEAR(c.threshold_m, expected, 0.05 * expected);
}

TEST(RemoveRadiusOutliers, AnExplicitRadiusCountsNeighboursExactly) {
  // A row of points 1 m apart and one 5 m away; radius 1.5 m, min_neighbours 1:
  // every point of the row has a neighbour, the far one has none.
  Cloud cloud;
  for (double x : {0.0, 1.0, 2.0, 3.0, 8.0}) cloud.points.emplace_back(x, 0.0, 0.0);
  RadiusOutlierParams p;
  p.radius_m = 1.5;
  p.min_neighbours = 1;
  Cleaning c = removeRadiusOutliers(cloud, p);
  EXPECT_EQ(c.threshold_m, 1.5);
  EXPECT_EQ(c.kept, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(c.removed, (std::vector<uint32_t>{4}));
  // Two neighbours within 1.5 m: only the inner points of the row qualify.
  p.min_neighbours = 2;
  c = removeRadiusOutliers(cloud, p);
  EXPECT_EQ(c.kept, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(c.removed, (std::vector<uint32_t>{0, 3, 4}));
  // The radius is inclusive: a neighbour exactly 1 m away counts at radius 1 m.
  p.radius_m = 1.0;
  p.min_neighbours = 1;
  c = removeRadiusOutliers(cloud, p);
  EXPECT_EQ(c.kept, (std::vector<uint32_t>{0, 1, 2, 3}));
}

TEST(RemoveRadiusOutliers, ACloudSmallerThanMinNeighboursIsRemovedWithAWarning) {
  Cloud cloud;
  for (double x : {0.0, 0.01, 0.02}) cloud.points.emplace_back(x, 0.0, 0.0);
  RadiusOutlierParams p;
  p.min_neighbours = 4;  // 3 points can have at most 2 neighbours each
  const Cleaning c = removeRadiusOutliers(cloud, p);
  EXPECT_TRUE(c.kept.empty());
  EXPECT_EQ(c.removed, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("every point removed"), std::string::npos) << c.warnings[0];
}

TEST(RemoveRadiusOutliers, RejectsBadParametersAndTinyClouds) {
  const PlaneWithOutliers s = planeWithOutliers(100, 0, 5);
  for (double r : {-0.1, std::numeric_limits<double>::infinity(), std::nan("")}) {
    RadiusOutlierParams p;
    p.radius_m = r;
    expectInvalidInput([&] { removeRadiusOutliers(s.cloud, p); }, {"[removeRadiusOutliers]", "radius_m must be >= 0"});
  }
  RadiusOutlierParams p;
  p.min_neighbours = 0;
  expectInvalidInput([&] { removeRadiusOutliers(s.cloud, p); },
                     {"[removeRadiusOutliers]", "min_neighbours must be >= 1 (got 0)"});
  Cloud one;
  one.points.emplace_back(0, 0, 0);
  expectInvalidInput([&] { removeRadiusOutliers(one, RadiusOutlierParams{}); },
                     {"[removeRadiusOutliers]", "fewer than 2 points"});
  expectInvalidInput([&] { removeRadiusOutliers(Cloud{}, RadiusOutlierParams{}); }, {"[removeRadiusOutliers]"});
}

// The head of a sail: a 20° wedge 3 m long in the plane z = 0 at 2500 points/m²
// with σ = 4 mm noise across it, apex at the origin pointing along −y, and
// points 0.1 m off the plane (spray, rigging) scattered over it.
struct Wedge {
  Cloud cloud;
  std::vector<double> offset;  // each inlier's distance from the plane, in σ (NaN for outliers)
  std::set<uint32_t> outliers;
};

Wedge sailHead(uint32_t seed) {
  Wedge w;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  const double half = std::tan(10.0 * 3.14159265358979 / 180.0), length = 3.0;
  const size_t n = static_cast<size_t>(2500 * length * length * half);  // area = length² · tan(10°)
  for (size_t i = 0; i < n + 60; ++i) {
    // Uniform over the triangle: the distance from the apex goes as √U.
    const double d = length * std::sqrt(U(rng)), x = (2 * U(rng) - 1) * half * d;
    if (i < n) {
      const double e = N(rng);
      w.cloud.points.emplace_back(x, -d, kSigma * e);
      w.offset.push_back(std::abs(e));
    } else {
      w.outliers.insert(static_cast<uint32_t>(w.cloud.size()));
      w.cloud.points.emplace_back(x, -d, (i % 2 ? 0.1 : -0.1));
      w.offset.push_back(std::numeric_limits<double>::quiet_NaN());
    }
  }
  return w;
}

TEST(ReadmitSurfacePoints, BringsBackTheSparseTipTheFiltersCutAndKeepsOutliersOut) {
  const Wedge w = sailHead(5);
  // The pipeline's two filters, one after the other, in indices of the input.
  const Cleaning s = removeStatisticalOutliers(w.cloud);
  const Cloud after_s = selectPoints(w.cloud, s.kept);
  const Cleaning r = removeRadiusOutliers(after_s);
  std::vector<uint32_t> kept;
  for (uint32_t j : r.kept) kept.push_back(s.kept[j]);
  std::set<uint32_t> filtered(kept.begin(), kept.end());
  size_t tip_lost = 0;
  for (uint32_t i = 0; i < w.cloud.size(); ++i)
    if (!w.outliers.count(i) && !filtered.count(i) && -w.cloud.points[i].y() < 0.3) ++tip_lost;
  ASSERT_GT(tip_lost, 0u) << "the filters must have cut into the tip for this test to say anything";

  ReadmitParams p;
  p.max_offset_m = 3 * kSigma;
  const Cleaning c = readmitSurfacePoints(w.cloud, kept, p);
  ASSERT_EQ(c.kept.size() + c.removed.size(), w.cloud.size());
  EXPECT_TRUE(std::is_sorted(c.kept.begin(), c.kept.end()));
  const std::set<uint32_t> back(c.kept.begin(), c.kept.end());
  for (uint32_t i : kept) EXPECT_TRUE(back.count(i)) << "a point the filters kept stays";
  for (uint32_t i : w.outliers) EXPECT_FALSE(back.count(i)) << "outlier " << i << " 0.1 m off the surface came back";
  // Every inlier within 2σ of the plane is on the surface by any account: all of
  // them are back, the tip's included (the plane through 12 neighbours is itself
  // known to about σ/√12, so the 3σ limit leaves them a clear margin).
  for (uint32_t i = 0; i < w.cloud.size(); ++i) {
    if (!w.outliers.count(i) && w.offset[i] <= 2.0) {
      EXPECT_TRUE(back.count(i)) << "inlier " << i << " at " << -w.cloud.points[i].y() << " m from the apex";
    }
  }
}

TEST(ReadmitSurfacePoints, RejectsBadParametersAndIndices) {
  const Wedge w = sailHead(1);
  std::vector<uint32_t> kept(w.cloud.size() / 2);
  for (uint32_t i = 0; i < kept.size(); ++i) kept[i] = i;
  ReadmitParams p;
  p.max_offset_m = 0.012;
  ReadmitParams bad = p;
  bad.k_neighbours = 2;
  EXPECT_THROW(readmitSurfacePoints(w.cloud, kept, bad), InvalidInput);
  bad = p;
  bad.max_offset_m = 0;
  EXPECT_THROW(readmitSurfacePoints(w.cloud, kept, bad), InvalidInput);
  bad = p;
  bad.max_gap_factor = -1;
  EXPECT_THROW(readmitSurfacePoints(w.cloud, kept, bad), InvalidInput);
  std::vector<uint32_t> outside = kept;
  outside.push_back(static_cast<uint32_t>(w.cloud.size()));
  EXPECT_THROW(readmitSurfacePoints(w.cloud, outside, p), InvalidInput);
}

TEST(OutlierRemoval, OneSharedTableGivesWhatEachTestFindsAlone) {
  // The pipeline's path: a table with enough columns for both tests, the statistical
  // test, then the radius test on the kept part of the same rows.
  // No outliers and a tight ratio: the statistical test removes the upper tail of the
  // plane's own points (about 16 % beyond mean + 1 std), so kept rows lose neighbours.
  const PlaneWithOutliers s = planeWithOutliers(8000, 0, 8);
  const StatisticalOutlierParams sp{10, 1.0};
  const RadiusOutlierParams rp;
  const NeighbourTable table = nearestNeighbours(s.cloud.points, 11);
  const Cleaning alone = removeStatisticalOutliers(s.cloud, sp);
  const Cleaning shared = removeStatisticalOutliers(s.cloud, table, sp);
  EXPECT_EQ(shared.kept, alone.kept);
  EXPECT_EQ(shared.removed, alone.removed);
  EXPECT_DOUBLE_EQ(shared.threshold_m, alone.threshold_m);
  ASSERT_GT(alone.removed.size(), 500u);

  Cloud kept;
  for (uint32_t i : alone.kept) kept.points.push_back(s.cloud.points[i]);
  const NeighbourTable sub = subsetTable(table, s.cloud.points, alone.kept, 5);
  const Cleaning radius_alone = removeRadiusOutliers(kept, rp);
  const Cleaning radius_shared = removeRadiusOutliers(kept, sub, rp);
  EXPECT_EQ(radius_shared.kept, radius_alone.kept);
  EXPECT_DOUBLE_EQ(radius_shared.threshold_m, radius_alone.threshold_m);

  const NeighbourTable too_narrow = nearestNeighbours(s.cloud.points, 4);
  expectInvalidInput([&] { removeStatisticalOutliers(s.cloud, too_narrow, sp); },
                     {"[removeStatisticalOutliers]", "k = 4", "needs 11 columns"});
  expectInvalidInput([&] { removeRadiusOutliers(kept, too_narrow, rp); },
                     {"[removeRadiusOutliers]", "does not match the cloud"});
}

}  // namespace
}  // namespace sailshape
