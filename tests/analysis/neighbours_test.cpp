#include "analysis/neighbours.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "analysis/errors.hpp"
#include "tests/analysis/fixtures.hpp"

namespace sailshape {
namespace {

// A regular n × n grid with spacing h in the plane z = 0; point (i, j) has index i*n + j.
std::vector<Vec3> grid(int n, double h) {
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) pts.emplace_back(i * h, j * h, 0.0);
  return pts;
}

uint32_t at(int n, int i, int j) { return static_cast<uint32_t>(i * n + j); }

TEST(KdTree, NearestOnAGridFindsTheFourEdgeNeighboursAtSpacingH) {
  const int n = 10;
  const double h = 0.05;
  const std::vector<Vec3> pts = grid(n, h);
  const KdTree tree(pts);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  tree.nearest(pts[at(n, 4, 5)], 5, idx, d2);
  ASSERT_EQ(idx.size(), 5u);
  ASSERT_EQ(d2.size(), 5u);
  EXPECT_EQ(idx[0], at(n, 4, 5));
  EXPECT_DOUBLE_EQ(d2[0], 0.0);
  const std::set<uint32_t> expected{at(n, 3, 5), at(n, 5, 5), at(n, 4, 4), at(n, 4, 6)};
  EXPECT_EQ(std::set<uint32_t>(idx.begin() + 1, idx.end()), expected);
  for (int j = 1; j < 5; ++j) EXPECT_NEAR(d2[j], h * h, 1e-15);
}

TEST(KdTree, NearestBetweenGridNodesIsSortedAndExact) {
  const int n = 10;
  const double h = 0.05;
  const std::vector<Vec3> pts = grid(n, h);
  const KdTree tree(pts);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  // A query a quarter-spacing from node (2, 2) along x, lifted 0.01 m off the plane.
  const Vec3 q(2.25 * h, 2 * h, 0.01);
  tree.nearest(q, 3, idx, d2);
  ASSERT_EQ(idx.size(), 3u);
  EXPECT_EQ(idx[0], at(n, 2, 2));
  EXPECT_EQ(idx[1], at(n, 3, 2));
  EXPECT_NEAR(d2[0], std::pow(0.25 * h, 2) + 1e-4, 1e-15);
  EXPECT_NEAR(d2[1], std::pow(0.75 * h, 2) + 1e-4, 1e-15);
  // Third: (2, 1) or (2, 3), both at sqrt((h/4)² + h² + 0.01²).
  EXPECT_NEAR(d2[2], std::pow(0.25 * h, 2) + h * h + 1e-4, 1e-15);
  EXPECT_TRUE(idx[2] == at(n, 2, 1) || idx[2] == at(n, 2, 3)) << idx[2];
}

TEST(KdTree, NearestReturnsEveryPointWhenKExceedsTheCloud) {
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {3, 0, 0}};
  const KdTree tree(pts);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  tree.nearest(Vec3(2.9, 0, 0), 10, idx, d2);
  ASSERT_EQ(idx.size(), 3u);
  EXPECT_EQ(idx, (std::vector<uint32_t>{2, 1, 0}));
  EXPECT_NEAR(d2[0], 0.01, 1e-12);
  EXPECT_NEAR(d2[1], 3.61, 1e-12);
  EXPECT_NEAR(d2[2], 8.41, 1e-12);
}

TEST(KdTree, AnEmptyTreeFindsNothing) {
  const std::vector<Vec3> pts;
  const KdTree tree(pts);
  std::vector<uint32_t> idx{7};
  std::vector<double> d2{1.0};
  tree.nearest(Vec3::Zero(), 4, idx, d2);
  EXPECT_TRUE(idx.empty());
  EXPECT_TRUE(d2.empty());
  idx = {7};
  d2 = {1.0};
  tree.withinRadius(Vec3::Zero(), 1.0, idx, d2);
  EXPECT_TRUE(idx.empty());
  EXPECT_TRUE(d2.empty());
}

TEST(KdTree, WithinRadiusCountsGridRingsExactly) {
  const int n = 10;
  const double h = 0.05;
  const std::vector<Vec3> pts = grid(n, h);
  const KdTree tree(pts);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  const Vec3 q = pts[at(n, 5, 5)];
  // Rings around an interior node: itself, 4 at h, 4 at √2·h, 4 at 2h, 8 at √5·h.
  tree.withinRadius(q, 0.99 * h, idx, d2);
  EXPECT_EQ(idx.size(), 1u);
  tree.withinRadius(q, 1.01 * h, idx, d2);
  EXPECT_EQ(idx.size(), 5u);
  tree.withinRadius(q, 1.5 * h, idx, d2);
  EXPECT_EQ(idx.size(), 9u);
  tree.withinRadius(q, 2.01 * h, idx, d2);
  EXPECT_EQ(idx.size(), 13u);
  tree.withinRadius(q, 2.3 * h, idx, d2);
  ASSERT_EQ(idx.size(), 21u);
  ASSERT_EQ(d2.size(), 21u);
  EXPECT_EQ(idx[0], at(n, 5, 5));
  EXPECT_TRUE(std::is_sorted(d2.begin(), d2.end()));
  for (size_t j = 0; j < idx.size(); ++j) EXPECT_NEAR(d2[j], (pts[idx[j]] - q).squaredNorm(), 1e-15);
  // A corner node has 3 points within 1.01 h: itself and two edge neighbours.
  tree.withinRadius(pts[at(n, 0, 0)], 1.01 * h, idx, d2);
  EXPECT_EQ(std::set<uint32_t>(idx.begin(), idx.end()), (std::set<uint32_t>{at(n, 0, 0), at(n, 1, 0), at(n, 0, 1)}));
}

TEST(NearestNeighbours, RowsMatchABruteForceSearch) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<Vec3> pts(500);
  for (Vec3& p : pts) p = Vec3(U(rng), U(rng), 0.3 * U(rng));
  const size_t k = 8;
  const NeighbourTable table = nearestNeighbours(pts, k);
  ASSERT_EQ(table.k, k);
  ASSERT_EQ(table.size(), pts.size());
  ASSERT_EQ(table.index.size(), pts.size() * k);
  ASSERT_EQ(table.dist2.size(), pts.size() * k);
  for (size_t i = 0; i < pts.size(); ++i) {
    std::vector<double> brute;
    for (const Vec3& q : pts) brute.push_back((q - pts[i]).squaredNorm());
    std::sort(brute.begin(), brute.end());
    EXPECT_EQ(table.row(i)[0], i);
    for (size_t j = 0; j < k; ++j) {
      // dist2 is stored as float: relative precision 2^-24.
      EXPECT_NEAR(table.rowDist2(i)[j], brute[j], 1e-6 * brute[j] + 1e-12) << "row " << i << " col " << j;
      EXPECT_NEAR(table.rowDist2(i)[j], (pts[table.row(i)[j]] - pts[i]).squaredNorm(), 1e-6 * brute[j] + 1e-12);
    }
  }
}

TEST(NearestNeighbours, DuplicatePointsStillListThemselvesFirst) {
  // Three coincident points and two others: each duplicate's row must start with itself.
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {2, 0, 0}};
  const NeighbourTable table = nearestNeighbours(pts, 3);
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_EQ(table.row(i)[0], i) << "row " << i;
    EXPECT_EQ(table.rowDist2(i)[0], 0.0f);
  }
  for (uint32_t i = 1; i <= 3; ++i) {
    const std::set<uint32_t> row(table.row(i), table.row(i) + 3);
    EXPECT_EQ(row, (std::set<uint32_t>{1, 2, 3}));
    EXPECT_EQ(table.rowDist2(i)[1], 0.0f);
    EXPECT_EQ(table.rowDist2(i)[2], 0.0f);
  }
}

TEST(NearestNeighbours, ReportsProgressUpToOne) {
  const std::vector<Vec3> pts = grid(20, 0.1);
  std::vector<double> fractions;
  Progress progress;
  progress.callback = [&](std::string_view stage, double f) {
    EXPECT_EQ(stage, "neighbours");
    fractions.push_back(f);
  };
  nearestNeighbours(pts, 4, progress);
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
}

TEST(NearestNeighbours, RejectsKZeroAndCloudsSmallerThanK) {
  const std::vector<Vec3> pts = grid(3, 0.1);
  expectInvalidInput([&] { nearestNeighbours(pts, 0); }, {"[nearestNeighbours]", "k must be >= 1"});
  expectInvalidInput([&] { nearestNeighbours(pts, 10); }, {"[nearestNeighbours]", "9 points", "k = 10"});
  expectInvalidInput([&] { nearestNeighbours({}, 1); }, {"[nearestNeighbours]", "0 points"});
  EXPECT_EQ(nearestNeighbours(pts, 9).size(), 9u);  // exactly k points is enough
}

TEST(MedianSpacing, IsTheGridSpacing) {
  const double h = 0.037;
  const NeighbourTable table = nearestNeighbours(grid(12, h), 5);
  // dist2 is a float: sqrt keeps ~1e-7 relative precision.
  EXPECT_NEAR(medianSpacing(table), h, 1e-7);
}

TEST(MedianSpacing, MatchesThePoissonNearestNeighbourDistance) {
  // Uniform random points at density ρ per m²: the nearest-neighbour distance has
  // median sqrt(ln 2 / (π ρ)) (Poisson process); 40000 samples keep the sample
  // median within ~1 % (edge effects add ~0.5 %).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.0, 2.0);
  std::vector<Vec3> pts(40000);
  for (Vec3& p : pts) p = Vec3(U(rng), U(rng), 0.0);
  const double rho = 40000.0 / 4.0;
  const double expected = std::sqrt(std::log(2.0) / (M_PI * rho));
  EXPECT_NEAR(medianSpacing(nearestNeighbours(pts, 2)), expected, 0.02 * expected);
}

TEST(MedianSpacing, IsZeroWithoutASecondColumnOrPoint) {
  EXPECT_EQ(medianSpacing(nearestNeighbours(grid(4, 0.1), 1)), 0.0);
  EXPECT_EQ(medianSpacing(nearestNeighbours({Vec3(1, 2, 3)}, 1)), 0.0);
  EXPECT_EQ(medianSpacing(NeighbourTable{}), 0.0);
}

}  // namespace
}  // namespace sailshape
