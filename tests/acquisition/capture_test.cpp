// Capture archives: our format written and read back (also cut short), pcapng-JSON recordings, bad files,
// and replayCapture's frames and JSON.
#include "acquisition/capture.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "acquisition/capture_replay.hpp"
#include "acquisition/turntable_protocol.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;
const std::string kRecordings = std::string(SAILSHAPE_SHARED) + "/sick-recordings/";

class CaptureFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sailshape-capture-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  fs::path dir_;
};

TEST_F(CaptureFiles, WriteAndReadBack) {
  const std::string login = frameCola(ColaDialect::kBinary, "sMN SetAccessMode " + std::string("\x03\xf4\x72\x47\x44", 5));
  const std::string reply = frameCola(ColaDialect::kBinary, "sAN SetAccessMode \x01");
  {
    CaptureWriter w(path("a.sscap"), ColaDialect::kBinary);
    w.append({CaptureDirection::kToDevice, 1700000000.25, login});
    w.append({CaptureDirection::kFromDevice, 1700000000.5, reply});
    EXPECT_THROW(CaptureWriter(path("a.sscap"), ColaDialect::kBinary), FileError);  // never overwrites
  }
  const Capture c = readCapture(path("a.sscap"));
  EXPECT_EQ(c.format, "sscap");
  EXPECT_EQ(c.dialect, ColaDialect::kBinary);
  EXPECT_TRUE(c.warnings.empty());
  ASSERT_EQ(c.records.size(), 2u);
  EXPECT_EQ(c.records[0].direction, CaptureDirection::kToDevice);
  EXPECT_EQ(c.records[0].time_s, 1700000000.25);
  EXPECT_EQ(c.records[0].bytes, login);
  EXPECT_EQ(c.records[1].bytes, reply);
  const CaptureTelegrams t = extractTelegrams(c);
  ASSERT_EQ(t.telegrams.size(), 2u);
  EXPECT_EQ(t.telegrams[1].payload, "sAN SetAccessMode \x01");
  EXPECT_EQ(t.telegrams[1].direction, CaptureDirection::kFromDevice);
}

TEST_F(CaptureFiles, FileCutShortKeepsCompleteRecords) {
  {
    CaptureWriter w(path("cut.sscap"), ColaDialect::kAscii);
    w.append({CaptureDirection::kFromDevice, 1.0, "\x02sAN Run 1\x03"});
    w.append({CaptureDirection::kFromDevice, 2.0, "\x02sEA LMDscandata 1\x03"});
  }
  for (size_t cut : {size_t{3}, size_t{15}}) {  // inside the last record's bytes, then inside its header
    const std::string name = "cut" + std::to_string(cut) + ".sscap";
    fs::copy_file(dir_ / "cut.sscap", dir_ / name);
    fs::resize_file(dir_ / name, fs::file_size(dir_ / name) - cut);
    const Capture c = readCapture(path(name));
    ASSERT_EQ(c.records.size(), 1u);
    EXPECT_EQ(c.records[0].bytes, "\x02sAN Run 1\x03");
    ASSERT_EQ(c.warnings.size(), 1u);
    EXPECT_NE(c.warnings[0].find("truncated"), std::string::npos);
  }
}

TEST_F(CaptureFiles, BadFilesAreErrorsNamingTheFile) {
  EXPECT_THROW(readCapture(path("missing")), FileError);
  write("text.txt", "hello");
  try {
    readCapture(path("text.txt"));
    FAIL() << "no exception";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("text.txt"), std::string::npos) << e.what();
  }
  write("short.sscap", "SSCAP001");
  EXPECT_THROW(readCapture(path("short.sscap")), FileError);
  write("dialect.sscap", std::string("SSCAP001\x07", 9));
  EXPECT_THROW(readCapture(path("dialect.sscap")), FileError);
  write("direction.sscap", std::string("SSCAP001\x00\x05", 10) + std::string(12, '\0'));
  EXPECT_THROW(readCapture(path("direction.sscap")), FileError);
  write("broken.json", "[{\"_source\": ");
  EXPECT_THROW(readCapture(path("broken.json")), FileError);
  write("nolayers.json", "[{\"a\": 1}]");
  EXPECT_THROW(readCapture(path("nolayers.json")), FileError);
  write("badhex.json", R"([{"_source":{"layers":{"tcp":{"tcp.payload":"02:0x"}}}}])");
  EXPECT_THROW(readCapture(path("badhex.json")), FileError);
  write("badsep.json", R"([{"_source":{"layers":{"tcp":{"tcp.payload":"02-02"}}}}])");
  EXPECT_THROW(readCapture(path("badsep.json")), FileError);
  write("numpayload.json", R"([{"_source":{"layers":{"tcp":{"tcp.payload":2}}}}])");
  EXPECT_THROW(readCapture(path("numpayload.json")), FileError);
  EXPECT_THROW(CaptureWriter(path("no/such/dir/x.sscap"), ColaDialect::kBinary), FileError);
}

TEST(CaptureRecordings, DirectionsAndTimesFromPcapJson) {
  const Capture c = readCapture(kRecordings + "20210302_lms111.pcapng.json");
  EXPECT_EQ(c.format, "pcapng-json");
  EXPECT_EQ(c.dialect, ColaDialect::kBinary);
  const CaptureTelegrams t = extractTelegrams(c);
  ASSERT_GE(t.telegrams.size(), 2u);
  EXPECT_EQ(t.telegrams[0].direction, CaptureDirection::kToDevice);
  EXPECT_EQ(t.telegrams[0].payload.substr(0, 17), "sMN SetAccessMode");
  EXPECT_EQ(t.telegrams[1].direction, CaptureDirection::kFromDevice);
  EXPECT_EQ(t.telegrams[1].payload, "sAN SetAccessMode \x01");
  // Time stamps are relative and never go backwards.
  for (size_t i = 1; i < t.telegrams.size(); ++i) EXPECT_GE(t.telegrams[i].time_s, t.telegrams[i - 1].time_s);
  EXPECT_NEAR(t.telegrams[0].time_s, 0.203, 0.001);  // first element's tcp.time_relative
}

TEST(CaptureReplay, RecordingFramesAndJson) {
  const ReplayResult r = replayCapture(kRecordings + "20210302_lms111.pcapng.json");
  ASSERT_GE(r.frames.size(), 170u);
  EXPECT_EQ(r.undecodable, 0u);
  EXPECT_EQ(r.frames[0].scan.telegram_counter, 63336);
  EXPECT_EQ(r.other_telegrams.at("sRN FirmwareVersion"), 1u);
  // The LMS111 answered the driver's duplicate LIDinputstate twice; every reply is counted.
  EXPECT_EQ(r.other_telegrams.at("sRA LIDinputstate"), 2u);
  const nlohmann::json j = replayJson(r);
  EXPECT_EQ(j["scan_frames"], r.frames.size());
  EXPECT_EQ(j["frames"][0]["channels16"][0]["start_angle_deg"], -45.0);
  EXPECT_EQ(j["frames"][0]["channels16"][0]["count"], 541);
  EXPECT_EQ(j["frames"][0]["time"]["year"], 1970);
  EXPECT_THROW(replayCapture(kRecordings + "README.md"), FileError);
}

// Two frames of a unit whose turntable encoder is wired to the scanner: β = 10° then 12° (one scan apart).
ReplayResult encoderFrames() {
  ReplayResult r;
  for (int k = 0; k < 2; ++k) {
    ScanData s;
    s.scan_counter = static_cast<uint16_t>(7 + k);
    s.scan_frequency = 2500;
    const double beta_deg = 10.0 + 2.0 * k;
    s.encoders = {{static_cast<uint32_t>(std::lround(beta_deg / 360.0 * kTurntableCountsPerRev)), 0}};
    // α = 0°, 6°, ..., 180°; echoes only at 0° and 180°.
    std::vector<uint16_t> dist(31, 0), rssi(31, 0);
    dist[0] = 2000;
    dist[30] = 3000;
    rssi[0] = 200;
    rssi[30] = 100;
    s.channels16 = {{"DIST1", 1.0f, 0.0f, 0, 60000, dist}};
    s.channels8 = {{"RSSI1", 1.0f, 0.0f, 0, 60000, rssi}};
    r.frames.push_back({static_cast<double>(k), s});
  }
  return r;
}

TEST(CaptureReplay, CloudFromEncoderFramesFollowsSpec2AndThePose) {
  UnitConfig unit;
  unit.p_m = 0.12;
  unit.theta_rad = 0.3;
  unit.pose = makePose(Vec3(1, 2, 3), 0, 0, M_PI / 2);
  const ReplayCloud c = replayToCloud(encoderFrames(), unit);
  EXPECT_EQ(c.scans_used, 2u);
  EXPECT_EQ(c.beams, 62u);
  ASSERT_EQ(c.cloud.size(), 4u);  // two echoes per frame
  EXPECT_TRUE(c.warnings.empty());
  const double deg = kRadPerDeg;
  // Expected by SPEC §2 written out: β moves 2° per turn, so the beam at α = 180° fires at β0 + 1°.
  auto expected = [&](double r, double alpha_deg, double beta_deg) {
    const double a = alpha_deg * deg, b = beta_deg * deg;
    const Vec3 u(r * std::cos(a), r * std::sin(a) * std::cos(b) + 0.12 * std::cos(b + 0.3),
                 r * std::sin(a) * std::sin(b) + 0.12 * std::sin(b + 0.3));
    return Vec3(1 - u.y(), 2 + u.x(), 3 + u.z());  // yaw 90°: x -> y, y -> -x
  };
  const double tick = 360.0 / kTurntableCountsPerRev;  // encoder rounding
  const std::vector<Vec3> want = {expected(2.0, 0, 10), expected(3.0, 180, 11), expected(2.0, 0, 12),
                                  expected(3.0, 180, 13)};
  for (size_t i = 0; i < 4; ++i)
    EXPECT_LT((c.cloud.points[i] - want[i]).norm(), (3.0 + 0.12) * tick * deg) << i;  // (r + p) × one tick
  EXPECT_NEAR(c.cloud.beta_rad[1], 11 * deg, tick * deg);
  EXPECT_NEAR(c.cloud.alpha_rad[1], M_PI, 1e-12);
  EXPECT_EQ(c.cloud.intensity[1], 100.0f);
  EXPECT_EQ(*c.cloud.viewpoint, Vec3(1, 2, 3));

  ReplayResult no_encoder = encoderFrames();
  for (auto& f : no_encoder.frames) f.scan.encoders.clear();
  EXPECT_THROW(replayToCloud(no_encoder, unit), InvalidInput);
  ReplayResult mixed = encoderFrames();
  mixed.frames[1].scan.encoders.clear();
  const ReplayCloud half = replayToCloud(mixed, unit);
  EXPECT_EQ(half.scans_used, 1u);
  ASSERT_EQ(half.warnings.size(), 1u);
  UnitConfig bad = unit;
  bad.speed_deg_s = 0;
  EXPECT_THROW(replayToCloud(encoderFrames(), bad), InvalidInput);
}

}  // namespace
}  // namespace sailshape
