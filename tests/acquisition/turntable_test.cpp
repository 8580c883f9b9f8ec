// The turntable protocol, the emulated drive on a real pty, and the termios client.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/turntable.hpp"
#include "analysis/core/errors.hpp"

using namespace sailshape;

namespace {

EmulatedTurntableParams fastDrive() {
  EmulatedTurntableParams p;
  p.home_speed_deg_s = 720;
  p.acceleration_deg_s2 = 3600;
  return p;
}

TurntableLinkParams linkTo(const EmulatedTurntable& drive, int timeout_ms = 2000) {
  TurntableLinkParams l;
  l.device = drive.devicePath();
  l.baud = 115200;
  l.reply_timeout_ms = timeout_ms;
  return l;
}

}  // namespace

TEST(TurntableProtocol, RepliesRoundTrip) {
  TurntableStatus s;
  s.state = TurntableState::Moving;
  s.homed = true;
  s.counts = -12345;
  s.velocity_deg_s = 12.5;
  const auto back = parseStatus(formatStatus(s));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->state, TurntableState::Moving);
  EXPECT_TRUE(back->homed);
  EXPECT_EQ(back->counts, -12345);
  EXPECT_DOUBLE_EQ(back->velocity_deg_s, 12.5);
  const auto pos = parsePosition(formatPosition({360000, 42}));
  ASSERT_TRUE(pos);
  EXPECT_EQ(pos->counts, 360000);
  EXPECT_EQ(pos->device_time_us, 42u);
  EXPECT_DOUBLE_EQ(countsToDeg(pos->counts), 360.0);
  const auto err = parseError(formatError(TurntableErrorCode::NotHomed, "home first"));
  ASSERT_TRUE(err);
  EXPECT_EQ(err->first, TurntableErrorCode::NotHomed);
  EXPECT_EQ(err->second, "NOT_HOMED home first");
  EXPECT_FALSE(parseStatus("STAT SPINNING 1 0 0 0"));
  EXPECT_FALSE(parseStatus("POS 1 2"));
  EXPECT_FALSE(parsePosition("POS x"));
  EXPECT_FALSE(parseError("ERR 99 X"));
  EXPECT_FALSE(parseError("OK"));
}

TEST(EmulatedTurntable, ErrorReplies) {
  EmulatedTurntable drive(fastDrive());
  EXPECT_EQ(drive.handle("SPIN"), "ERR 1 UNKNOWN_COMMAND SPIN");
  EXPECT_EQ(drive.handle(""), "ERR 1 UNKNOWN_COMMAND empty line");
  EXPECT_EQ(drive.handle("VEL fast").substr(0, 5), "ERR 2");
  EXPECT_EQ(drive.handle("VEL 10 20").substr(0, 5), "ERR 2");
  EXPECT_EQ(drive.handle("VEL -1").substr(0, 5), "ERR 2");
  EXPECT_EQ(drive.handle("ACC 0").substr(0, 5), "ERR 2");
  EXPECT_EQ(drive.handle("MOVA 10").substr(0, 5), "ERR 3");
  EXPECT_EQ(drive.handle("MOVR 10").substr(0, 5), "ERR 3");
  EXPECT_EQ(drive.handle(std::string(100, 'X')).substr(0, 5), "ERR 2");
  EXPECT_EQ(drive.handle("VEL 45\r"), "OK");
}

TEST(Turntable, HomeMoveAndReportThroughThePty) {
  EmulatedTurntable drive(fastDrive());
  TurntableClient client(linkTo(drive));
  EXPECT_EQ(client.identify(), "sailshape-turntable-emulator 1 360000");
  EXPECT_FALSE(client.status().homed);
  EXPECT_THROW(client.moveAbsolute(10), TurntableError);
  client.home(10.0);
  TurntableStatus s = client.status();
  EXPECT_TRUE(s.homed);
  EXPECT_EQ(s.state, TurntableState::Idle);
  EXPECT_EQ(s.counts, 0);

  client.setVelocity(90);
  client.setAcceleration(900);
  const double before = hostTimeSeconds();
  const auto t_before = TurntableMotion::Clock::now();
  client.moveAbsolute(45);
  const auto t_after = TurntableMotion::Clock::now();
  try {
    client.moveAbsolute(10);
    ADD_FAILURE() << "a move while moving must be refused";
  } catch (const TurntableError& e) {
    EXPECT_EQ(e.code, TurntableErrorCode::Busy);
  }
  const TurntableSample mid = client.sample();
  EXPECT_GE(mid.host_time_s, before);
  ASSERT_TRUE(client.waitIdle(5.0));
  EXPECT_EQ(client.status().counts, 45000);
  EXPECT_EQ(client.sample().counts, 45000);
  // Trapezoid: 0.1 s ramps at 900 °/s², cruise at 90 °/s. 0.3 s after the start the table is at
  // 4.5° + 90 °/s · 0.2 s = 22.5°; the start lies between t_before and t_after.
  EXPECT_LE(drive.motion().angleDegAt(t_before + std::chrono::milliseconds(300)), 22.5 + 1e-9);
  EXPECT_GE(drive.motion().angleDegAt(t_after + std::chrono::milliseconds(300)), 22.5 - 1e-9);
  EXPECT_NEAR(drive.motion().angleDegAt(t_before - std::chrono::milliseconds(5)), 0.0, 1e-12);

  client.moveRelative(-15);
  ASSERT_TRUE(client.waitIdle(5.0));
  EXPECT_EQ(client.sample().counts, 30000);
  try {
    client.moveAbsolute(800);
    ADD_FAILURE() << "beyond the cable wrap";
  } catch (const TurntableError& e) {
    EXPECT_EQ(e.code, TurntableErrorCode::OutOfRange);
  }
  try {
    client.setVelocity(1000);
    ADD_FAILURE() << "beyond the drive's speed";
  } catch (const TurntableError& e) {
    EXPECT_EQ(e.code, TurntableErrorCode::BadArgument);
  }
}

TEST(Turntable, StopDeceleratesAndHolds) {
  EmulatedTurntable drive(fastDrive());
  TurntableClient client(linkTo(drive));
  client.home(10.0);
  client.setVelocity(90);
  client.moveAbsolute(600);
  while (client.sample().deg() < 5.0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  client.stop();
  ASSERT_TRUE(client.waitIdle(5.0));
  const int64_t held = client.sample().counts;
  EXPECT_GT(held, 5000);
  EXPECT_LT(held, 600000);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(client.sample().counts, held);
}

TEST(Turntable, NeverFindsHomeIsAClearError) {
  EmulatedTurntableParams p = fastDrive();
  p.home_sensor_works = false;
  p.home_search_deg = 90;
  EmulatedTurntable drive(p);
  TurntableClient client(linkTo(drive));
  try {
    client.home(10.0);
    ADD_FAILURE() << "homing must fail";
  } catch (const TurntableError& e) {
    EXPECT_EQ(e.code, TurntableErrorCode::HomeNotFound);
    EXPECT_NE(std::string(e.what()).find("never found the home sensor"), std::string::npos) << e.what();
  }
  const TurntableStatus s = client.status();
  EXPECT_EQ(s.state, TurntableState::Error);
  EXPECT_FALSE(s.homed);
  EXPECT_THROW(client.moveAbsolute(10), TurntableError);
}

TEST(Turntable, SilentDriveTimesOut) {
  EmulatedTurntableParams p = fastDrive();
  p.silent = true;
  EmulatedTurntable drive(p);
  TurntableClient client(linkTo(drive, 150));
  try {
    client.identify();
    ADD_FAILURE() << "no reply expected";
  } catch (const TurntableError& e) {
    EXPECT_NE(std::string(e.what()).find("no reply"), std::string::npos) << e.what();
  }
}

TEST(Turntable, BadLinks) {
  TurntableLinkParams l;
  l.device = "/nonexistent/ttyUSB9";
  EXPECT_THROW(TurntableClient{l}, TurntableError);
  l.device = "/dev/null";  // not a serial line
  EXPECT_THROW(TurntableClient{l}, TurntableError);
  l.baud = 12345;
  EXPECT_THROW(TurntableClient{l}, InvalidInput);
  l.baud = 9600;
  l.reply_timeout_ms = 0;
  EXPECT_THROW(TurntableClient{l}, InvalidInput);
}
