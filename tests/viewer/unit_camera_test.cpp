// The camera preset from a scanner unit: eye at the scanner, looking along the sweep's centre (SPEC §2 geometry).
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "viewer/scanner_session.hpp"
#include "viewer/unit_camera.hpp"

namespace sailshape::viewer {
namespace {

void expectNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(a.z(), b.z(), tol);
}

TEST(UnitCamera, TheDeckUnitLooksAftToPortAndUp) {
  // Shaft along boat +Z: unit Y is boat +Y (port), unit Z boat −X (aft); p = 0, so the eye is the pose's origin.
  const UnitConfig u = deckUnit(Vec3(1.5, -6.0, 1.2));
  const double alpha = (u.output_start_deg + u.output_stop_deg) / 2 * kRadPerDeg;
  const double beta = (u.start_angle_deg + u.sweep_angle_deg / 2) * kRadPerDeg;
  const Vec3 dir(-std::sin(alpha) * std::sin(beta), std::sin(alpha) * std::cos(beta), std::cos(alpha));
  const CameraPlacement c = unitCamera(u, 10.0);
  expectNear(c.position, Vec3(1.5, -6.0, 1.2), 1e-9);
  expectNear(c.focal_point, Vec3(1.5, -6.0, 1.2) + 10.0 * dir, 1e-9);
  EXPECT_NEAR(c.view_up.norm(), 1.0, 1e-12);
  EXPECT_NEAR(c.view_up.dot(dir), 0.0, 1e-12);
  EXPECT_GT(c.view_up.z(), 0.5) << "the boat's up stays up on screen";
}

TEST(UnitCamera, OffsetScannerAndYawedUnit) {
  UnitConfig u;
  u.pose = makePose(Vec3(1, 2, 3), 0, 0, 90 * kRadPerDeg);  // unit X → boat +Y, unit Y → boat −X
  u.p_m = 0.1;
  u.theta_rad = 8 * kRadPerDeg;
  u.start_angle_deg = 10;
  u.sweep_angle_deg = 40;  // centre β = 30°
  u.output_start_deg = 0;
  u.output_stop_deg = 180;  // centre α = 90°: the beam at right angles to the shaft
  const double b = 30 * kRadPerDeg, bt = 38 * kRadPerDeg;
  // Unit frame: origin (0, p cos(β+θ), p sin(β+θ)), beam (0, cos β, sin β); rotated by Rz(90°): (x, y, z) → (−y, x, z).
  const Vec3 eye(1 - 0.1 * std::cos(bt), 2, 3 + 0.1 * std::sin(bt));
  const Vec3 dir(-std::cos(b), 0, std::sin(b));
  const CameraPlacement c = unitCamera(u, 5.0);
  expectNear(c.position, eye, 1e-9);
  expectNear(c.focal_point, eye + 5.0 * dir, 1e-9);
  EXPECT_NEAR(c.view_up.dot(dir), 0.0, 1e-12);
}

TEST(UnitCamera, LookingAlongTheShaftStillHasAnUp) {
  UnitConfig u;
  u.pose = makePose(Vec3::Zero(), 0, -90 * kRadPerDeg, 0);  // shaft up
  u.output_start_deg = -5;
  u.output_stop_deg = 5;  // centre α = 0: along the shaft, straight up
  u.start_angle_deg = 0;
  u.sweep_angle_deg = 0;
  const CameraPlacement c = unitCamera(u, 2.0);
  expectNear(c.focal_point - c.position, Vec3(0, 0, 2), 1e-9);
  EXPECT_NEAR(c.view_up.norm(), 1.0, 1e-12);
  EXPECT_NEAR(c.view_up.z(), 0.0, 1e-12);
}

TEST(UnitCamera, AStoredScanIsSeenFromItsUnitAndRegistration) {
  // As `sailshape demo` stores a scan: the unit file's keys plus the sweep's own, the cloud in the unit's frame.
  UnitConfig u = deckUnit(Vec3(1.5, -6.0, 1.2));
  u.name = "main-unit";
  ScanRecord record;
  record.scan_id = 7;
  record.settings = nlohmann::json::parse(unitToJson(u));
  record.settings["sweep"] = {{"scans", 120}, {"partial", false}};
  record.settings["forces"] = "simulated";
  const std::optional<UnitConfig> from_file = scanUnit(record);
  ASSERT_TRUE(from_file.has_value());
  EXPECT_EQ(from_file->name, "main-unit");
  expectNear(unitCamera(*from_file).position, Vec3(1.5, -6.0, 1.2), 1e-9);  // the unit file's pose

  // The registration (unit frame → boat frame) wins over the nominal pose: here a unit standing 2 m further
  // aft and 0.5 m higher than its file says, shaft still vertical.
  Eigen::Isometry3d registered = u.pose;
  registered.translation() += Vec3(-2.0, 0.0, 0.5);
  record.registration = registered.matrix();
  const std::optional<UnitConfig> from_registration = scanUnit(record);
  ASSERT_TRUE(from_registration.has_value());
  const CameraPlacement c = unitCamera(*from_registration, 4.0), nominal = unitCamera(*from_file, 4.0);
  expectNear(c.position, Vec3(-0.5, -6.0, 1.7), 1e-9);
  expectNear(c.focal_point - c.position, nominal.focal_point - nominal.position, 1e-9);

  // A scan taken in the viewer stores its sweeps, not a unit file: no camera from it.
  ScanRecord viewer_scan;
  viewer_scan.settings = {{"sweeps", nlohmann::json::array()}, {"start_spread_s", 0.0}};
  EXPECT_FALSE(scanUnit(viewer_scan).has_value());
  EXPECT_FALSE(scanUnit(ScanRecord{}).has_value());
  ScanRecord broken = record;
  broken.settings["output_start_deg"] = "wide";
  EXPECT_FALSE(scanUnit(broken).has_value()) << "settings that make no valid unit give no camera";
}

TEST(UnitCamera, RefusesANonPositiveDistance) {
  EXPECT_THROW(unitCamera(deckUnit(), 0.0), InvalidInput);
  EXPECT_THROW(unitCamera(deckUnit(), -1.0), InvalidInput);
  EXPECT_THROW(unitCamera(deckUnit(), NAN), InvalidInput);
}

}  // namespace
}  // namespace sailshape::viewer
