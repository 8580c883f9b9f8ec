// Planar regions for the plane-based registration: walls, floor, ceiling and
// the faces of a reference cube, found with their poses.
#include "analysis/plane_detection.hpp"

#include <gtest/gtest.h>

#include "analysis/sail_generator.hpp"
#include "analysis/tunnel_scene.hpp"
#include "tests/analysis/fixtures.hpp"

namespace sailshape {
namespace {

// The detected plane closest in orientation to `normal`, or nullptr.
const DetectedPlane* planeAlong(const PlaneDetection& d, const Vec3& normal) {
  const DetectedPlane* best = nullptr;
  for (const DetectedPlane& p : d.planes)
    if (p.normal.dot(normal) > 0.999 && (!best || p.points > best->points)) best = &p;
  return best;
}

TEST(PlaneDetection, FindsTheChamberAndCubeFacesWithTheirPoses) {
  // Reference unit of the tunnel scene (tunnel frame = unit frame here), 4 mm noise.
  TunnelSceneParams p;
  p.noise_sigma_m = kSigma;
  const TunnelScene s = makeTunnelScene(p);
  const PlaneDetection d = detectPlanes(s.reference);
  // Floor, ceiling, starboard wall, screen, cube top and the two cube faces this unit sees.
  EXPECT_EQ(d.planes.size(), 7u);
  struct Expected {
    Vec3 normal;
    double offset_m;
  };
  const double r2 = std::sqrt(0.5);
  for (const Expected& e : std::vector<Expected>{{Vec3::UnitZ(), 0.0},
                                                 {-Vec3::UnitZ(), -2.4},
                                                 {Vec3::UnitY(), -1.8},
                                                 {-Vec3::UnitX(), -3.0},
                                                 {Vec3(-r2, -r2, 0), Vec3(-r2, -r2, 0).dot(Vec3(1.9, 0.1, 0.3)) + 0.3},
                                                 {Vec3(-r2, r2, 0), Vec3(-r2, r2, 0).dot(Vec3(1.9, 0.1, 0.3)) + 0.3}}) {
    const DetectedPlane* pl = planeAlong(d, e.normal);
    ASSERT_NE(pl, nullptr) << e.normal.transpose();
    // Thousands of points with σ = 4 mm: the offset is good to well under a millimetre.
    EXPECT_NEAR(pl->offset_m, e.offset_m, 0.001) << e.normal.transpose();
    EXPECT_LT(std::acos(std::min(1.0, pl->normal.dot(e.normal))) / kDeg, 0.1);
    // Range noise along the ray, projected on the normal: σ·cos(incidence), at most σ.
    EXPECT_GT(pl->rms_m, 0.2 * kSigma);
    EXPECT_LT(pl->rms_m, 1.1 * kSigma);
  }
  // Largest first; sails (curved) are not planes.
  for (size_t i = 1; i < d.planes.size(); ++i) EXPECT_GE(d.planes[i - 1].points, d.planes[i].points);
}

TEST(PlaneDetection, NormalsPointTowardsTheScanner) {
  TunnelScene s = makeTunnelScene({});
  const PlaneDetection d = detectPlanes(s.reference);
  ASSERT_FALSE(d.planes.empty());
  for (const DetectedPlane& p : d.planes) EXPECT_GT(p.normal.dot(*s.reference.viewpoint - p.centroid), 0);
}

TEST(PlaneDetection, ASailIsNotAPlane) {
  const Cloud sail = sampleSail(exampleDesign(SailType::Main), {20000, kSigma, 1});
  const PlaneDetection d = detectPlanes(sail);
  EXPECT_TRUE(d.planes.empty()) << d.planes.size() << " planes, the first with rms " << d.planes[0].rms_m;
}

TEST(PlaneDetection, FitAndIntersection) {
  std::vector<Vec3> pts = {Vec3(0, 0, 1), Vec3(2, 0, 1), Vec3(0, 3, 1), Vec3(2, 3, 1)};
  const DetectedPlane p = fitPlane(pts, {0, 1, 2, 3});
  EXPECT_NEAR(std::abs(p.normal.z()), 1.0, 1e-12);
  EXPECT_NEAR(p.offset_m * p.normal.z(), 1.0, 1e-12);
  EXPECT_NEAR(p.rms_m, 0.0, 1e-12);
  expectInvalidInput([&] { fitPlane(pts, {0, 1}); }, {"fitPlane", "3 points", "got 2"});
  DetectedPlane x, y, z;
  x.normal = Vec3::UnitX();
  x.offset_m = 1;
  y.normal = Vec3::UnitY();
  y.offset_m = 2;
  z.normal = Vec3(0, 1, 1).normalized();
  z.offset_m = z.normal.dot(Vec3(1, 2, 3));
  EXPECT_LT((intersectPlanes(x, y, z) - Vec3(1, 2, 3)).norm(), 1e-12);
  DetectedPlane y2 = y;
  y2.offset_m = 5;
  expectThrowWith<AnalysisError>([&] { intersectPlanes(x, y, y2); }, {"intersectPlanes", "coplanar"});
}

TEST(PlaneDetection, BadParametersAreRejected) {
  const TunnelScene s = makeTunnelScene({});
  auto with = [&](auto change, std::vector<std::string> parts) {
    PlaneDetectionParams p;
    change(p);
    expectInvalidInput([&] { detectPlanes(s.reference, p); }, parts);
  };
  with([](PlaneDetectionParams& p) { p.normal_k = 2; }, {"detectPlanes", "normal_k", "got 2"});
  with([](PlaneDetectionParams& p) { p.ransac_threshold_m = 0; }, {"detectPlanes", "ransac_threshold_m"});
  with([](PlaneDetectionParams& p) { p.ransac_iterations = 0; }, {"detectPlanes", "ransac_iterations"});
  with([](PlaneDetectionParams& p) { p.min_inlier_fraction = 1.5; }, {"detectPlanes", "min_inlier_fraction"});
  with([](PlaneDetectionParams& p) { p.max_rms_m = 0; }, {"detectPlanes", "max_rms_m"});
  with([](PlaneDetectionParams& p) { p.min_extent_m = -1; }, {"detectPlanes", "min_extent_m"});
  with([](PlaneDetectionParams& p) { p.max_planes = 0; }, {"detectPlanes", "max_planes"});
  Cloud tiny;
  tiny.points.assign(5, Vec3::Zero());
  expectInvalidInput([&] { detectPlanes(tiny); }, {"detectPlanes", "5 points"});
}

}  // namespace
}  // namespace sailshape
