// Two emulated units started by one UDP trigger on loopback.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/sync.hpp"
#include "acquisition/turntable.hpp"

using namespace sailshape;

namespace {

struct EmulatedUnit {
  EmulatedTurntable table;
  ScannerEmulator scanner;
  UnitConfig unit;
  EmulatedUnit(const Scene& scene, ScannerModel model, double home_sensor_deg)
      : table(tableParams(home_sensor_deg)), scanner(scene, scannerParams(model), &table.motion()) {
    unit.name = scannerModelName(model);
    unit.model = model;
    unit.port = scanner.port();
    unit.serial_device = table.devicePath();
    unit.frequency_hz = model == ScannerModel::Lms111 ? 50 : 25;
    unit.resolution_deg = model == ScannerModel::Lms111 ? 0.5 : 1.0;
    unit.output_start_deg = 45;
    unit.output_stop_deg = 135;
    unit.start_angle_deg = -10;
    unit.sweep_angle_deg = 20;
    unit.speed_deg_s = 40;
    unit.acceleration_deg_s2 = 400;
  }
  static EmulatedTurntableParams tableParams(double home_sensor_deg) {
    EmulatedTurntableParams p;
    p.home_sensor_deg = home_sensor_deg;
    p.home_speed_deg_s = 360;
    p.acceleration_deg_s2 = 3600;
    return p;
  }
  static ScannerEmulatorParams scannerParams(ScannerModel model) {
    ScannerEmulatorParams p;
    p.port = 0;
    p.sensor.model = model;
    return p;
  }
};

Scene box() {
  Scene s;
  for (SceneObject& o : makeChamber(Vec3(-8, -6, -3), Vec3(8, 6, 3))) s.objects.push_back(std::move(o));
  return s;
}

}  // namespace

TEST(Sync, TwoUnitsStartWithin20Milliseconds) {
  // Different homing distances (sensor at 20° and 300°): the units get ready at different times and
  // the trigger lines them up.
  EmulatedUnit a(box(), ScannerModel::Lms511, 20), b(box(), ScannerModel::Lms111, 300);
  const SynchronisedSweeps r = runSynchronisedSweeps({a.unit, b.unit});
  ASSERT_EQ(r.sweeps.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(r.errors[i].empty()) << r.errors[i];
    EXPECT_FALSE(r.sweeps[i].partial) << r.sweeps[i].message;
    EXPECT_GT(r.sweeps[i].points.size(), 100u);
    EXPECT_GT(r.sweeps[i].trigger_time_s, 0);
    EXPECT_GE(r.sweeps[i].start_time_s, r.sweeps[i].trigger_time_s);
  }
  EXPECT_LT(r.start_spread_s, 0.020);
  EXPECT_NEAR(r.trigger_received_s[0], r.trigger_received_s[1], 0.020);
}

TEST(Sync, AUnitThatFailsIsReportedAndTheOtherRuns) {
  EmulatedUnit a(box(), ScannerModel::Lms511, 20);
  UnitConfig missing = a.unit;
  missing.name = "missing";
  missing.serial_device = "/nonexistent/tty";
  const SynchronisedSweeps r = runSynchronisedSweeps({a.unit, missing});
  EXPECT_TRUE(r.errors[0].empty()) << r.errors[0];
  EXPECT_FALSE(r.errors[1].empty());
  EXPECT_GT(r.sweeps[0].points.size(), 100u);
}

TEST(Sync, ListenerIgnoresStrangersAndTimesOut) {
  TriggerListener l({"127.0.0.1", 0});
  ASSERT_GT(l.port(), 0);
  // A datagram that is not a trigger is ignored.
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(l.port());
  inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
  const char junk[] = "HELLO 1";
  ::sendto(fd, junk, sizeof junk - 1, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::close(fd);
  EXPECT_THROW(l.wait(0.1), std::runtime_error);
  const double before = hostTimeSeconds();
  sendTrigger({{"127.0.0.1", l.port()}}, 42);
  const TriggerListener::Trigger t = l.wait(1.0);
  EXPECT_EQ(t.id, 42u);
  EXPECT_GE(t.received_s, before);
  EXPECT_THROW(sendTrigger({{"not-an-address", 1}}, 1), std::runtime_error);
  EXPECT_THROW(TriggerListener({"999.1.1.1", 0}), std::runtime_error);
}
