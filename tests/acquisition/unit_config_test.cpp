#include <gtest/gtest.h>

#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"

using namespace sailshape;

TEST(UnitConfig, DefaultsFollowTheModel) {
  const UnitConfig u = parseUnitJson(R"({"name": "port", "model": "lms111"})");
  EXPECT_EQ(u.model, ScannerModel::Lms111);
  EXPECT_DOUBLE_EQ(u.output_start_deg, -45);
  EXPECT_DOUBLE_EQ(u.output_stop_deg, 225);
  EXPECT_DOUBLE_EQ(u.frequency_hz, 50);
  EXPECT_DOUBLE_EQ(u.resolution_deg, 0.5);
  EXPECT_EQ(u.port, 2112);
}

TEST(UnitConfig, RoundTripsThroughJson) {
  UnitConfig u;
  u.name = "starboard";
  u.port = 2113;
  u.protocol = "cola-a";
  u.serial_device = "/tmp/tt0";
  u.p_m = 0.112;
  u.theta_rad = 0.3;
  u.pose = makePose(Vec3(1, 2, 3), 0.1, -0.2, 0.7);
  u.start_angle_deg = -30;
  u.sweep_angle_deg = 120;
  u.beta_source = BetaSource::Timestamp;
  const UnitConfig v = parseUnitJson(unitToJson(u));
  EXPECT_EQ(v.name, u.name);
  EXPECT_EQ(v.port, u.port);
  EXPECT_EQ(v.protocol, u.protocol);
  EXPECT_EQ(v.serial_device, u.serial_device);
  EXPECT_NEAR(v.p_m, u.p_m, 1e-12);
  EXPECT_NEAR(v.theta_rad, u.theta_rad, 1e-12);
  EXPECT_TRUE(v.pose.isApprox(u.pose, 1e-12));
  EXPECT_EQ(v.beta_source, BetaSource::Timestamp);
  EXPECT_DOUBLE_EQ(v.sweep_angle_deg, 120);
}

TEST(UnitConfig, Spec2Geometry) {
  // β = 0, θ = 0: the scanner origin sits p along +Y; α = 90° looks along +Y.
  const Vec3 a = unitPoint(2.0, M_PI / 2, 0.0, 0.1, 0.0);
  EXPECT_TRUE(a.isApprox(Vec3(0, 2.1, 0), 1e-12));
  // β = 90°: the plane turned to +Z; the offset turns with it.
  const Vec3 b = unitPoint(2.0, M_PI / 2, M_PI / 2, 0.1, 0.0);
  EXPECT_NEAR(b.z(), 2.1, 1e-12);
  EXPECT_NEAR(b.y(), 0.0, 1e-12);
  // α = 0 lies on the shaft whatever β: only the offset moves.
  const Vec3 c = unitPoint(3.0, 0.0, 1.0, 0.1, 0.5);
  EXPECT_NEAR(c.x(), 3.0, 1e-12);
  EXPECT_NEAR(std::hypot(c.y(), c.z()), 0.1, 1e-12);
}

TEST(UnitConfig, BadFilesNameTheKey) {
  EXPECT_THROW(parseUnitJson("{"), FileError);
  EXPECT_THROW(parseUnitJson("3"), FileError);
  EXPECT_THROW(readUnitFile("/nonexistent/unit.json"), FileError);
  EXPECT_THROW(parseUnitJson(R"({"colour": "red"})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"port": 70000})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"port": "x"})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"model": "lms999"})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"protocol": "cola-c"})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"speed_deg_s": 0})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"sweep_angle_deg": 0})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"start_angle_deg": 700, "sweep_angle_deg": 100})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"frequency_hz": 10})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"resolution_deg": 2})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"model": "lms511", "output_start_deg": -45})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"p_m": -0.1})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"pose": {"position_m": [1, 2]}})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"pose": {"where": [1, 2, 3]}})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"beta_source": "guess"})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"rssi": 1})"), InvalidInput);
  EXPECT_THROW(parseUnitJson(R"({"host": ""})"), InvalidInput);
}
