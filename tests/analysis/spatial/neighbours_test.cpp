#include "analysis/spatial/neighbours.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

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

// Brute-force k nearest of q: (squared distance, index), closest first, ties by index.
std::vector<std::pair<double, uint32_t>> bruteNearest(const std::vector<Vec3>& pts, const Vec3& q, size_t k) {
  std::vector<std::pair<double, uint32_t>> all;
  for (uint32_t j = 0; j < pts.size(); ++j) all.emplace_back((pts[j] - q).squaredNorm(), j);
  std::sort(all.begin(), all.end());
  all.resize(std::min(k, all.size()));
  return all;
}

// A noisy curved sheet (1.5 m × 1 m, bent 0.2 m deep, σ = 4 mm) plus a few far strays.
std::vector<Vec3> sheetWithStrays(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, kSigma);
  std::vector<Vec3> pts;
  for (size_t i = 0; i < n; ++i) {
    const double x = 1.5 * U(rng), y = U(rng);
    pts.emplace_back(x, y, 0.2 * std::sin(M_PI * x / 1.5) + N(rng));
  }
  pts.emplace_back(5.0, 5.0, 5.0);  // far from everything: many empty rings of cells
  pts.emplace_back(-3.0, 0.5, 0.0);
  return pts;
}

TEST(PointGrid, NearestMatchesABruteForceSearchAtAnyCellWidth) {
  const std::vector<Vec3> pts = sheetWithStrays(3000, 21);
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> U(-0.5, 2.0);
  // Cells far narrower and far wider than the neighbour distances: still exact.
  for (double cell : {0.004, 0.03, 0.5}) {
    const PointGrid g(pts, cell);
    EXPECT_DOUBLE_EQ(g.cellSize(), cell);
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    for (int t = 0; t < 200; ++t) {
      // Queries on cloud points, between them and outside the cloud's box.
      const Vec3 q = t % 3 == 0 ? pts[static_cast<size_t>(t) * 7] : Vec3(U(rng), U(rng), U(rng));
      for (size_t k : {size_t{1}, size_t{12}, size_t{60}}) {
        g.nearest(q, k, idx, d2);
        const auto expected = bruteNearest(pts, q, k);
        ASSERT_EQ(idx.size(), k);
        ASSERT_EQ(d2.size(), k);
        for (size_t j = 0; j < k; ++j) {
          EXPECT_EQ(idx[j], expected[j].second) << "cell " << cell << " query " << t << " k " << k << " col " << j;
          EXPECT_DOUBLE_EQ(d2[j], expected[j].first);
        }
      }
    }
    // The far stray's nearest neighbours come from the other end of the cloud.
    g.nearest(pts[pts.size() - 2], 3, idx, d2);
    EXPECT_EQ(idx[0], pts.size() - 2);
    EXPECT_EQ(idx[1], bruteNearest(pts, pts[pts.size() - 2], 2)[1].second);
  }
}

TEST(PointGrid, WithinRadiusFindsExactlyThePointsInTheBall) {
  const std::vector<Vec3> pts = sheetWithStrays(3000, 23);
  const PointGrid g(pts, 0.05);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  for (double r : {0.0, 0.02, 0.07, 0.3, 10.0}) {
    for (size_t t = 0; t < pts.size(); t += 97) {
      g.withinRadius(pts[t], r, idx, d2);
      std::set<uint32_t> expected;
      for (uint32_t j = 0; j < pts.size(); ++j)
        if ((pts[j] - pts[t]).squaredNorm() <= r * r) expected.insert(j);
      EXPECT_EQ(std::set<uint32_t>(idx.begin(), idx.end()), expected) << "radius " << r << " point " << t;
      ASSERT_EQ(idx.size(), d2.size());
      for (size_t j = 0; j < idx.size(); ++j) EXPECT_DOUBLE_EQ(d2[j], (pts[idx[j]] - pts[t]).squaredNorm());
    }
  }
  // Asked for, the coordinates come along, row for row.
  std::vector<Vec3> coords;
  g.withinRadius(pts[10], 0.07, idx, d2, &coords);
  ASSERT_EQ(coords.size(), idx.size());
  for (size_t j = 0; j < idx.size(); ++j) EXPECT_EQ(coords[j], pts[idx[j]]);
  // The same call gives the same order every time.
  std::vector<uint32_t> again;
  g.withinRadius(pts[10], 0.07, idx, d2);
  g.withinRadius(pts[10], 0.07, again, d2);
  EXPECT_EQ(idx, again);
}

TEST(PointGrid, CellsHoldEveryPointOnceNearTheirCentres) {
  const std::vector<Vec3> pts = sheetWithStrays(3000, 25);
  const double cell = 0.05;
  const PointGrid g(pts, cell);
  const std::vector<uint32_t>& start = g.cellStart();
  const std::vector<uint32_t>& held = g.cellPoints();
  ASSERT_EQ(start.size(), g.cellCount() + 1);
  EXPECT_EQ(start.front(), 0u);
  EXPECT_EQ(start.back(), pts.size());
  std::vector<int> seen(pts.size(), 0);
  for (size_t c = 0; c < g.cellCount(); ++c) {
    EXPECT_LT(start[c], start[c + 1]) << "cell " << c << " is listed but empty";
    const Vec3 centre = g.cellCentre(c);
    for (uint32_t s = start[c]; s < start[c + 1]; ++s) {
      ASSERT_LT(held[s], pts.size());
      ++seen[held[s]];
      EXPECT_LE((pts[held[s]] - centre).cwiseAbs().maxCoeff(), 0.5 * cell + 1e-12) << "point " << held[s];
    }
  }
  for (size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(seen[i], 1) << "point " << i;
  // No two cells share a centre.
  std::set<std::tuple<double, double, double>> centres;
  for (size_t c = 0; c < g.cellCount(); ++c) {
    const Vec3 m = g.cellCentre(c);
    centres.emplace(m.x(), m.y(), m.z());
  }
  EXPECT_EQ(centres.size(), g.cellCount());
}

TEST(PointGrid, ACellsNeighbourhoodHoldsWhatWithinRadiusReadsInItsOrder) {
  const std::vector<Vec3> pts = sheetWithStrays(3000, 26);
  const PointGrid g(pts, 0.05);
  std::vector<uint32_t> near, idx, expected;
  std::vector<Vec3> near_pts;
  std::vector<double> d2;
  // Radii within one ring, within several, and wide enough to read every cell.
  for (double r : {0.03, 0.12, 10.0})
    for (size_t c = 0; c < g.cellCount(); c += 7) {
      g.cellNeighbourhood(c, r, near, near_pts);
      ASSERT_EQ(near.size(), near_pts.size());
      for (size_t j = 0; j < near.size(); ++j) ASSERT_EQ(near_pts[j], pts[near[j]]);
      // Filtered by distance, it is withinRadius's answer for each point of the cell, in its order.
      for (uint32_t s = g.cellStart()[c]; s < g.cellStart()[c + 1]; ++s) {
        const Vec3& q = pts[g.cellPoints()[s]];
        g.withinRadius(q, r, idx, d2);
        expected.clear();
        for (size_t j = 0; j < near.size(); ++j)
          if ((near_pts[j] - q).squaredNorm() <= r * r) expected.push_back(near[j]);
        EXPECT_EQ(idx, expected) << "radius " << r << " cell " << c;
      }
    }
}

TEST(PointGrid, TableMatchesTheKdTreeOnANoisySheet) {
  const std::vector<Vec3> pts = sheetWithStrays(20000, 24);
  const KdTree tree(pts);
  const size_t k = 21;
  const NeighbourTable table = nearestNeighbours(pts, k);
  ASSERT_EQ(table.size(), pts.size());
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  for (size_t i = 0; i < pts.size(); ++i) {
    tree.nearest(pts[i], k, idx, d2);
    ASSERT_EQ(table.row(i)[0], i);
    for (size_t j = 0; j < k; ++j)
      ASSERT_EQ(table.rowDist2(i)[j], static_cast<float>(d2[j])) << "row " << i << " col " << j;
  }
}

TEST(PointGrid, GridForNeighboursSizesCellsByTheKthNeighbourDistance) {
  // Uniform points at ρ per m²: the k-th point (itself first) is the (k-1)-th other one,
  // so π ρ r² follows Gamma(k - 1, 1), whose median is about k - 4/3; the cell is 1.5 ×
  // the sampled median distance (64 samples and edge effects: ±15 %).
  std::mt19937 rng(25);
  std::uniform_real_distribution<double> U(0.0, 2.0);
  std::vector<Vec3> pts(40000);
  for (Vec3& p : pts) p = Vec3(U(rng), U(rng), 0.0);
  for (size_t k : {size_t{5}, size_t{30}, size_t{200}}) {
    const double expected = 1.5 * std::sqrt((static_cast<double>(k) - 4.0 / 3.0) / (M_PI * 10000.0));
    EXPECT_NEAR(gridForNeighbours(pts, k)->cellSize(), expected, 0.15 * expected) << "k " << k;
  }
}

TEST(PointGrid, RejectsANonPositiveCellAndBadTableRequests) {
  const std::vector<Vec3> pts = grid(4, 0.1);
  for (double cell : {0.0, -1.0, std::nan("")})
    expectInvalidInput([&] { PointGrid g(pts, cell); }, {"[PointGrid]", "cell_m must be > 0"});
  const PointGrid g(pts, 0.1);
  NeighbourTable table;
  expectInvalidInput([&] { g.fillTable(table, 0, {}); }, {"[PointGrid::fillTable]", "k = 0"});
  expectInvalidInput([&] { g.fillTable(table, 17, {}); }, {"[PointGrid::fillTable]", "k = 17", "16 points"});
  // An empty grid answers nothing.
  const std::vector<Vec3> none;
  const PointGrid empty(none, 0.1);
  std::vector<uint32_t> idx{1};
  std::vector<double> d2{1.0};
  empty.nearest(Vec3::Zero(), 3, idx, d2);
  EXPECT_TRUE(idx.empty());
  empty.withinRadius(Vec3::Zero(), 1.0, idx, d2);
  EXPECT_TRUE(idx.empty());
}

TEST(SubsetTable, MatchesATableBuiltOnTheSubCloud) {
  const std::vector<Vec3> pts = sheetWithStrays(5000, 26);
  const NeighbourTable full = nearestNeighbours(pts, 12);
  // Drop every third point and a solid patch, so some rows run out of kept neighbours.
  std::vector<uint32_t> kept;
  std::vector<Vec3> sub_pts;
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const bool patch = pts[i].x() > 0.5 && pts[i].x() < 0.55;
    if (i % 3 == 0 || patch) continue;
    kept.push_back(i);
    sub_pts.push_back(pts[i]);
  }
  const NeighbourTable sub = subsetTable(full, pts, kept, 6);
  const NeighbourTable direct = nearestNeighbours(sub_pts, 6);
  ASSERT_EQ(sub.k, 6u);
  EXPECT_EQ(sub.index, direct.index);
  EXPECT_EQ(sub.dist2, direct.dist2);

  expectInvalidInput([&] { subsetTable(full, pts, kept, 13); }, {"[subsetTable]", "k = 13", "12 columns"});
  expectInvalidInput([&] { subsetTable(full, sub_pts, kept, 6); }, {"[subsetTable]", "rows for"});
  expectInvalidInput([&] { subsetTable(full, pts, {5, 3}, 1); }, {"[subsetTable]", "ascending", "got 3"});
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

// The yes-or-no against the median itself: false at the median (not below it),
// true just above; on a noisy sheet of random points (a scan's spacing spread), one
// with exact duplicates (distance 0) and a regular grid (every distance tied).
TEST(MedianNeighbourDistanceBelow, AgreesWithTheMedianAtAndAroundIt) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.5);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<Vec3> sheet(20000);
  for (Vec3& p : sheet) p = Vec3(U(rng), U(rng), noise(rng));
  std::vector<Vec3> doubled(sheet.begin(), sheet.begin() + 3000);
  for (size_t i = 0; i < 600; ++i) doubled.push_back(doubled[i * 5]);  // a third of the points: 0 apart
  for (const std::vector<Vec3>* pts : {&sheet, &doubled}) {
    for (size_t samples : {size_t{512}, size_t{97}}) {
      const double median = medianNeighbourDistance(PointGrid(*pts, 0.05), *pts, 2, samples);
      ASSERT_GT(median, 0.0);
      EXPECT_FALSE(medianNeighbourDistanceBelow(*pts, median, samples));
      EXPECT_TRUE(medianNeighbourDistanceBelow(*pts, std::nextafter(median, 1.0), samples));
      for (double f : {0.3, 0.9, 1.1, 3.0})
        EXPECT_EQ(medianNeighbourDistanceBelow(*pts, f * median, samples), f > 1) << f << " " << samples;
    }
  }
  // More than half the sample duplicated: the median is 0, below any positive limit.
  std::vector<Vec3> twice = grid(20, 0.1);
  twice.insert(twice.end(), twice.begin(), twice.end());
  EXPECT_TRUE(medianNeighbourDistanceBelow(twice, 1e-9));
  // Every nearest distance is the spacing h on a grid (to rounding: many near-ties).
  const std::vector<Vec3> g = grid(30, 0.02);
  const double h = medianNeighbourDistance(PointGrid(g, 0.05), g, 2);
  EXPECT_NEAR(h, 0.02, 1e-12);
  EXPECT_FALSE(medianNeighbourDistanceBelow(g, h));
  EXPECT_TRUE(medianNeighbourDistanceBelow(g, std::nextafter(h, 1.0)));
  // Fewer than two points: the median distance is 0.
  EXPECT_TRUE(medianNeighbourDistanceBelow({Vec3(1, 2, 3)}, 0.01));
  EXPECT_FALSE(medianNeighbourDistanceBelow(g, 0.0));
  EXPECT_FALSE(medianNeighbourDistanceBelow(g, -1.0));
}

TEST(VoxelKey, EveryCellAroundTheOriginHasItsOwnKey) {
  // The boat frame's origin is the mast foot: sail, mast and boom all lie within a
  // few hundred cells of it on either side. An XOR-mixing hash gave (12, −4, 231)
  // and (−12, 4, 231) one key, so segmentation's voxel of mast samples joined a
  // sail voxel across the mast. Every cell of a 61³ block around the origin, and
  // cells at the packing's ±2^20 limits, keep distinct keys.
  std::set<int64_t> keys;
  size_t cells = 0;
  for (int x = -30; x <= 30; ++x)
    for (int y = -30; y <= 30; ++y)
      for (int z = -30; z <= 30; ++z, ++cells) keys.insert(voxelKey(Eigen::Vector3i(x, y, z)));
  EXPECT_EQ(keys.size(), cells);
  EXPECT_NE(voxelKey(Eigen::Vector3i(12, -4, 231)), voxelKey(Eigen::Vector3i(-12, 4, 231)));
  const int lim = 1 << 20;
  std::set<std::tuple<int, int, int>> edge_cells;
  std::set<int64_t> edge_keys;
  for (int a : {-lim, -lim + 1, -1, 0, 1, lim - 1})
    for (int b : {-lim, 0, lim - 1})
      for (const Eigen::Vector3i& c : {Eigen::Vector3i(a, b, 0), Eigen::Vector3i(0, a, b), Eigen::Vector3i(b, 0, a)}) {
        edge_cells.insert({c.x(), c.y(), c.z()});
        edge_keys.insert(voxelKey(c));
      }
  EXPECT_EQ(edge_keys.size(), edge_cells.size());
  // The key is the cell's: points in one cell share it, a point a cell away does not.
  EXPECT_EQ(voxelKey(Vec3(0.011, -0.019, 4.62), 0.02), voxelKey(Vec3(0.019, -0.001, 4.6399), 0.02));
  EXPECT_NE(voxelKey(Vec3(0.011, -0.019, 4.62), 0.02), voxelKey(Vec3(-0.011, 0.019, 4.62), 0.02));
}

TEST(KeyIds, NumbersKeysInTheOrderFirstSeenAndKeepsThemWhileGrowing) {
  // Starts small (16 slots) and grows many times over 10,000 keys, negative and
  // colliding-prone (multiples of a large power of two) among them.
  KeyIds ids(1);
  std::vector<int64_t> keys;
  for (int64_t i = 0; i < 10000; ++i) keys.push_back((i % 2 ? -1 : 1) * (i << 40) + i);
  for (size_t i = 0; i < keys.size(); ++i) {
    EXPECT_EQ(ids.idOf(keys[i]), i);
    EXPECT_EQ(ids.size(), i + 1);
  }
  for (size_t i = 0; i < keys.size(); i += 7) EXPECT_EQ(ids.idOf(keys[i]), i);
  EXPECT_EQ(ids.size(), keys.size());
  // find gives the same ids and adds nothing.
  for (size_t i = 0; i < keys.size(); i += 13) {
    uint32_t id = 0;
    ASSERT_TRUE(ids.find(keys[i], id));
    EXPECT_EQ(id, i);
  }
  uint32_t none = 7;
  EXPECT_FALSE(ids.find(int64_t{1} << 62, none));
  EXPECT_EQ(none, 7u);
  EXPECT_EQ(ids.size(), keys.size());
  // The voxel keys of points in the same cube share an id.
  KeyIds voxels;
  const uint32_t a = voxels.idOf(voxelKey(Vec3(0.01, 0.02, 0.03), 0.1));
  EXPECT_EQ(voxels.idOf(voxelKey(Vec3(0.09, 0.08, 0.07), 0.1)), a);
  EXPECT_EQ(voxels.idOf(voxelKey(Vec3(0.11, 0.02, 0.03), 0.1)), a + 1);
}

TEST(VoxelMeans, AveragesEachVoxelsPointsAndAttributesInTheOrderFirstMet) {
  // Cubes 0.1 m wide: three points in [0, 0.1)³, one in the cube above, one more
  // back in the first, and one in the cube to -x (floor, not truncation, at 0).
  Cloud c;
  c.points = {Vec3(0.01, 0.02, 0.03), Vec3(0.05, 0.06, 0.07), Vec3(0.02, 0.04, 0.05), Vec3(0.05, 0.05, 0.15),
              Vec3(0.09, 0.08, 0.01), Vec3(-0.01, 0.05, 0.05)};
  c.intensity = {10, 20, 30, 40, 60, 70};
  c.alpha_rad = {0.1, 0.2, 0.3, 0.4, 0.6, 0.7};
  c.beta_rad = {-1, -2, -3, -4, -6, -7};
  c.viewpoint = Vec3(5, 0, 1);
  const VoxelMeans m = voxelMeans(c, 0.1);
  ASSERT_EQ(m.cloud.size(), 3u);
  EXPECT_EQ(m.count, (std::vector<uint32_t>{4, 1, 1}));
  EXPECT_EQ(m.voxel_of, (std::vector<uint32_t>{0, 0, 0, 1, 0, 2}));
  EXPECT_LT((m.cloud.points[0] - Vec3(0.0425, 0.05, 0.04)).norm(), 1e-15);
  EXPECT_EQ(m.cloud.points[1], c.points[3]);
  EXPECT_EQ(m.cloud.points[2], c.points[5]);
  EXPECT_FLOAT_EQ(m.cloud.intensity[0], 30.0f);
  EXPECT_NEAR(m.cloud.alpha_rad[0], 0.3, 1e-15);
  EXPECT_NEAR(m.cloud.beta_rad[0], -3.0, 1e-15);
  EXPECT_FLOAT_EQ(m.cloud.intensity[2], 70.0f);
  EXPECT_EQ(m.cloud.viewpoint, c.viewpoint);
  // No attributes in, none out.
  Cloud bare;
  bare.points = c.points;
  const VoxelMeans b = voxelMeans(bare, 0.1);
  EXPECT_EQ(b.cloud.points, m.cloud.points);
  EXPECT_TRUE(b.cloud.intensity.empty());
  EXPECT_FALSE(b.cloud.hasScanAngles());
  EXPECT_TRUE(voxelMeans(Cloud{}, 0.1).cloud.empty());
}

TEST(VoxelMeans, RejectsABadVoxelAndAnAttributeOfTheWrongLength) {
  Cloud c;
  c.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  for (double bad : {0.0, -0.1, std::numeric_limits<double>::infinity(), std::nan("")}) {
    try {
      voxelMeans(c, bad);
      ADD_FAILURE() << "voxel " << bad << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("[voxelMeans] voxel must be > 0 and finite"), std::string::npos) << e.what();
    }
  }
  c.intensity = {1.0f};
  try {
    voxelMeans(c, 0.1);
    ADD_FAILURE() << "a short intensity was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[voxelMeans] an attribute has 1 values for 2 points");
  }
}

// A plane through `origin` spanned by unit u and v, sampled on a jittered grid
// `spacing` apart over size × size, with Gaussian noise `sigma` along its normal.
Cloud noisyPlane(const Vec3& origin, const Vec3& u, const Vec3& v, double size, double spacing, double sigma,
                 unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(0, spacing);
  std::normal_distribution<double> noise(0, sigma);
  const Vec3 n = u.cross(v).normalized();
  Cloud c;
  for (double a = 0; a < size; a += spacing)
    for (double b = 0; b < size; b += spacing) c.points.push_back(origin + (a + jitter(rng)) * u + (b + jitter(rng)) * v + noise(rng) * n);
  return c;
}

// RMS distance of `points` from the plane through `origin` with normal n.
double rmsOffPlane(const std::vector<Vec3>& points, const Vec3& origin, const Vec3& n) {
  double ss = 0;
  for (const Vec3& x : points) ss += std::pow(n.dot(x - origin), 2);
  return std::sqrt(ss / static_cast<double>(points.size()));
}

TEST(ColumnMeans, AveragesTheWholeNoiseBandWhereCubeVoxelsCutItApart) {
  // A 1 m plane with 4 mm noise, 25 samples per 2 cm column, lying on a face of the
  // 2 cm cube grid (z = 0). A cube voxel then holds the samples on one side of the
  // plane only, and its mean lies E|N(0, σ)| = 0.8σ off it; a column holds all 25 and
  // its mean lies σ/5 off (RMS). Over 2,500 columns that RMS is known to about 1.5 %,
  // and the bound allows 10 %.
  const double sigma = 0.004;
  const Vec3 origin(0, 0, 0), u(1, 0, 0), v(0, 1, 0), n(0, 0, 1);
  const Cloud c = noisyPlane(origin, u, v, 1.0, 0.004, sigma, 11);
  Eigen::Matrix3d axes;
  axes << n, v, u;
  const VoxelMeans columns = columnMeans(c, axes, 0.02, 0.05);
  const VoxelMeans cubes = voxelMeans(c, 0.02);
  EXPECT_EQ(columns.cloud.size(), 2500u);
  EXPECT_LT(rmsOffPlane(columns.cloud.points, origin, n), 0.2 * sigma * 1.1);
  EXPECT_GT(rmsOffPlane(cubes.cloud.points, origin, n), 0.75 * sigma);
  // Every sample in one column, each column's count summed back to the cloud.
  uint32_t total = 0;
  for (uint32_t k : columns.count) total += k;
  EXPECT_EQ(total, c.size());
}

TEST(ColumnMeans, StandsOnAnyPlaneAndKeepsEverySampleOfADeepColumn) {
  // Two parallel sheets 10 cm apart on a tilted plane, the upper one half as wide:
  // where they lie over one another a column's samples are 10 cm apart along the
  // normal, more than the 5 cm allowed, and every one stays a point of its own; the
  // lower sheet's other half is merged, one point per column.
  const Vec3 u = Vec3(1, 0, 0.5).normalized(), v = Vec3(0, 1, 0);
  const Vec3 n = u.cross(v).normalized();
  const Vec3 origin(2, -3, 1);
  Cloud c = noisyPlane(origin, u, v, 0.4, 0.005, 0, 3);
  const size_t lower = c.size();
  const Cloud upper = noisyPlane(origin + 0.1 * n, u, v, 0.2, 0.005, 0, 4);
  c.points.insert(c.points.end(), upper.points.begin(), upper.points.end());
  Eigen::Matrix3d axes;
  axes << n, v, u;
  const VoxelMeans m = columnMeans(c, axes, 0.02, 0.05);
  size_t single = 0;
  for (size_t i = 0; i < c.size(); ++i) {
    const uint32_t cell = m.voxel_of[i];
    // Any point of the upper sheet, and a lower point under it, is its own cell.
    if (i >= lower) EXPECT_EQ(m.count[cell], 1u) << i;
    single += m.count[cell] == 1 ? 1 : 0;
  }
  // The lower sheet's samples under the upper one (a quarter of them, to within the
  // columns the upper sheet's edge crosses) are kept too.
  EXPECT_GE(single, upper.size() + lower / 4 - 400);
  // The merged columns are the lower sheet's other 300 or so 2 cm squares.
  const size_t merged = m.cloud.size() - single;
  EXPECT_GT(merged, 280u);
  EXPECT_LT(merged, 420u);
  for (size_t cell = 0; cell < m.cloud.size(); ++cell)
    if (m.count[cell] > 1) EXPECT_LT(std::abs(n.dot(m.cloud.points[cell] - origin)), 1e-12);
}

TEST(ColumnMeans, RejectsBadSizesAndAnAttributeOfTheWrongLength) {
  Cloud c;
  c.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  const double inf = std::numeric_limits<double>::infinity();
  for (auto [across, depth] : {std::pair{0.0, 0.05}, {-0.02, 0.05}, {inf, 0.05}, {std::nan(""), 0.05}, {0.02, -0.01},
                               {0.02, inf}, {0.02, std::nan("")}}) {
    try {
      columnMeans(c, axes, across, depth);
      ADD_FAILURE() << across << ", " << depth << " accepted";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("[columnMeans] need a column width > 0 and a depth >= 0"), std::string::npos)
          << e.what();
    }
  }
  c.alpha_rad = {0.1};
  try {
    columnMeans(c, axes, 0.02, 0.05);
    ADD_FAILURE() << "a short alpha was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[columnMeans] an attribute has 1 values for 2 points");
  }
}

// The binned selection against a plain sort by (distance², slot), on squared
// distances spread evenly, crowded into a few values (exact ties across the bin
// holding the k-th) and beyond the limit.
TEST(SelectNearest, PicksTheKNearestByDistanceThenSlot) {
  std::mt19937_64 rng(7);
  std::vector<uint8_t> bin;
  std::vector<uint32_t> part, out;
  std::vector<double> part_d2;
  for (int trial = 0; trial < 300; ++trial) {
    const size_t m = 1 + rng() % 2000;
    const bool ties = trial % 3 == 0;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> d2(m);
    for (double& d : d2) d = ties ? std::floor(u(rng) * 7.0) / 6.0 : 1.2 * u(rng);
    const double limit2 = trial % 5 == 0 ? 2.0 : u(rng);
    const size_t k = 1 + rng() % m;
    std::vector<std::pair<double, uint32_t>> within;
    for (uint32_t j = 0; j < m; ++j)
      if (d2[j] <= limit2) within.emplace_back(d2[j], j);
    std::sort(within.begin(), within.end());
    const double kth = selectNearest(d2, limit2, k, bin, part, part_d2, out);
    SCOPED_TRACE("trial " + std::to_string(trial) + ", m " + std::to_string(m) + ", k " + std::to_string(k));
    if (within.size() < k) {
      EXPECT_EQ(kth, -1.0);
      continue;
    }
    EXPECT_EQ(kth, within[k - 1].first);
    std::vector<uint32_t> expected;
    for (size_t i = 0; i < k; ++i) expected.push_back(within[i].second);
    std::sort(expected.begin(), expected.end());
    std::vector<uint32_t> got = out;
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected);
  }
  EXPECT_EQ(selectNearest({0.5, 0.1}, 1.0, 0, bin, part, part_d2, out), 0.0);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace sailshape
