// Sweeps end to end: the client drives the emulated turntable through a real pty and the emulated
// scanner through a real TCP socket; clouds of known shapes reconstruct within SPEC §3's noise model.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scanner_client.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/sweep.hpp"
#include "acquisition/turntable.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/segmentation/mixed_pixels.hpp"

using namespace sailshape;

namespace {

constexpr double kSigmaCloth = 0.0041;  // SPEC §3

// One emulated unit: drive on a pty, scanner on an ephemeral port, sharing the drive's motion.
struct Rig {
  EmulatedTurntable table;
  ScannerEmulator scanner;
  UnitConfig unit;
  Rig(const Scene& scene, const UnitConfig& u, const ScannerEmulatorParams& sp, const EmulatedTurntableParams& tp)
      : table(tp), scanner(scene, sp, &table.motion()), unit(u) {
    unit.port = scanner.port();
    unit.serial_device = table.devicePath();
  }
};

EmulatedTurntableParams fastTable() {
  EmulatedTurntableParams p;
  p.home_speed_deg_s = 720;
  p.acceleration_deg_s2 = 3600;
  return p;
}

// A compact sweep: LMS511 at 50 Hz, 1°, α 60°..120°, β −20°..+20° at 40 °/s.
UnitConfig compactUnit(double p_m, double theta_deg) {
  UnitConfig u;
  u.name = "test-unit";
  u.model = ScannerModel::Lms511;
  u.p_m = p_m;
  u.theta_rad = theta_deg * kRadPerDeg;
  u.frequency_hz = 50;
  u.resolution_deg = 1.0;
  u.output_start_deg = 60;
  u.output_stop_deg = 120;
  u.start_angle_deg = -20;
  u.sweep_angle_deg = 40;
  u.speed_deg_s = 40;
  u.acceleration_deg_s2 = 400;
  return u;
}

ScannerEmulatorParams emulatorFor(const UnitConfig& u) {
  ScannerEmulatorParams p;
  p.port = 0;
  p.sensor.model = u.model;
  p.p_m = u.p_m;
  p.theta_rad = u.theta_rad;
  p.pose = u.pose;
  return p;
}

Scene wallAt(double y) {
  Scene s;
  s.objects.push_back({"wall", Material::Cloth, makeQuad(Vec3(-20, y, -20), Vec3(20, y, -20), Vec3(20, y, 20), Vec3(-20, y, 20))});
  return s;
}

struct PlaneFit {
  Vec3 normal, centroid;
  double rms = 0;
};
PlaneFit fitPlane(const std::vector<Vec3>& pts) {
  PlaneFit f;
  f.centroid = Vec3::Zero();
  for (const Vec3& p : pts) f.centroid += p;
  f.centroid /= pts.size();
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (const Vec3& p : pts) c += (p - f.centroid) * (p - f.centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c);
  f.normal = es.eigenvectors().col(0);
  for (const Vec3& p : pts) f.rms += std::pow((p - f.centroid).dot(f.normal), 2);
  f.rms = std::sqrt(f.rms / pts.size());
  return f;
}

// `slow_host_s`: the emulator takes that long to compute each scan (longer than the 20 ms period), and drops
// the scans it is more than `max_lag_s` late for. The sweep is left in `out` when given.
void checkPlaneSweep(BetaSource source, const std::string& protocol = "cola-b", double slow_host_s = 0,
                     double max_lag_s = 0.25, Sweep* out = nullptr) {
  UnitConfig u = compactUnit(0.12, 25);
  u.beta_source = source;
  u.protocol = protocol;
  u.pose = makePose(Vec3(0.5, -1.0, 2.0), 0, 0, 0.3);
  // The wall y = 3 in the unit frame, placed in the scene through the pose.
  Scene scene;
  const Vec3 c[4] = {Vec3(-20, 3, -20), Vec3(20, 3, -20), Vec3(20, 3, 20), Vec3(-20, 3, 20)};
  scene.objects.push_back({"wall", Material::Cloth, makeQuad(u.pose * c[0], u.pose * c[1], u.pose * c[2], u.pose * c[3])});
  ScannerEmulatorParams sp = emulatorFor(u);
  sp.slow_host_s = slow_host_s;
  sp.max_lag_s = max_lag_s;
  Rig rig(scene, u, sp, fastTable());
  const Sweep s = runSweep(rig.unit);
  if (out) *out = s;
  ASSERT_FALSE(s.partial) << s.message;
  // ≈ 1.1 s of motion at 50 Hz, or at the rate a slow host computes its scans.
  const double rate_hz = slow_host_s > 0 ? std::min(u.frequency_hz, 1.0 / slow_host_s) : u.frequency_hz;
  EXPECT_GE(s.scans, static_cast<size_t>(0.7 * 1.1 * rate_hz));
  EXPECT_EQ(s.cloud.size(), s.points.size());
  EXPECT_GT(s.points.size(), 0.9 * s.beams);
  EXPECT_NEAR(s.beta_start_deg, -20, 1.0);
  EXPECT_NEAR(s.beta_end_deg, 20, 1.0);
  const PlaneFit f = fitPlane(s.cloud.points);
  EXPECT_LE(f.rms, 1.5 * kSigmaCloth) << "plane RMS residual";
  // The fitted plane is the true one (normal along the pose's Y), offset by at most the systematic error.
  const Vec3 n_true = u.pose.linear() * Vec3::UnitY();
  EXPECT_GT(std::abs(f.normal.dot(n_true)), std::cos(0.2 * kRadPerDeg));
  const double offset = (f.centroid - u.pose * Vec3(0, 3, 0)).dot(n_true);
  EXPECT_GT(offset, -3 * kSigmaCloth / std::sqrt(double(s.points.size())));
  EXPECT_LT(offset, 0.003 * 3.6);  // SPEC §3: ≤ 0.3 % of the longest range (3 m / sin 60° ≈ 3.5 m)
  // Samples keep r, α, β, RSSI and time.
  for (const SweepPoint& p : s.points) {
    ASSERT_GE(p.alpha_rad, 60 * kRadPerDeg - 1e-9);
    ASSERT_LE(p.alpha_rad, 120 * kRadPerDeg + 1e-9);
    ASSERT_GT(p.rssi, 0);
    ASSERT_GE(p.time_s, s.start_time_s - 0.05);
  }
}

}  // namespace

TEST(Sweep, PlaneWithEncoderBeta) { checkPlaneSweep(BetaSource::Encoder); }

TEST(Sweep, PlaneWithTimestampBeta) { checkPlaneSweep(BetaSource::Timestamp); }

TEST(Sweep, PlaneInColaA) { checkPlaneSweep(BetaSource::Encoder, "cola-a"); }

// A host that cannot compute 50 Hz. With the emulator's default lag it drops the scans it falls behind on,
// as a device drops what its output cannot send: the sweep still covers the whole turntable move, the gaps
// in the scan counter are counted and said, and β across a gap still puts the wall where it is. Allowed to
// fall 10 s behind, it is a device draining a backlog after the turntable stopped: the sweep waits for the
// scans taken while it moved, placed by their own time stamps rather than by when they arrived, and none
// is lost.
TEST(Sweep, AHostTooSlowForTheScanRateLosesScansNotTheEndOfTheSweep) {
  for (const double max_lag_s : {0.25, 10.0})
    for (BetaSource source : {BetaSource::Encoder, BetaSource::Timestamp}) {
      SCOPED_TRACE(std::string(source == BetaSource::Encoder ? "encoder" : "timestamp") + ", lag " +
                   std::to_string(max_lag_s));
      Sweep s;
      checkPlaneSweep(source, "cola-b", 0.03, max_lag_s, &s);
      bool said = false;
      for (const std::string& w : s.warnings) said = said || w.find("never arrived") != std::string::npos;
      EXPECT_EQ(s.scans_missed > 0, max_lag_s < 1.0);
      EXPECT_EQ(said, s.scans_missed > 0) << "the lost scans are said";
      // And where: a β per scan lost while the turntable turned (one lost while it stood
      // at the end lost no line), in the gap it left between the lines received. At full
      // speed (2° from either end: 40°/s reached at 400°/s²) a line's samples span a
      // fraction of a step, and none lies within half a step of a lost line.
      EXPECT_LE(s.cloud.lost_beta_rad.size(), s.scans_missed);
      EXPECT_EQ(s.cloud.lost_beta_rad.empty(), s.scans_missed == 0);
      EXPECT_TRUE(std::is_sorted(s.cloud.lost_beta_rad.begin(), s.cloud.lost_beta_rad.end()));
      const double step = scanLineStepRad(s.cloud);
      ASSERT_GT(step, 0);
      size_t at_speed = 0;
      const auto [lo, hi] = std::minmax_element(s.cloud.beta_rad.begin(), s.cloud.beta_rad.end());
      for (const double b : s.cloud.lost_beta_rad) {
        // Within the sweep: between its first and last lines (each line's samples
        // span part of a step about its middle beam).
        EXPECT_GT(b, *lo - 0.5 * step);
        EXPECT_LT(b, *hi + 0.5 * step);
        if (b < (s.beta_start_deg + 2) * kRadPerDeg || b > (s.beta_end_deg - 2) * kRadPerDeg) continue;
        ++at_speed;
        double nearest = 1e9;
        for (const double pb : s.cloud.beta_rad) nearest = std::min(nearest, std::abs(pb - b));
        EXPECT_GT(nearest, 0.5 * step) << "lost line at " << b;
      }
      EXPECT_EQ(at_speed > 0, s.scans_missed > 0) << "the host loses scans all along";
    }
}

TEST(Sweep, ScanLinesArriveWhileTheTurntableMoves) {
  UnitConfig u = compactUnit(0.12, 25);
  u.beta_source = BetaSource::Encoder;
  u.pose = makePose(Vec3(0.5, -1.0, 2.0), 0, 0, 0.3);
  Scene scene;
  const Vec3 c[4] = {Vec3(-20, 3, -20), Vec3(20, 3, -20), Vec3(20, 3, 20), Vec3(-20, 3, 20)};
  scene.objects.push_back({"wall", Material::Cloth, makeQuad(u.pose * c[0], u.pose * c[1], u.pose * c[2], u.pose * c[3])});
  Rig rig(scene, u, emulatorFor(u), fastTable());
  SweepOptions o;
  std::vector<Vec3> seen;
  size_t calls = 0;
  std::chrono::steady_clock::time_point first, last;
  o.on_scan = [&](const std::vector<Vec3>& pts) {
    last = std::chrono::steady_clock::now();
    if (calls++ == 0) first = last;
    seen.insert(seen.end(), pts.begin(), pts.end());
  };
  const Sweep s = runSweep(rig.unit, o);
  ASSERT_FALSE(s.partial) << s.message;
  // Every scan the sweep used was shown first (and those at the start angle before the move).
  EXPECT_GE(calls, s.scans);
  EXPECT_GE(seen.size(), s.cloud.size());
  // Shown as they came: over the second the 40° take at 40 °/s, not all at the end.
  EXPECT_GT(std::chrono::duration<double>(last - first).count(), 0.5);
  // On the wall, up to holding β for a whole line: 40 °/s for 20 ms (0.8°) at up to 3.5 m, plus 4σ of noise.
  const Vec3 n = u.pose.linear() * Vec3::UnitY(), on_wall = u.pose * Vec3(0, 3, 0);
  const double limit = 3.5 * 0.8 * kRadPerDeg + 4 * kSigmaCloth;
  size_t off = 0;
  for (const Vec3& p : seen) off += std::abs((p - on_wall).dot(n)) > limit;
  EXPECT_EQ(off, 0u) << "of " << seen.size() << " shown points";
}

TEST(Sweep, CylinderAtAKnownPosition) {
  // A vertical cylinder of radius 0.4 m, axis through (0.3, 3, ·) in the unit frame; no background.
  UnitConfig u = compactUnit(0.1, -15);
  u.output_start_deg = 70;
  u.output_stop_deg = 110;
  const double radius = 0.4;
  const Vec3 axis_point(0.3, 3.0, -5.0);
  Scene scene;
  scene.objects.push_back({"cylinder", Material::Cloth, makeCylinder(axis_point, Vec3::UnitZ(), radius, 10.0, 720)});
  Rig rig(scene, u, emulatorFor(u), fastTable());
  const Sweep s = runSweep(rig.unit);
  ASSERT_FALSE(s.partial) << s.message;
  ASSERT_GT(s.points.size(), 500u);
  double sum = 0, sum2 = 0;
  for (const Vec3& p : s.cloud.points) {
    const double d = std::hypot(p.x() - axis_point.x(), p.y() - axis_point.y()) - radius;
    sum += d;
    sum2 += d * d;
  }
  const double n = s.cloud.size(), mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  // The 720-facet cylinder lies within 0.4·(1 − cos 0.25°) ≈ 4 µm of the true one.
  EXPECT_LE(sd, 1.5 * kSigmaCloth);
  // A range too long puts the point behind the surface the scanner sees, i.e. inside the cylinder:
  // the mean residual lies between minus the systematic bound and zero (plus its sampling error).
  EXPECT_LT(mean, 3 * kSigmaCloth / std::sqrt(n));
  EXPECT_GT(mean, -0.003 * 3.2);
}

TEST(Sweep, ConnectionDroppedMidSweepKeepsThePartialSweep) {
  UnitConfig u = compactUnit(0.1, 0);
  ScannerEmulatorParams sp = emulatorFor(u);
  sp.drop_after_scans = 30;  // a few before the move starts, the rest during it
  Rig rig(wallAt(3), u, sp, fastTable());
  Sweep s;
  ASSERT_NO_THROW(s = runSweep(rig.unit));
  EXPECT_TRUE(s.partial);
  EXPECT_FALSE(s.message.empty());
  EXPECT_GT(s.points.size(), 0u);
  EXPECT_LT(s.scans, 30u);
  EXPECT_EQ(s.cloud.size(), s.points.size());
  // The turntable was stopped short of the sweep's end.
  EXPECT_LT(s.beta_end_deg, 20.0);
}

// A unit still spinning up streams nothing (the recorded units answered "busy" while starting): the
// move waits for its first scan, so the sweep still starts at its start angle. Moved at once, the
// 1 s sweep would be over before the first scan, 2.5 s after power-on.
TEST(Sweep, TheMoveWaitsForAUnitThatIsStillStarting) {
  UnitConfig u = compactUnit(0.1, 0);
  ScannerEmulatorParams sp = emulatorFor(u);
  sp.spin_up_s = 2.5;
  Rig rig(wallAt(3), u, sp, fastTable());
  const Sweep s = runSweep(rig.unit);
  ASSERT_FALSE(s.partial) << s.message;
  EXPECT_NEAR(s.beta_start_deg, -20, 1.0);
  EXPECT_NEAR(s.beta_end_deg, 20, 1.0);
  EXPECT_GE(s.scans, 40u);
}

// One that never gets ready within the wait: one error naming the wait and the device's state.
TEST(Sweep, AUnitThatNeverStartsStreamingIsReported) {
  UnitConfig u = compactUnit(0.1, 0);
  ScannerEmulatorParams sp = emulatorFor(u);
  sp.spin_up_s = 30;
  Rig rig(wallAt(3), u, sp, fastTable());
  SweepOptions o;
  o.ready_timeout_s = 1;
  try {
    runSweep(rig.unit, o);
    ADD_FAILURE() << "a sweep cannot run without scans";
  } catch (const ScannerError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("streamed no scan within 1 s"), std::string::npos) << what;
    EXPECT_NE(what.find("device state 0, busy"), std::string::npos) << what;
  }
}

TEST(Sweep, ADurationOrSpeedThatIsNotPositiveIsOneErrorBeforeAnythingMoves) {
  UnitConfig u = compactUnit(0.1, 0);
  Rig rig(wallAt(3), u, emulatorFor(u), fastTable());
  const std::vector<std::pair<double SweepOptions::*, std::string>> fields{
      {&SweepOptions::home_timeout_s, "home_timeout_s"},   {&SweepOptions::positioning_speed_deg_s, "positioning_speed_deg_s"},
      {&SweepOptions::reply_timeout_s, "reply_timeout_s"}, {&SweepOptions::scan_timeout_s, "scan_timeout_s"},
      {&SweepOptions::ready_timeout_s, "ready_timeout_s"}};
  for (const auto& [field, name] : fields)
    for (double bad : {0.0, -1.0, std::nan("")}) {
      SweepOptions o;
      o.*field = bad;
      try {
        runSweep(rig.unit, o);
        ADD_FAILURE() << name << " = " << bad;
      } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("[runSweep] " + name + " must be > 0"), std::string::npos) << e.what();
      }
    }
  // Refused before any link was opened.
  EXPECT_EQ(rig.scanner.connections(), 0u);
}

TEST(Sweep, TurntableThatNeverFindsHome) {
  EmulatedTurntableParams tp = fastTable();
  tp.home_sensor_works = false;
  tp.home_search_deg = 60;
  UnitConfig u = compactUnit(0.1, 0);
  Rig rig(wallAt(3), u, emulatorFor(u), tp);
  try {
    runSweep(rig.unit);
    ADD_FAILURE() << "a sweep cannot start without home";
  } catch (const TurntableError& e) {
    EXPECT_EQ(e.code, TurntableErrorCode::HomeNotFound);
  }
  EXPECT_EQ(rig.scanner.connections(), 0u) << "nothing streamed before the table was homed";
}

TEST(Sweep, RefusedLoginAndSilentScanner) {
  UnitConfig u = compactUnit(0.1, 0);
  ScannerEmulatorParams sp = emulatorFor(u);
  sp.refuse_login = true;
  {
    Rig rig(wallAt(3), u, sp, fastTable());
    EXPECT_THROW(runSweep(rig.unit), ScannerError);
  }
  sp = emulatorFor(u);
  sp.mute = true;
  {
    Rig rig(wallAt(3), u, sp, fastTable());
    SweepOptions o;
    o.reply_timeout_s = 0.3;
    EXPECT_THROW(runSweep(rig.unit, o), ScannerError);
  }
  UnitConfig bad = u;
  bad.speed_deg_s = 0;
  EXPECT_THROW(runSweep(bad), InvalidInput);
}
