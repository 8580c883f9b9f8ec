// Registration of two units' clouds (SPEC §4 step 2, issue 5) on the synthetic
// two-unit wind-tunnel scene: the plane method against the known transform
// (90° about X, 1 m along each axis), plain ICP failing from the raw pose,
// picked pairs, and the degenerate inputs that must fail loudly.
#include "analysis/registration/registration.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/fixtures.hpp"
#include "tests/support/tunnel_scene.hpp"

namespace sailshape {
namespace {

double rotationErrorDeg(const Registration& r, const RigidTransform& truth) {
  return rotationDifferenceDeg(r.rotation, truth.linear());
}
double translationError(const Registration& r, const RigidTransform& truth) {
  return (r.translation - truth.translation()).norm();
}

const TunnelScene& scene(double noise) {
  static const TunnelScene exact = makeTunnelScene({});
  static const TunnelScene noisy = [] {
    TunnelSceneParams p;
    p.noise_sigma_m = kSigma;
    return makeTunnelScene(p);
  }();
  return noise > 0 ? noisy : exact;
}

// A cloud holding only the given axis-aligned rectangles (as planes the
// detector will find), sampled on a grid with a little jitter, viewpoint at the origin.
Cloud planesCloud(const std::vector<std::array<Vec3, 3>>& rects, double spacing = 0.05) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> J(-0.2, 0.2);
  Cloud c;
  for (const auto& r : rects) {
    const int nu = static_cast<int>(r[1].norm() / spacing), nv = static_cast<int>(r[2].norm() / spacing);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j)
        c.points.push_back(r[0] + (i + 0.5 + J(rng)) / nu * r[1] + (j + 0.5 + J(rng)) / nv * r[2]);
  }
  c.viewpoint = Vec3(0.3, 0.2, 1.0);
  return c;
}

TEST(TunnelScene, IsTwoPoorlyOverlappingUnitsWithTheStudyTransform) {
  const TunnelScene& s = scene(0);
  EXPECT_GT(s.reference.size(), 15000u);
  EXPECT_LT(s.reference.size(), 40000u);
  EXPECT_GT(s.moving.size(), 15000u);
  // In the reference frame the moving unit stands on the port side, the reference unit on starboard.
  const Vec3 b_in_a = s.truth * *s.moving.viewpoint;
  EXPECT_GT(b_in_a.y(), 1.0);
  EXPECT_LT(s.reference.viewpoint->y(), -1.0);
  EXPECT_LT(rotationDifferenceDeg(s.truth.linear(), Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix()), 1e-12);
  // Poor overlap: well under half of the moving points have a reference point within 5 cm.
  const CrossedFilter cf = crossedFilter(s.reference, transformCloud(s.moving, s.truth), 0.05);
  EXPECT_LT(cf.moving.size(), s.moving.size() / 2);
  EXPECT_GT(cf.moving.size(), s.moving.size() / 10);
  expectInvalidInput([] {
    TunnelSceneParams p;
    p.noise_sigma_m = -1;
    makeTunnelScene(p);
  }, {"makeTunnelScene", "noise_sigma_m"});
  expectInvalidInput([] {
    TunnelSceneParams p;
    p.cube_density_per_m2 = 0;
    makeTunnelScene(p);
  }, {"makeTunnelScene", "densities"});
  expectInvalidInput([] {
    TunnelSceneParams p;
    p.sail_points = 0;
    makeTunnelScene(p);
  }, {"makeTunnelScene", "sail_points"});
}

TEST(PlaneRegistration, NoiseFreeSceneIsRecoveredExactly) {
  // Issue 5: rotation error < 0.01°, translation error < 0.1 mm without noise.
  const TunnelScene& s = scene(0);
  const Registration r = registerClouds(s.reference, s.moving);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.01);
  EXPECT_LT(translationError(r, s.truth), 1e-4);
  EXPECT_TRUE(r.accepted);
  EXPECT_TRUE(r.below_uncertainty);
  EXPECT_TRUE(r.converged);
  EXPECT_FALSE(r.ambiguous);
  // Every plane the pose lands is paired: at least the three that fix it.
  ASSERT_GE(r.pairings.size(), 3u);
  EXPECT_EQ(r.pairings.size(), r.coarse_planes_on);
  for (const PlanePairing& pp : r.pairings) EXPECT_LT(pp.angle_after_deg, 0.01);
  // The coarse plane alignment alone is already exact on exact planes.
  EXPECT_LT(rotationDifferenceDeg(r.coarse.linear(), s.truth.linear()), 0.01);
  EXPECT_LT((r.coarse.translation() - s.truth.translation()).norm(), 1e-4);
  // The 4×4 is the rotation and translation.
  EXPECT_LT((r.transform.matrix().topLeftCorner<3, 3>() - r.rotation).norm(), 1e-15);
  EXPECT_GT(r.overlap_moving_points, 1000u);
  EXPECT_EQ(r.before_refinement.count, r.overlap_moving_points);
  EXPECT_EQ(r.after_refinement.count, r.overlap_moving_points);
}

TEST(PlaneRegistration, FourMillimetreNoiseStaysWithinTheIssueTolerances) {
  // Issue 5 with SPEC §3's σ = 4 mm: < 0.05° and < 2 mm; the fitness of two
  // noisy clouds is about σ·√(1 + 1/k) on the overlap, under the 9 mm uncertainty.
  const TunnelScene& s = scene(kSigma);
  const Registration r = registerClouds(s.reference, s.moving);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.05);
  EXPECT_LT(translationError(r, s.truth), 0.002);
  EXPECT_TRUE(r.accepted);
  EXPECT_GT(r.fitness_rms_m, 0.5 * kSigma);
  EXPECT_LT(r.fitness_rms_m, 0.009);
  EXPECT_GT(r.inlier_fraction, 0.9);
  // Refinement did not make the overlap worse.
  EXPECT_LE(r.after_refinement.median_m, r.before_refinement.median_m + 1e-4);
}

TEST(PlaneRegistration, HoldsOverOtherNoiseSeeds) {
  for (uint64_t seed : {2u, 3u}) {
    TunnelSceneParams p;
    p.noise_sigma_m = kSigma;
    p.seed = seed;
    const TunnelScene s = makeTunnelScene(p);
    const Registration r = registerClouds(s.reference, s.moving);
    EXPECT_LT(rotationErrorDeg(r, s.truth), 0.05) << "seed " << seed;
    EXPECT_LT(translationError(r, s.truth), 0.002) << "seed " << seed;
    EXPECT_TRUE(r.accepted) << "seed " << seed;
  }
}

TEST(PlainIcp, FailsFromTheRawPoseWhereThePlaneMethodSucceeds) {
  // The study's motivation (§5.3.2): ICP from the raw poses of two poorly
  // overlapping units converges to a wrong minimum — and must say so.
  const TunnelScene& s = scene(kSigma);
  RegistrationParams p;
  p.method = "icp";
  const Registration icp = registerClouds(s.reference, s.moving, p);
  EXPECT_GT(rotationErrorDeg(icp, s.truth), 10.0);
  EXPECT_FALSE(icp.accepted);
  EXPECT_FALSE(icp.warnings.empty());
  const Registration planes = registerClouds(s.reference, s.moving);
  EXPECT_LT(rotationErrorDeg(planes, s.truth), 0.05);
  EXPECT_TRUE(planes.accepted);
}

TEST(SvdRegistration, PickedCornersThenRefinement) {
  // Five picked points (chamber corners, the cube's top corner), picked with
  // 1 cm errors as a user would; the ICP refinement on the overlap brings the
  // result within a few millimetres.
  const TunnelScene& s = scene(kSigma);
  const std::vector<Vec3> tunnel_points = {Vec3(3.0, -0.3, 0.0), Vec3(3.0, 0.3, 2.4), Vec3(-2.0, 0.0, 0.0),
                                           Vec3(1.9 + 0.3 * std::sqrt(2.0), 0.1, 0.6), Vec3(0.0, 0.4, 2.4)};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N(0, 0.01);
  RegistrationParams p;
  p.method = "svd";
  for (const Vec3& x : tunnel_points) {
    const Vec3 ref = s.reference_pose.inverse() * x;
    p.pairs.push_back({s.truth.inverse() * ref + Vec3(N(rng), N(rng), N(rng)), ref});
  }
  const Registration r = registerClouds(s.reference, s.moving, p);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.1);
  EXPECT_LT(translationError(r, s.truth), 0.004);
  EXPECT_TRUE(r.accepted);
}

TEST(PlaneRegistration, OnePickedPairGivesTheTranslationWithTwoPlanes) {
  // The study's option 1: two plane pairs for the rotation, a picked point
  // (here the cube's top corner, exact) for the translation.
  const TunnelScene& s = scene(0);
  RegistrationParams p;
  const Vec3 corner = s.reference_pose.inverse() * Vec3(1.9 + 0.3 * std::sqrt(2.0), 0.1, 0.6);
  p.pairs = {{s.truth.inverse() * corner, corner}};
  const Registration r = registerClouds(s.reference, s.moving, p);
  ASSERT_GE(r.pairings.size(), 2u);
  EXPECT_EQ(r.pairings.size(), r.coarse_planes_on);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.01);
  EXPECT_LT(translationError(r, s.truth), 1e-4);
  EXPECT_TRUE(r.accepted);
}

TEST(PlaneRegistration, UserHintsPickThePlanes) {
  // One point on each of floor, downstream screen and the cube's port-upstream face.
  const TunnelScene& s = scene(kSigma);
  RegistrationParams p;
  for (const Vec3& x : {Vec3(0.0, 0.0, 0.0), Vec3(3.0, 0.0, 1.2), Vec3(1.9 - 0.21, 0.1 + 0.21, 0.3)}) {
    const Vec3 ref = s.reference_pose.inverse() * x;
    p.plane_hints.push_back({s.truth.inverse() * ref, ref});
  }
  const Registration r = registerClouds(s.reference, s.moving, p);
  EXPECT_EQ(r.candidates, 1u);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.05);
  EXPECT_LT(translationError(r, s.truth), 0.002);
  // A hint far from every plane is an error naming the point.
  p.plane_hints[2].reference = Vec3(40, 40, 40);
  expectThrowWith<AnalysisError>([&] { registerClouds(s.reference, s.moving, p); },
                                 {"registerClouds", "no plane of the reference cloud", "hint"});
}

TEST(PlaneRegistration, CubeAtTwoHundredThousandPointsPerUnitIsNotTurnedEndForEnd) {
  // The cube at the density of the 200,000-points-per-unit benchmark (the
  // chamber at the default density keeps the test fast). Region growing misses
  // the cube face each unit sees head-on there; before those faces were
  // recovered the chamber matched turned 180° and 2 m off, refused only as
  // ambiguous. Issue 5's tolerances with σ = 4 mm: < 0.05° and < 2 mm.
  TunnelSceneParams p;
  p.noise_sigma_m = kSigma;
  p.cube_density_per_m2 *= 200'000.0 / 23'800.0;  // the default scene has ~23,800 points per unit
  const TunnelScene s = makeTunnelScene(p);
  const Registration r = registerClouds(s.reference, s.moving);
  EXPECT_LT(rotationErrorDeg(r, s.truth), 0.05);
  EXPECT_LT(translationError(r, s.truth), 0.002);
  EXPECT_FALSE(r.ambiguous);
  EXPECT_TRUE(r.accepted);
  // Floor, ceiling, screen, cube top and both cube faces seen by both units.
  EXPECT_EQ(r.coarse_planes_on, 6u);
}

TEST(PlaneRegistration, ASymmetricChamberIsAmbiguousNeverAccepted) {
  // Without the cube's faces (too sparse to be planes) the two units share only
  // floor, ceiling and screen, and the chamber turned end for end about its long
  // axis lands as many planes as any other match: the result must say so and
  // must not be accepted (the 200,000-point benchmark found this case).
  TunnelSceneParams p;
  p.noise_sigma_m = kSigma;
  p.cube_density_per_m2 = 5;
  const TunnelScene s = makeTunnelScene(p);
  const Registration r = registerClouds(s.reference, s.moving);
  EXPECT_TRUE(r.ambiguous);
  EXPECT_FALSE(r.accepted);
}

TEST(PlaneRegistration, FewerThanThreePlanesIsAClearError) {
  // Floor and one wall only: the translation along the wall is free.
  const Cloud two = planesCloud({{Vec3(-2, -2, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)},
                                 {Vec3(-2, 2, 0), Vec3(4, 0, 0), Vec3(0, 0, 2.5)}});
  const TunnelScene& s = scene(0);
  expectThrowWith<AnalysisError>([&] { registerClouds(two, s.moving); },
                                 {"registerClouds", "fewer than three usable planes", "reference", "found 2"});
  expectThrowWith<AnalysisError>([&] { registerClouds(s.reference, two); },
                                 {"registerClouds", "fewer than three usable planes", "moving"});
}

TEST(PlaneRegistration, ParallelPlanesAreAClearError) {
  // Floor, ceiling and a shelf: three planes, all parallel.
  const Cloud parallel = planesCloud({{Vec3(-2, -2, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)},
                                      {Vec3(-2, -2, 2.5), Vec3(4, 0, 0), Vec3(0, 4, 0)},
                                      {Vec3(-1, -1, 1.0), Vec3(2, 0, 0), Vec3(0, 2, 0)}});
  const TunnelScene& s = scene(0);
  expectThrowWith<AnalysisError>([&] { registerClouds(parallel, s.moving); }, {"registerClouds", "parallel"});
  // A tunnel without the screen or cube: floor, ceiling and both walls have
  // normals in one plane, so nothing fixes the position along the flow.
  const Cloud tube = planesCloud({{Vec3(-3, -1.8, 0), Vec3(6, 0, 0), Vec3(0, 3.6, 0)},
                                  {Vec3(-3, -1.8, 2.4), Vec3(6, 0, 0), Vec3(0, 3.6, 0)},
                                  {Vec3(-3, -1.8, 0), Vec3(6, 0, 0), Vec3(0, 0, 2.4)},
                                  {Vec3(-3, 1.8, 0), Vec3(6, 0, 0), Vec3(0, 0, 2.4)}},
                                 0.08);
  expectThrowWith<AnalysisError>([&] { registerClouds(tube, s.moving); },
                                 {"registerClouds", "parallel or their normals share one plane"});
}

TEST(PlaneRegistration, NoMatchingPlanesIsAClearError) {
  // A room whose walls meet at 60°: no plane triple of the tunnel has its angles.
  const Vec3 a(1, 0, 0), b(0.5, std::sqrt(3.0) / 2, 0);
  const Cloud skew = planesCloud({{Vec3(0, 0, 0), a * 3, b * 3},
                                  {Vec3(0, 0, 0), a * 3, Vec3(0, 0, 2.5)},
                                  {Vec3(0, 0, 0), b * 3, Vec3(0, 0, 2.5)}});
  const TunnelScene& s = scene(0);
  expectThrowWith<AnalysisError>([&] { registerClouds(skew, s.moving); },
                                 {"registerClouds", "match the angles"});
}

TEST(Registration, NoOverlapIsAClearErrorNotAPoorTransform) {
  // Pairs that put the moving cloud 100 m away: nothing overlaps.
  const TunnelScene& s = scene(0);
  RegistrationParams p;
  p.method = "svd";
  for (const Vec3& m : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
    p.pairs.push_back({m, m + Vec3(100, 0, 0)});
  expectThrowWith<AnalysisError>([&] { registerClouds(s.reference, s.moving, p); },
                                 {"registerClouds", "no overlap", "within"});
  p.method = "icp";
  p.initial = RigidTransform::Identity();
  p.initial.translation() = Vec3(100, 0, 0);
  expectThrowWith<AnalysisError>([&] { registerClouds(s.reference, s.moving, p); }, {"registerClouds", "no overlap"});
}

TEST(Registration, BadParametersAreRejected) {
  const TunnelScene& s = scene(0);
  auto with = [&](auto change, std::vector<std::string> parts) {
    RegistrationParams p;
    change(p);
    expectInvalidInput([&] { registerClouds(s.reference, s.moving, p); }, parts);
  };
  with([](RegistrationParams& p) { p.method = "magic"; }, {"registerClouds", "method", "magic"});
  with([](RegistrationParams& p) { p.method = "svd"; }, {"registerClouds", "svd", "3 point pairs", "got 0"});
  with([](RegistrationParams& p) { p.pairs.resize(2); }, {"registerClouds", "at most one point pair"});
  with([](RegistrationParams& p) { p.plane_hints.resize(2); }, {"registerClouds", "3 planes", "got 2"});
  with([](RegistrationParams& p) { p.crossed_radius_m = 0; }, {"registerClouds", "crossed_radius_m"});
  with([](RegistrationParams& p) { p.uncertainty_m = -1; }, {"registerClouds", "uncertainty_m"});
  with([](RegistrationParams& p) { p.icp_initial_correspondence_m = 0; }, {"icp_initial_correspondence_m"});
  with([](RegistrationParams& p) { p.max_icp_points = 10; }, {"max_icp_points"});
  with([](RegistrationParams& p) { p.verify.samples_per_cloud = 1; }, {"samples_per_cloud"});
  with([](RegistrationParams& p) { p.screen_samples = 1; }, {"screen_samples"});
  with([](RegistrationParams& p) { p.refined_hypotheses = 0; }, {"refined_hypotheses"});
  with([](RegistrationParams& p) { p.match.verify_radius_m = 0; }, {"verify_radius_m"});
  with([](RegistrationParams& p) { p.match.max_angle_mismatch_deg = 0; }, {"max_angle_mismatch_deg"});
  with([](RegistrationParams& p) { p.match.min_plane_angle_deg = 120; }, {"min_plane_angle_deg"});
  expectInvalidInput([&] { registerClouds(Cloud{}, s.moving); }, {"registerClouds", "both clouds need points"});
}

TEST(TransformFromPlanes, FollowsTheStudysTwoRotationsAndIntersection) {
  // Three planes of a box corner, moved by the study transform.
  const RigidTransform truth = [] {
    RigidTransform t = RigidTransform::Identity();
    t.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
    t.translation() = Vec3(1, 1, 1);
    return t;
  }();
  auto plane = [](const Vec3& n, double d) {
    DetectedPlane p;
    p.normal = n.normalized();
    p.offset_m = d;
    return p;
  };
  const DetectedPlane mov[3] = {plane(Vec3::UnitZ(), 0.5), plane(Vec3(1, 1, 0), 0.2), plane(Vec3::UnitX(), -1)};
  DetectedPlane ref[3];
  for (int i = 0; i < 3; ++i) {
    const Vec3 n = truth.linear() * mov[i].normal;
    ref[i] = plane(n, mov[i].offset_m + n.dot(truth.translation()));
  }
  const RigidTransform t = transformFromPlanes(ref, mov);
  EXPECT_LT(rotationDifferenceDeg(t.linear(), truth.linear()), 1e-9);
  EXPECT_LT((t.translation() - truth.translation()).norm(), 1e-12);
  const DetectedPlane flat[3] = {plane(Vec3::UnitZ(), 0), plane(Vec3::UnitY(), 0), plane(Vec3(0, 1, 1), 1)};
  expectThrowWith<AnalysisError>([&] { transformFromPlanes(flat, flat); }, {"intersectPlanes", "coplanar"});
}

TEST(Drift, ComparesAStoredTransformWithAFreshOne) {
  RigidTransform stored = RigidTransform::Identity();
  stored.translation() = Vec3(1, 2, 3);
  RigidTransform fresh = stored;
  fresh.translation() += Vec3(0.003, 0, 0);
  Drift d = compareTransforms(stored, fresh, 5.0, 0.009);
  EXPECT_NEAR(d.translation_m, 0.003, 1e-12);
  EXPECT_NEAR(d.rotation_deg, 0.0, 1e-9);
  EXPECT_FALSE(d.moved);
  // 0.2° at 5 m is 17 mm: moved.
  fresh.linear() = Eigen::AngleAxisd(0.2 * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  d = compareTransforms(stored, fresh, 5.0, 0.009);
  EXPECT_NEAR(d.rotation_deg, 0.2, 1e-9);
  EXPECT_NEAR(d.max_displacement_m, 0.003 + 2 * std::sin(0.1 * kRadPerDeg) * 5.0, 1e-9);
  EXPECT_TRUE(d.moved);
  expectInvalidInput([&] { compareTransforms(stored, fresh, -1, 0.009); }, {"compareTransforms", "radius_m"});
}

}  // namespace
}  // namespace sailshape
