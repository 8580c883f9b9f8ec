// The scanner emulator through a real TCP socket: SICK's recorded driver
// command sequence gets replies of the recorded types, and the stream carries
// the point count the output range implies, ranges from the scene.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "acquisition/capture.hpp"
#include "acquisition/cola.hpp"
#include "acquisition/scan_data.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

using namespace sailshape;

namespace {

// A raw CoLa connection for the tests (the product's client is tested elsewhere).
class RawCola {
 public:
  RawCola(uint16_t port, ColaDialect dialect) : decoder_({dialect}), dialect_(dialect) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) throw std::runtime_error("connect failed");
  }
  ~RawCola() { ::close(fd_); }
  void send(const std::string& payload) {
    const std::string f = frameCola(dialect_, payload);
    ASSERT_EQ(::send(fd_, f.data(), f.size(), MSG_NOSIGNAL), static_cast<ssize_t>(f.size()));
  }
  // Next payload whose type is not `skip_type`, within timeout; empty on timeout or close.
  std::string next(double timeout_s = 3.0, const std::string& skip_type = "") {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      while (auto p = decoder_.next())
        if (skip_type.empty() || p->compare(0, 3, skip_type) != 0) return *p;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0) return {};
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      char buf[8192];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) {
        closed_ = true;
        return {};
      }
      decoder_.feed(std::string_view(buf, static_cast<size_t>(n)));
    }
  }
  bool closed() const { return closed_; }

 private:
  int fd_ = -1;
  ColaStreamDecoder decoder_;
  ColaDialect dialect_;
  bool closed_ = false;
};

// A cloth wall 4 m in front of the unit (along +Y of the unit frame, where the device's 90° looks at β = 0).
Scene wallScene() {
  Scene s;
  s.objects.push_back({"wall", Material::Cloth,
                       makeQuad(Vec3(-30, 4, -30), Vec3(30, 4, -30), Vec3(30, 4, 30), Vec3(-30, 4, 30))});
  return s;
}

ScannerEmulatorParams params(ScannerModel model) {
  ScannerEmulatorParams p;
  p.port = 0;
  p.sensor.model = model;
  return p;
}

struct Recorded {
  std::vector<std::pair<std::string, std::string>> exchanges;  // request payload, type of the device's reply
  size_t first_scan_values = 0;
};

// Pairs each request with the next reply of the same name (the LMS111 repeats some replies: extras are skipped).
Recorded readRecording(const std::string& file) {
  const CaptureTelegrams tel = extractTelegrams(readCapture(std::string(SAILSHAPE_SHARED) + "/sick-recordings/" + file));
  Recorded r;
  std::vector<std::string> pending;
  for (const CapturedTelegram& t : tel.telegrams) {
    const ColaTelegram c = splitColaTelegram(t.payload);
    if (t.direction == CaptureDirection::kToDevice) {
      pending.push_back(t.payload);
    } else if (c.type == "sSN") {
      if (c.name == "LMDscandata" && r.first_scan_values == 0)
        r.first_scan_values = decodeScanData(t.payload, ColaDialect::kBinary).channel("DIST1")->values.size();
    } else {
      for (auto it = pending.begin(); it != pending.end(); ++it)
        if (splitColaTelegram(*it).name == c.name) {
          r.exchanges.emplace_back(*it, c.type);
          pending.erase(it);
          break;
        }
    }
  }
  return r;
}

void answersLikeTheRecordedDevice(ScannerModel model, const std::string& file) {
  const Recorded rec = readRecording(file);
  ASSERT_GT(rec.exchanges.size(), 40u);
  ASSERT_GT(rec.first_scan_values, 0u);
  ScannerEmulator emu(wallScene(), params(model));
  RawCola cola(emu.port(), ColaDialect::kBinary);
  for (const auto& [req, reply_type] : rec.exchanges) {
    const ColaTelegram q = splitColaTelegram(req);
    cola.send(req);
    const std::string reply = cola.next(3.0, "sSN");
    ASSERT_FALSE(reply.empty()) << "no reply to " << q.type << " " << q.name;
    const ColaTelegram a = splitColaTelegram(reply);
    EXPECT_EQ(a.type, reply_type) << q.type << " " << q.name;
    EXPECT_EQ(a.name, q.name);
  }
  // Streaming is on: scans carry the point count the driver's output range implies (as the device sent).
  const std::string scan = cola.next(3.0);
  ASSERT_FALSE(scan.empty());
  const ScanData d = decodeScanData(scan, ColaDialect::kBinary);
  EXPECT_EQ(d.command_type, "sSN");
  EXPECT_EQ(d.channel("DIST1")->values.size(), rec.first_scan_values);
  EXPECT_EQ(d.version, model == ScannerModel::Lms111 ? 1 : 0);
}

// Log in, start measuring and switch the stream on, in CoLa B, each reply read.
void startStreaming(RawCola& cola) {
  cola.send(colaPayload("sMN", "SetAccessMode", ColaWriter(ColaDialect::kBinary).u8(3).u32(0xF4724744u).bytes()));
  cola.next();
  cola.send("sMN LMCstartmeas");
  cola.next();
  cola.send(colaPayload("sEN", "LMDscandata", ColaWriter(ColaDialect::kBinary).u8(1).bytes()));
  cola.next();
}

// One request and its reply, skipping streamed scans.
ColaTelegram request(RawCola& cola, const std::string& type, const std::string& name, const ColaWriter& w) {
  cola.send(colaPayload(type, name, w.bytes()));
  return splitColaTelegram(cola.next(3.0, "sSN"));
}

}  // namespace

TEST(ScannerEmulator, Lms111AnswersTheRecordedStartupSequence) {
  answersLikeTheRecordedDevice(ScannerModel::Lms111, "20210302_lms111.pcapng.json");
}

TEST(ScannerEmulator, Lms511AnswersTheRecordedStartupSequence) {
  answersLikeTheRecordedDevice(ScannerModel::Lms511, "20210302_lms511.pcapng.json");
}

TEST(ScannerEmulator, StreamsRayCastRangesAtTheConfiguredRate) {
  ScannerEmulatorParams p = params(ScannerModel::Lms511);
  ScannerEmulator emu(wallScene(), p);
  RawCola cola(emu.port(), ColaDialect::kBinary);
  const auto ask = [&](const std::string& type, const std::string& name, const ColaWriter& w) {
    return request(cola, type, name, w);
  };
  using W = ColaWriter;
  EXPECT_EQ(ask("sMN", "SetAccessMode", W(ColaDialect::kBinary).u8(3).u32(0xF4724744u)).arguments, std::string(1, '\x01'));
  // 50 Hz, 1°, 60°..120°: 61 values.
  const ColaTelegram cfg = ask("sMN", "mLMPsetscancfg", W(ColaDialect::kBinary).u32(5000).u16(1).u32(10000).i32(600000).i32(1200000));
  EXPECT_EQ(cfg.arguments[0], '\x00') << "status: no error";
  ask("sWN", "LMDscandatacfg", W(ColaDialect::kBinary).u8(1).u8(0).u8(1).u8(0).u8(0).u8(0).u8(0).u8(0).u8(0).u8(0).u8(0).u16(1));
  EXPECT_EQ(ask("sMN", "LMCstartmeas", W(ColaDialect::kBinary)).type, "sAN");
  EXPECT_EQ(ask("sMN", "Run", W(ColaDialect::kBinary)).type, "sAN");
  EXPECT_EQ(ask("sEN", "LMDscandata", W(ColaDialect::kBinary).u8(1)).type, "sEA");
  std::vector<ScanData> scans;
  while (scans.size() < 10) {
    const std::string s = cola.next(3.0);
    ASSERT_FALSE(s.empty());
    if (isScanDataTelegram(s)) scans.push_back(decodeScanData(s, ColaDialect::kBinary));
  }
  for (size_t k = 0; k < scans.size(); ++k) {
    const ScanChannel* dist = scans[k].channel("DIST1");
    ASSERT_NE(dist, nullptr);
    ASSERT_EQ(dist->values.size(), 61u);
    ASSERT_NE(scans[k].channel("RSSI1"), nullptr);
    EXPECT_EQ(scans[k].scan_frequency, 5000u);
    EXPECT_EQ(dist->start_angle, 600000);
    EXPECT_EQ(dist->angular_step, 10000);
    if (k > 0) {
      EXPECT_EQ(scans[k].scan_counter, scans[k - 1].scan_counter + 1);
      // Scan start stamps one period (20 ms) apart on the device clock.
      EXPECT_EQ(scans[k].time_since_startup_us - scans[k - 1].time_since_startup_us, 20000u);
    }
    // The wall at 4 m: r = 4 / sin α, within 5σ of cloth noise plus the 0.3 % systematic bound.
    for (size_t i = 0; i < dist->values.size(); ++i) {
      const double alpha = scanAngleRad(*dist, i);
      const double expect = 4.0 / std::sin(alpha);
      ASSERT_GT(dist->values[i], 0u);
      EXPECT_NEAR(scanRangeMm(*dist, i) / 1000.0, expect, 5 * 0.0041 + 0.003 * expect + 0.0005) << "beam " << i;
    }
  }
  // Stop streaming: no further scan.
  cola.send(colaPayload("sEN", "LMDscandata", W(ColaDialect::kBinary).u8(0).bytes()));
  std::string r;
  do r = cola.next(1.0); while (!r.empty() && r.compare(0, 3, "sSN") == 0);
  ASSERT_EQ(r.substr(0, 3), "sEA");
  EXPECT_TRUE(cola.next(0.2).empty());
}

// A host too slow to compute 50 Hz (30 ms more per scan than the 20 ms period) falls behind; past
// max_lag_s the emulator drops scans as a device drops what its output cannot send. The scan counter
// still counts them, every scan sent keeps its own start stamp, and none is sent later than the lag
// allows, so the stream keeps to the turntable's time instead of lagging ever further behind it.
TEST(ScannerEmulator, AHostTooSlowForTheRateDropsScansInsteadOfLagging) {
  ScannerEmulatorParams p = params(ScannerModel::Lms511);
  p.slow_host_s = 0.03;
  p.max_lag_s = 0.1;
  ScannerEmulator emu(wallScene(), p);
  RawCola cola(emu.port(), ColaDialect::kBinary);
  // Logged in, 50 Hz at 1° over 60°..120°, measuring and streaming.
  const ColaWriter none(ColaDialect::kBinary);
  for (const auto& [type, name, args] : std::vector<std::tuple<std::string, std::string, ColaWriter>>{
           {"sMN", "SetAccessMode", ColaWriter(none).u8(3).u32(0xF4724744u)},
           {"sMN", "mLMPsetscancfg", ColaWriter(none).u32(5000).u16(1).u32(10000).i32(600000).i32(1200000)},
           {"sMN", "LMCstartmeas", none},
           {"sMN", "Run", none},
           {"sEN", "LMDscandata", ColaWriter(none).u8(1)}})
    ASSERT_NE(request(cola, type, name, args).type, "sFA") << name;
  std::vector<ScanData> scans;
  while (scans.size() < 40) {
    const std::string s = cola.next(3.0);
    ASSERT_FALSE(s.empty());
    if (isScanDataTelegram(s)) scans.push_back(decodeScanData(s, ColaDialect::kBinary));
  }
  uint64_t gaps = 0;
  for (size_t k = 1; k < scans.size(); ++k) {
    const uint16_t step = static_cast<uint16_t>(scans[k].scan_counter - scans[k - 1].scan_counter);
    ASSERT_GE(step, 1u);
    gaps += step - 1u;
    // Each scan's start stamp stands `step` periods after the previous one: a dropped scan is a gap in time.
    EXPECT_EQ(scans[k].time_since_startup_us - scans[k - 1].time_since_startup_us, 20000u * step);
    // Sent within the lag allowed, plus one period of measuring and the slow host's own time, and 150 ms
    // of scheduling slack for a loaded machine. (Without dropping, the 40th scan would go 0.44 s late.)
    EXPECT_LT(scans[k].time_of_transmission_us - scans[k].time_since_startup_us, (0.1 + 0.02 + 0.03 + 0.15) * 1e6);
  }
  // The 40 sends, each ≥ 30 ms, span ≥ 1.17 s. A start stamp precedes its send by ≥ 50 ms (a period and
  // the slow host) and by ≤ 150 ms (plus the lag allowed), so the stamps span ≥ 1.07 s, 53.5 periods, of
  // which 39 steps were sent: at least 15 scans were dropped.
  EXPECT_GE(gaps, 15u);
  EXPECT_GE(emu.scansDropped(), gaps);
}

TEST(ScannerEmulator, AsciiDialectAndErrors) {
  ScannerEmulator emu(wallScene(), params(ScannerModel::Lms111));
  RawCola cola(emu.port(), ColaDialect::kAscii);
  cola.send("sRN FirmwareVersion");
  const ColaTelegram fw = splitColaTelegram(cola.next());
  EXPECT_EQ(fw.type, "sRA");
  EXPECT_EQ(ColaReader(ColaDialect::kAscii, fw.arguments, "fw").string("version"), "V1.80.2  ");
  cola.send("sMN LMCstartmeas");  // before login
  EXPECT_EQ(cola.next().substr(0, 3), "sFA");
  cola.send("sRN NoSuchVariable");
  EXPECT_EQ(cola.next().substr(0, 3), "sFA");
  cola.send("sMN SetAccessMode 3 12345678");  // wrong password
  EXPECT_EQ(cola.next(), "sAN SetAccessMode 0");
  cola.send("sMN SetAccessMode 3 F4724744");
  EXPECT_EQ(cola.next(), "sAN SetAccessMode 1");
  cola.send("sMN mLMPsetscancfg 1388 1 3E8 FFF92230 225510");  // 0.1° is not an LMS111 resolution
  const ColaTelegram bad = splitColaTelegram(cola.next());
  EXPECT_EQ(bad.type, "sAN");
  EXPECT_NE(ColaReader(ColaDialect::kAscii, bad.arguments, "cfg").u8("status"), 0);
  cola.send("sRN LMDscandata");  // polled scan
  const std::string polled = cola.next();
  const ScanData d = decodeScanData(polled, ColaDialect::kAscii);
  EXPECT_EQ(d.command_type, "sRA");
  EXPECT_EQ(d.channel("DIST1")->values.size(), 541u);
}

TEST(ScannerEmulator, Faults) {
  ScannerEmulatorParams p = params(ScannerModel::Lms511);
  p.refuse_login = true;
  {
    ScannerEmulator emu(wallScene(), p);
    RawCola cola(emu.port(), ColaDialect::kBinary);
    cola.send(colaPayload("sMN", "SetAccessMode", ColaWriter(ColaDialect::kBinary).u8(3).u32(0xF4724744u).bytes()));
    EXPECT_EQ(splitColaTelegram(cola.next()).arguments, std::string(1, '\0'));
  }
  p = params(ScannerModel::Lms511);
  p.mute = true;
  {
    ScannerEmulator emu(wallScene(), p);
    RawCola cola(emu.port(), ColaDialect::kBinary);
    cola.send("sRN FirmwareVersion");
    EXPECT_TRUE(cola.next(0.3).empty());
    EXPECT_FALSE(cola.closed());
  }
  p = params(ScannerModel::Lms511);
  p.drop_after_scans = 3;
  {
    ScannerEmulator emu(wallScene(), p);
    RawCola cola(emu.port(), ColaDialect::kBinary);
    startStreaming(cola);
    int scans = 0;
    while (!cola.next(2.0).empty()) ++scans;
    EXPECT_EQ(scans, 3);
    EXPECT_TRUE(cola.closed());
  }
  p = params(ScannerModel::Lms511);
  p.bind_address = "not-an-address";
  EXPECT_THROW(ScannerEmulator(wallScene(), p), std::runtime_error);
}

// A unit still starting answers "busy" (the recorded units said 0 then) and streams nothing; once its
// spin-up is over it answers "ready" and the stream begins.
TEST(ScannerEmulator, AStartingUnitIsBusyAndStreamsOnlyOnceReady) {
  ScannerEmulatorParams p = params(ScannerModel::Lms511);
  p.spin_up_s = 1.5;
  const auto power_on = std::chrono::steady_clock::now();
  ScannerEmulator emu(wallScene(), p);
  RawCola cola(emu.port(), ColaDialect::kBinary);
  cola.send("sRN SCdevicestate");
  EXPECT_EQ(splitColaTelegram(cola.next()).arguments, std::string(1, '\0'));  // busy
  startStreaming(cola);
  EXPECT_FALSE(cola.next(4.0).empty()) << "no scan after the spin-up";
  const double first_scan_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - power_on).count();
  EXPECT_GE(first_scan_s, 1.5) << "a scan came before the unit was ready";
  cola.send("sRN SCdevicestate");
  EXPECT_EQ(splitColaTelegram(cola.next(3.0, "sSN")).arguments, std::string(1, '\1'));  // ready
}

TEST(ScannerEmulator, BetaFollowsTheTurntable) {
  // p = 0, θ = 0: at β the beam at α = 90° points along (0, cos β, sin β); a floor at z = -2 is met
  // at r = 2 / sin(-β) for β < 0.
  Scene s;
  s.objects.push_back({"floor", Material::Paint, makeQuad(Vec3(-30, -30, -2), Vec3(30, -30, -2), Vec3(30, 30, -2), Vec3(-30, 30, -2))});
  EmulatedTurntableParams tp;
  tp.home_speed_deg_s = 720;
  tp.acceleration_deg_s2 = 3600;
  TurntableMotion table(tp);
  table.home();
  while (table.status().state != TurntableState::Idle) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  table.setVelocity(360);
  ASSERT_EQ(table.moveTo(-60), TurntableErrorCode::None);
  while (table.status().state != TurntableState::Idle) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ScannerEmulatorParams p = params(ScannerModel::Lms511);
  p.sensor.noise_scale = 0;
  p.sensor.systematic_fraction = 0;
  ScannerEmulator emu(s, p, &table);
  // A polled scan covers the last period: let the table rest for longer than that.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::string polled = emu.reply("sRN LMDscandata", true);
  const ScanData d = decodeScanData(polled, ColaDialect::kBinary);
  const ScanChannel* dist = d.channel("DIST1");
  const size_t i90 = static_cast<size_t>(std::lround((90.0 - scanAngleDeg(*dist, 0)) / (dist->angular_step / 10000.0)));
  const double alpha = scanAngleRad(*dist, i90);
  // Beam direction (cos α, sin α cos β, sin α sin β): z-component sin α sin(-60°).
  EXPECT_NEAR(scanRangeMm(*dist, i90) / 1000.0, 2.0 / (std::sin(alpha) * std::sin(60 * kRadPerDeg)), 0.0015);
}

namespace {

// One request of SICK's driver sick_scan_xd 3.x as it sends it (driver/src/sick_scan_common.cpp: the
// ASCII command, and what convertAscii2BinaryCmd makes of it for CoLa B), and the reply type a device gives.
struct DriverRequest {
  std::string ascii;   // payload in CoLa A, as the driver writes it
  std::string binary;  // payload in CoLa B
  std::string reply_type;
};

DriverRequest req(const std::string& type, const std::string& name, const std::string& ascii_args,
                  const ColaWriter& binary_args, const std::string& reply_type) {
  return {colaPayload(type, name, ascii_args), colaPayload(type, name, binary_args.bytes()), reply_type};
}

// sick_scan_xd's start-up for an LMS1xx or LMS5xx (one layer: no LMCstopmeas, no application switch),
// with an encoder asked for (encoder_mode 2), through to streaming.
std::vector<DriverRequest> driverStartup(ScannerModel model, ColaDialect dialect) {
  const bool lms5xx = model == ScannerModel::Lms511;
  const ColaWriter B(ColaDialect::kBinary);
  const auto u8 = [&](uint8_t v) { return ColaWriter(B).u8(v); };
  const ColaWriter login = ColaWriter(B).u8(3).u32(0xF4724744u);
  std::vector<DriverRequest> out = {
      req("sRN", "SCdevicestate", "", B, "sRA"),  // which dialect the device speaks
      req("sMN", "SetAccessMode", "3 F4724744", login, "sAN"),
      dialect == ColaDialect::kBinary ? req("sWN", "EIHstCola", "1", u8(1), "sWA") : req("sWN", "EIHstCola", "0", u8(0), "sWA"),
      req("sRN", "FirmwareVersion", "", B, "sRA"),
      req("sRN", "SCdevicestate", "", B, "sRA"),
      req("sRN", "ODoprh", "", B, "sRA"),
      req("sRN", "ODpwrc", "", B, "sRA"),
      req("sRN", "LocationName", "", B, "sRA")};
  if (lms5xx) out.push_back(req("sWN", "DO3And4Fnc", "1", u8(1), "sWA"));
  out.push_back(req("sWN", "LICsrc", "1", u8(1), "sWA"));
  out.push_back(req("sWN", "LICencset", "2", u8(2), "sWA"));
  out.push_back(req("sWN", "LICencres", "3F800000", ColaWriter(B).f32(1.0f), "sWA"));
  const int32_t first = lms5xx ? -50000 : -450000, last = lms5xx ? 1850000 : 2250000;
  const uint32_t step = lms5xx ? 1667 : 5000, frequency = lms5xx ? 2500 : 5000;
  const ColaWriter range = ColaWriter(B).u16(1).u32(step).i32(first).i32(last);
  const ColaWriter range_a = ColaWriter(ColaDialect::kAscii).u16(1).u32(step).i32(first).i32(last);
  out.push_back(req("sRN", "LMPoutputRange", "", B, "sRA"));
  out.push_back(req("sWN", "LMPoutputRange", range_a.bytes(), range, "sWA"));
  out.push_back(req("sRN", "LMPoutputRange", "", B, "sRA"));
  const ColaWriter cfg = ColaWriter(B).u8(1).u8(0).u8(1).u8(1).u8(0).u8(1).u8(0).u8(0).u8(0).u8(0).u8(1).u16(1);
  out.push_back(req("sWN", "LMDscandatacfg", "1 0 1 1 0 1 0 0 0 0 1 1", cfg, "sWA"));
  out.push_back(req("sRN", "LMDscandatacfg", "", B, "sRA"));
  if (lms5xx) {  // sendSopasRunSetAccessMode before the scan configuration
    out.push_back(req("sMN", "Run", "", B, "sAN"));
    out.push_back(req("sMN", "SetAccessMode", "3 F4724744", login, "sAN"));
  }
  const std::string scancfg_a = "+" + std::to_string(frequency) + " +1 +" + std::to_string(step) + " " +
                                (first < 0 ? "-" : "+") + std::to_string(std::abs(first)) + " +" + std::to_string(last);
  out.push_back(req("sMN", "mLMPsetscancfg", scancfg_a, ColaWriter(B).u32(frequency).u16(1).u32(step).i32(first).i32(last), "sAN"));
  out.push_back(req("sRN", "LMPscancfg", "", B, "sRA"));
  if (lms5xx) out.push_back(req("sWN", "FREchoFilter", "2", u8(2), "sWA"));
  out.push_back(req("sMN", "LMCstartmeas", "", B, "sAN"));
  out.push_back(req("sMN", "Run", "", B, "sAN"));
  out.push_back(req("sEN", "LMDscandata", "1", u8(1), "sEA"));
  return out;
}

void answersTheCurrentDriver(ScannerModel model, ColaDialect dialect) {
  ScannerEmulator emu(wallScene(), params(model));
  RawCola cola(emu.port(), dialect);
  for (const DriverRequest& r : driverStartup(model, dialect)) {
    const std::string& payload = dialect == ColaDialect::kBinary ? r.binary : r.ascii;
    cola.send(payload);
    const std::string reply = cola.next(3.0, "sSN");
    ASSERT_FALSE(reply.empty()) << "no reply to " << payload;
    const ColaTelegram q = splitColaTelegram(payload), a = splitColaTelegram(reply);
    ASSERT_EQ(a.type, r.reply_type) << q.type << " " << q.name << " got '" << reply.substr(0, 40) << "'";
    EXPECT_EQ(a.name, q.name);
  }
  const std::string scan = cola.next(3.0);
  ASSERT_FALSE(scan.empty());
  const ScanData d = decodeScanData(scan, dialect);
  EXPECT_EQ(d.channel("DIST1")->values.size(), model == ScannerModel::Lms511 ? 1141u : 541u);
  EXPECT_EQ(d.encoders.size(), 1u);
}

}  // namespace

TEST(ScannerEmulator, Lms511AnswersTheCurrentDriversStartupInCoLaB) {
  answersTheCurrentDriver(ScannerModel::Lms511, ColaDialect::kBinary);
}
TEST(ScannerEmulator, Lms511AnswersTheCurrentDriversStartupInCoLaA) {
  answersTheCurrentDriver(ScannerModel::Lms511, ColaDialect::kAscii);
}
TEST(ScannerEmulator, Lms111AnswersTheCurrentDriversStartupInCoLaB) {
  answersTheCurrentDriver(ScannerModel::Lms111, ColaDialect::kBinary);
}
TEST(ScannerEmulator, Lms111AnswersTheCurrentDriversStartupInCoLaA) {
  answersTheCurrentDriver(ScannerModel::Lms111, ColaDialect::kAscii);
}

// An LMS5xx keeps its echo filter (0 first, 1 all, 2 last echo) and refuses others; the LMS1xx has none.
TEST(ScannerEmulator, Lms511KeepsItsEchoFilter) {
  ScannerEmulator emu(wallScene(), params(ScannerModel::Lms511));
  EXPECT_EQ(emu.reply("sWN FREchoFilter 2", false), "sFA A");  // a write before the login
  EXPECT_EQ(emu.reply("sMN SetAccessMode 3 F4724744", false), "sAN SetAccessMode 1");
  EXPECT_EQ(emu.reply("sRN FREchoFilter", false), "sRA FREchoFilter 0");
  EXPECT_EQ(emu.reply("sWN FREchoFilter 2", false), "sWA FREchoFilter ");
  EXPECT_EQ(emu.reply("sRN FREchoFilter", false), "sRA FREchoFilter 2");
  EXPECT_EQ(emu.reply("sWN FREchoFilter 3", false), "sFA 4");
  EXPECT_EQ(emu.reply("sRN FREchoFilter", true), "sRA FREchoFilter " + std::string(1, '\x02'));
  EXPECT_EQ(emu.reply("sWN FREchoFilter " + std::string(1, '\x01'), true), "sWA FREchoFilter ");
  EXPECT_EQ(emu.reply("sRN FREchoFilter", true), "sRA FREchoFilter " + std::string(1, '\x01'));

  ScannerEmulator lms111(wallScene(), params(ScannerModel::Lms111));
  EXPECT_EQ(lms111.reply("sMN SetAccessMode 3 F4724744", false), "sAN SetAccessMode 1");
  EXPECT_EQ(lms111.reply("sWN FREchoFilter 2", false), "sFA 3");
  EXPECT_EQ(lms111.reply("sRN FREchoFilter", true), "sFA" + std::string("\x00\x03", 2));
}

// LMPscancfg is the scan configuration (frequency, sectors, step, sector start and stop), whatever the
// output range: narrowing the output to 60°..120° leaves it at the sector mLMPsetscancfg set.
TEST(ScannerEmulator, LmpScancfgAnswersTheScanConfigurationNotTheOutputRange) {
  ScannerEmulator emu(wallScene(), params(ScannerModel::Lms511));
  EXPECT_EQ(emu.reply("sMN SetAccessMode 3 F4724744", false), "sAN SetAccessMode 1");
  EXPECT_EQ(emu.reply("sRN LMPscancfg", false), "sRA LMPscancfg 9C4 1 683 FFFF3CB0 1C3A90");  // 25 Hz, 0.1667°, -5°..185°
  EXPECT_EQ(emu.reply("sMN mLMPsetscancfg +5000 +1 +5000 -50000 +1850000", false),
            "sAN mLMPsetscancfg 0 1388 1 1388 FFFF3CB0 1C3A90");
  EXPECT_EQ(emu.reply("sWN LMPoutputRange 1 1388 927C0 124F80", false), "sWA LMPoutputRange ");  // 60°..120°
  EXPECT_EQ(emu.reply("sRN LMPoutputRange", false), "sRA LMPoutputRange 1 1388 927C0 124F80");
  EXPECT_EQ(emu.reply("sRN LMPscancfg", false), "sRA LMPscancfg 1388 1 1388 FFFF3CB0 1C3A90");
  const ColaWriter B(ColaDialect::kBinary);
  EXPECT_EQ(emu.reply("sRN LMPscancfg", true),
            colaPayload("sRA", "LMPscancfg", ColaWriter(B).u32(5000).u16(1).u32(5000).i32(-50000).i32(1850000).bytes()));
  // The scans carry the output range: 60°..120° in 0.5° steps.
  const ScanData d = decodeScanData(emu.reply("sRN LMDscandata", true), ColaDialect::kBinary);
  EXPECT_EQ(d.channel("DIST1")->values.size(), 121u);
  EXPECT_EQ(d.channel("DIST1")->start_angle, 600000);
  // An output range beyond the measured sector is refused.
  EXPECT_EQ(emu.reply("sMN mLMPsetscancfg +5000 +1 +5000 +300000 +1500000", false),
            "sAN mLMPsetscancfg 0 1388 1 1388 493E0 16E360");
  EXPECT_EQ(emu.reply("sWN LMPoutputRange 1 1388 0 124F80", false), "sFA 4");
}

// The error numbers of SICK's driver's table (sick_scan_xd SopasBase): 1 method access denied, 2 unknown
// method, 3 unknown variable, 5 invalid data, 10 write access denied, 12 unknown command, 15 unknown event.
TEST(ScannerEmulator, ErrorRepliesUseTheDriversSopasCodes) {
  ScannerEmulator emu(wallScene(), params(ScannerModel::Lms511));
  EXPECT_EQ(emu.reply("sRN NoSuchVariable", false), "sFA 3");
  EXPECT_EQ(emu.reply("sRN NoSuchVariable", true), "sFA" + std::string("\x00\x03", 2));
  EXPECT_EQ(emu.reply("sWN NoSuchVariable 1", false), "sFA 3");
  EXPECT_EQ(emu.reply("sMN LMCstartmeas", false), "sFA 1");  // before the login
  EXPECT_EQ(emu.reply("sWN LMPoutputRange 1 683 0 10000", false), "sFA A");
  EXPECT_EQ(emu.reply("sMN mNoSuchMethod", false), "sFA 2");
  EXPECT_EQ(emu.reply("sMN mNoSuchMethod", true), "sFA" + std::string("\x00\x02", 2));
  EXPECT_EQ(emu.reply("sEN NoSuchEvent 1", false), "sFA F");
  EXPECT_EQ(emu.reply("sXN Something", false), "sFA C");
  EXPECT_EQ(emu.reply("sMN SetAccessMode 3 F4724744", false), "sAN SetAccessMode 1");
  EXPECT_EQ(emu.reply("sWN LMPoutputRange 1 683", false), "sFA 5");  // start and stop missing
}
