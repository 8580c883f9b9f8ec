// ICP refinement, the crossed filter and the distance distribution.
#include "analysis/registration/icp.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// Three faces of a box corner (floor and two walls), 2 m each, jittered grid
// at `spacing`, with range noise `noise` along the normal.
Cloud boxCorner(double spacing, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> J(-0.5, 0.5);
  std::normal_distribution<double> N(0, 1);
  Cloud c;
  const int n = static_cast<int>(2.0 / spacing);
  for (int face = 0; face < 3; ++face)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double u = (i + 0.5 + J(rng)) * spacing, v = (j + 0.5 + J(rng)) * spacing, w = noise * N(rng);
        c.points.push_back(face == 0 ? Vec3(u, v, w) : face == 1 ? Vec3(u, w, v) : Vec3(w, u, v));
      }
  return c;
}

RigidTransform smallMotion() {
  RigidTransform t = RigidTransform::Identity();
  t.linear() = Eigen::AngleAxisd(1.5 * kRadPerDeg, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  t.translation() = Vec3(0.02, -0.015, 0.01);
  return t;
}

TEST(Icp, PointToPlaneRecoversASmallMotionOnABoxCorner) {
  // Two independent samplings of the same corner (different seeds), 4 mm
  // noise: with ~4800 points per face the pose is good to well under σ.
  const Cloud reference = boxCorner(0.03, kSigma, 1);
  const RigidTransform truth = smallMotion();
  const Cloud moving = transformCloud(boxCorner(0.03, kSigma, 2), truth.inverse());
  const IcpResult r = refineIcp(reference, moving, RigidTransform::Identity());
  EXPECT_TRUE(r.converged);
  EXPECT_LT(rotationDifferenceDeg(r.transform.linear(), truth.linear()), 0.05);
  EXPECT_LT((r.transform.translation() - truth.translation()).norm(), 0.001);
  EXPECT_NEAR(r.rms_m, kSigma * std::sqrt(2.0), kSigma);  // two noisy samplings, residual along the normal
}

TEST(Icp, PointToPointAlsoConvergesOnDenseExactData) {
  const Cloud reference = boxCorner(0.02, 0, 1);
  const RigidTransform truth = smallMotion();
  const Cloud moving = transformCloud(reference, truth.inverse());  // the same points: exact correspondences exist
  IcpParams p;
  p.method = "point-to-point";
  p.max_iterations = 200;
  p.max_correspondence_m = 0.1;
  const IcpResult r = refineIcp(reference, moving, RigidTransform::Identity(), p);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(rotationDifferenceDeg(r.transform.linear(), truth.linear()), 0.001);
  EXPECT_LT((r.transform.translation() - truth.translation()).norm(), 1e-4);
}

TEST(Icp, PlaneAnchorsHoldWhatTheOverlapCannot) {
  // Overlap: a single floor patch leaves sliding free; ICP must stop and say so
  // rather than wander. With the two walls as anchors it is fully constrained.
  const Cloud corner = boxCorner(0.04, 0, 3);
  std::vector<uint32_t> floor_idx;
  for (uint32_t i = 0; i < corner.size(); ++i)
    if (corner.points[i].z() == 0) floor_idx.push_back(i);
  const Cloud floor = selectPoints(corner, floor_idx);
  const IcpResult sliding = refineIcp(floor, floor, RigidTransform::Identity());
  EXPECT_FALSE(sliding.converged);
  ASSERT_FALSE(sliding.warnings.empty());
  EXPECT_NE(sliding.warnings[0].find("six degrees of freedom"), std::string::npos) << sliding.warnings[0];

  RigidTransform truth = RigidTransform::Identity();
  truth.translation() = Vec3(0.01, 0.02, 0.0);  // in-plane: invisible to the floor alone
  std::vector<PlaneAnchor> anchors;
  for (int axis : {0, 1}) {
    PlaneAnchor a;
    a.normal = Vec3::Unit(axis);
    a.offset_m = 0;
    for (const Vec3& p : corner.points)
      if (p(axis) == 0) a.moving_points.push_back(truth.inverse() * p);
    anchors.push_back(a);
  }
  const Cloud moving_floor = transformCloud(floor, truth.inverse());
  const IcpResult held = refineIcp(floor, moving_floor, RigidTransform::Identity(), {}, {}, anchors);
  EXPECT_TRUE(held.converged);
  EXPECT_LT((held.transform.translation() - truth.translation()).norm(), 1e-5);
  IcpParams pp;
  pp.method = "point-to-point";
  expectInvalidInput([&] { refineIcp(floor, moving_floor, RigidTransform::Identity(), pp, {}, anchors); },
                     {"refineIcp", "anchors", "point-to-plane"});
}

TEST(Icp, TooFewCorrespondencesIsAResultNotAnError) {
  const Cloud reference = boxCorner(0.05, 0, 1);
  RigidTransform far = RigidTransform::Identity();
  far.translation() = Vec3(10, 0, 0);
  const IcpResult r = refineIcp(reference, reference, far);
  EXPECT_FALSE(r.converged);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("correspondences"), std::string::npos) << r.warnings[0];
}

TEST(Icp, BadParametersAreRejected) {
  const Cloud c = boxCorner(0.1, 0, 1);
  auto with = [&](auto change, std::vector<std::string> parts) {
    IcpParams p;
    change(p);
    expectInvalidInput([&] { refineIcp(c, c, RigidTransform::Identity(), p); }, parts);
  };
  with([](IcpParams& p) { p.method = "point-to-line"; }, {"refineIcp", "method", "point-to-line"});
  with([](IcpParams& p) { p.max_iterations = 0; }, {"refineIcp", "max_iterations", "got 0"});
  with([](IcpParams& p) { p.max_correspondence_m = -1; }, {"refineIcp", "max_correspondence_m"});
  with([](IcpParams& p) { p.normal_k = 2; }, {"refineIcp", "normal_k", "got 2"});
  with([](IcpParams& p) { p.min_correspondences = 3; }, {"refineIcp", "min_correspondences", "got 3"});
  Cloud tiny;
  tiny.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  expectInvalidInput([&] { refineIcp(tiny, c, RigidTransform::Identity()); }, {"refineIcp", "at least"});
}

TEST(CrossedFilter, KeepsOnlyPointsWithANeighbourFromTheOtherCloud) {
  Cloud a, b;
  a.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(5, 0, 0)};
  b.points = {Vec3(0.03, 0, 0), Vec3(1, 0.04, 0), Vec3(-5, 0, 0), Vec3(1.0, 0.0, 0.06)};
  const CrossedFilter f = crossedFilter(a, b, 0.05);
  EXPECT_EQ(f.reference, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(f.moving, (std::vector<uint32_t>{0, 1}));
  EXPECT_TRUE(crossedFilter(a, Cloud{}, 0.05).moving.empty());
  expectInvalidInput([&] { crossedFilter(a, b, 0); }, {"crossedFilter", "radius_m"});
}

TEST(NeighbourDistanceStats, SummarisesNearestDistances) {
  Cloud ref, mov;
  ref.points = {Vec3(0, 0, 0)};
  double sum2 = 0;
  for (int i = 1; i <= 10; ++i) {
    const double d = 0.002 * i + 0.0005;  // 2.5, 4.5, ..., 20.5 mm: none on a bin edge
    mov.points.push_back(Vec3(d, 0, 0));
    sum2 += d * d;
  }
  const NeighbourDistanceStats s = nearestDistanceStats(ref, mov, 0.005, 4);
  EXPECT_EQ(s.count, 10u);
  EXPECT_NEAR(s.mean_m, 0.0115, 1e-12);
  EXPECT_NEAR(s.max_m, 0.0205, 1e-12);
  EXPECT_NEAR(s.median_m, 0.0125, 1e-12);
  EXPECT_NEAR(s.rms_m, std::sqrt(sum2 / 10), 1e-12);
  // Bins of 5 mm: [0,5): 2.5, 4.5; [5,10): 6.5, 8.5; [10,15): 10.5, 12.5, 14.5; [15,∞): the rest.
  EXPECT_EQ(s.histogram, (std::vector<size_t>{2, 2, 3, 3}));
  expectInvalidInput([&] { nearestDistanceStats(Cloud{}, mov); }, {"nearestDistanceStats", "both clouds"});
  expectInvalidInput([&] { nearestDistanceStats(ref, mov, 0); }, {"nearestDistanceStats", "bin_m"});
}

}  // namespace
}  // namespace sailshape
