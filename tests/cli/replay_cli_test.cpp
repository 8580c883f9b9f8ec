// Runs `sailshape replay` as a user would, on SICK's recordings and on captures of ours.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string>

#include "acquisition/capture.hpp"
#include "acquisition/scan_data.hpp"
#include "acquisition/turntable_protocol.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/units.hpp"
#include "analysis/io/cloud_io.hpp"
#include "tests/cli/run_sailshape.hpp"

namespace {

namespace fs = std::filesystem;
using sailshape::testing::Outcome;
using sailshape::testing::readText;

class ReplayCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sailshape-replaycli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  Outcome run(const std::string& args) { return sailshape::testing::runSailshape(dir_, args); }
  fs::path dir_;
};

const std::string kRecordings = std::string(SAILSHAPE_SHARED) + "/sick-recordings/";

TEST_F(ReplayCli, RecordingToJsonKeepsTheRawValues) {
  const fs::path out = dir_ / "frames.json";
  const Outcome r = run("replay " + kRecordings + "20210302_lms511.pcapng.json --quiet --json " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("pcapng-json capture, CoLa binary"), std::string::npos) << r.out;
  const nlohmann::json doc = nlohmann::json::parse(readText(out));
  ASSERT_GE(doc["frames"].size(), 100u);
  EXPECT_EQ(doc["from_device"]["bad_checksum"], 0);
  // README facts for the first frame.
  const nlohmann::json& f = doc["frames"][0];
  EXPECT_EQ(f["command_type"], "sSN");
  EXPECT_EQ(f["telegram_counter"], 54098);
  EXPECT_EQ(f["scan_counter"], 54484);
  EXPECT_EQ(f["scan_frequency"], 2500);
  EXPECT_DOUBLE_EQ(f["scan_frequency_hz"].get<double>(), 25.0);
  ASSERT_EQ(f["channels16"].size(), 1u);
  ASSERT_EQ(f["channels8"].size(), 1u);
  const nlohmann::json& dist = f["channels16"][0];
  EXPECT_EQ(dist["name"], "DIST1");
  EXPECT_EQ(dist["scale_factor"], 1.0);
  EXPECT_EQ(dist["scale_offset"], 0.0);
  EXPECT_EQ(dist["start_angle"], -50000);
  EXPECT_EQ(dist["angular_step"], 1667);
  const auto values = dist["values"].get<std::vector<uint64_t>>();
  ASSERT_EQ(values.size(), 1141u);
  EXPECT_EQ(std::vector<uint64_t>(values.begin(), values.begin() + 5), (std::vector<uint64_t>{1305, 1299, 1307, 1299, 1307}));
  EXPECT_EQ(std::accumulate(values.begin(), values.end(), uint64_t{0}), 1480058u);
  const auto rssi = f["channels8"][0]["values"].get<std::vector<uint64_t>>();
  EXPECT_EQ(f["channels8"][0]["name"], "RSSI1");
  EXPECT_EQ(std::accumulate(rssi.begin(), rssi.end(), uint64_t{0}), 266142u);
  EXPECT_EQ(doc["other_telegrams"]["sMN SetAccessMode"], 1);
}

// SICK's LMS511 recording with the length field of one LMDscandata frame damaged so that it announces more
// than is left of the capture: that frame is skipped, the decoder resumes at the next frame start, every
// other frame is replayed, and one warning line gives the count.
TEST_F(ReplayCli, DamagedLengthFieldLosesOnlyItsFrame) {
  nlohmann::json doc = nlohmann::json::parse(readText(kRecordings + "20210302_lms511.pcapng.json"));
  std::vector<size_t> scan_segments;  // elements whose TCP segment is one sSN LMDscandata frame
  const std::string scan_head = "73:53:4e:20:4c:4d:44";  // "sSN LMD" after the 8-byte header
  for (size_t i = 0; i < doc.size(); ++i) {
    const auto& tcp = doc[i]["_source"]["layers"]["tcp"];
    if (tcp.contains("tcp.payload") && tcp["tcp.payload"].get<std::string>().compare(24, scan_head.size(), scan_head) == 0)
      scan_segments.push_back(i);
  }
  ASSERT_EQ(scan_segments.size(), 174u);
  // The tenth frame from the end: its length field (bytes 4..7, "02:02:02:02:LL:LL:LL:LL:") says 60000,
  // more than the nine frames after it hold.
  std::string& payload = doc[scan_segments[174 - 10]]["_source"]["layers"]["tcp"]["tcp.payload"].get_ref<std::string&>();
  ASSERT_EQ(payload.substr(12, 11), "00:00:0d:d8");  // 3544 payload bytes, as every frame in the file
  payload.replace(12, 11, "00:00:ea:60");
  const fs::path garbled = dir_ / "garbled.pcapng.json";
  std::ofstream(garbled) << doc.dump();

  const fs::path out = dir_ / "frames.json";
  const Outcome r = run("replay " + garbled.string() + " --quiet --json " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("173 LMDscandata frames (scan counter 54484..54657"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 bad length, 3553 garbage bytes"), std::string::npos) << r.out;
  const std::string warning =
      "warning: skipped 1 damaged frame (1 with a bad length field) and 3553 bytes in all, resuming at the next "
      "frame start each time\n";
  EXPECT_NE(r.err.find(warning), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;  // the warning and "wrote ..."
  const nlohmann::json frames = nlohmann::json::parse(readText(out))["frames"];
  ASSERT_EQ(frames.size(), 173u);
  // Counters run 54484..54657 without the damaged frame's 54648.
  for (size_t k = 0; k < frames.size(); ++k)
    EXPECT_EQ(frames[k]["scan_counter"], 54484 + k + (k >= 164 ? 1 : 0)) << k;
  // The frame after it is whole: DIST1 with its 1141 values.
  EXPECT_EQ(frames[164]["channels16"][0]["values"].size(), 1141u);
}

// CoLa A has no length field: a frame whose ETX was lost ends at the next STX; it is dropped, counted, and
// the frames around it are kept.
TEST_F(ReplayCli, AsciiFrameWithoutItsEndIsSkippedToTheNextStart) {
  const fs::path cap = dir_ / "session.sscap";
  size_t damaged_size = 0;
  {
    sailshape::CaptureWriter w(cap.string(), sailshape::ColaDialect::kAscii);
    for (uint16_t i = 1; i <= 5; ++i) {
      sailshape::ScanData s;
      s.scan_counter = i;
      s.channels16 = {{"DIST1", 1.0f, 0.0f, -450000, 5000, {1000, 1001, 1002}}};
      std::string frame = sailshape::frameCola(sailshape::ColaDialect::kAscii,
                                               sailshape::encodeScanData(s, sailshape::ColaDialect::kAscii));
      if (i == 3) {
        frame.back() = ' ';  // the ETX lost
        damaged_size = frame.size();
      }
      w.append({sailshape::CaptureDirection::kFromDevice, 100.0 + i, frame});
    }
  }
  const fs::path out = dir_ / "frames.json";
  const Outcome r = run("replay " + cap.string() + " --quiet --json " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: skipped 1 damaged frame (1 cut short) and " + std::to_string(damaged_size) +
                       " bytes in all, resuming at the next frame start each time\n"),
            std::string::npos)
      << r.err;
  const nlohmann::json frames = nlohmann::json::parse(readText(out))["frames"];
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[1]["scan_counter"], 2);
  EXPECT_EQ(frames[2]["scan_counter"], 4);
  EXPECT_EQ(frames[3]["channels16"][0]["values"], nlohmann::json({1000, 1001, 1002}));
}

TEST_F(ReplayCli, OurCaptureCutShortIsReplayedUpToTheCut) {
  const fs::path cap = dir_ / "session.sscap";
  {
    sailshape::CaptureWriter w(cap.string(), sailshape::ColaDialect::kAscii);
    for (uint16_t i = 1; i <= 3; ++i) {
      sailshape::ScanData s;
      s.scan_counter = i;
      s.scan_frequency = 5000;
      s.channels16 = {{"DIST1", 1.0f, 0.0f, -450000, 5000, {1000, 1001, 1002}}};
      const std::string frame = sailshape::frameCola(sailshape::ColaDialect::kAscii,
                                                     sailshape::encodeScanData(s, sailshape::ColaDialect::kAscii));
      // Split across two records as a socket may deliver it.
      w.append({sailshape::CaptureDirection::kFromDevice, 100.0 + i, frame.substr(0, 10)});
      w.append({sailshape::CaptureDirection::kFromDevice, 100.0 + i, frame.substr(10)});
    }
  }
  fs::resize_file(cap, fs::file_size(cap) - 5);  // a crash mid-record
  const fs::path out = dir_ / "frames.json";
  const Outcome r = run("replay " + cap.string() + " --quiet --json " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: truncated record"), std::string::npos) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(readText(out));
  EXPECT_EQ(doc["dialect"], "ascii");
  ASSERT_EQ(doc["frames"].size(), 2u);  // the third frame's second half was cut
  EXPECT_EQ(doc["frames"][1]["scan_counter"], 2);
  EXPECT_DOUBLE_EQ(doc["frames"][1]["time_s"].get<double>(), 102.0);
  EXPECT_EQ(doc["frames"][0]["channels16"][0]["values"], nlohmann::json({1000, 1001, 1002}));
}

TEST_F(ReplayCli, UnitFileTurnsEncoderFramesIntoACloud) {
  const fs::path cap = dir_ / "sweep.sscap";
  {
    sailshape::CaptureWriter w(cap.string(), sailshape::ColaDialect::kBinary);
    for (int k = 0; k < 3; ++k) {
      sailshape::ScanData s;
      s.scan_counter = static_cast<uint16_t>(k + 1);
      s.encoders = {{static_cast<uint32_t>(30 * k * sailshape::kTurntableCountsPerRev / 360), 0}};  // β = 0, 30, 60°
      s.channels16 = {{"DIST1", 1.0f, 0.0f, 900000, 10000, {2500}}};  // one beam at α = 90°, 2.5 m
      w.append({sailshape::CaptureDirection::kFromDevice, 1.0 + k,
                sailshape::frameCola(sailshape::ColaDialect::kBinary,
                                     sailshape::encodeScanData(s, sailshape::ColaDialect::kBinary))});
    }
  }
  sailshape::UnitConfig unit;
  unit.name = "jib";
  std::ofstream(dir_ / "unit.json") << sailshape::unitToJson(unit);
  const fs::path out = dir_ / "cloud.xyz";
  const Outcome r = run("replay " + cap.string() + " --quiet --unit " + (dir_ / "unit.json").string() + " --cloud " +
                        out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const sailshape::Cloud cloud = sailshape::readCloud(out.string()).cloud;
  ASSERT_EQ(cloud.size(), 3u);
  // p = 0, identity pose: α = 90° puts the point at r (0, cos β, sin β) (SPEC §2).
  for (int k = 0; k < 3; ++k) {
    const double b = 30.0 * k * sailshape::kRadPerDeg;
    EXPECT_LT((cloud.points[k] - sailshape::Vec3(0, 2.5 * std::cos(b), 2.5 * std::sin(b))).norm(), 1e-4) << k;
  }
  const Outcome alone = run("replay " + cap.string() + " --quiet --cloud " + out.string());
  EXPECT_NE(alone.exit_code, 0);  // --cloud needs --unit
}

TEST_F(ReplayCli, BadInputIsOneLineError) {
  const fs::path junk = dir_ / "junk.bin";
  std::ofstream(junk) << "this is not a capture";
  const Outcome r = run("replay " + junk.string() + " --quiet");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("neither a sailshape capture"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const Outcome missing = run("replay " + (dir_ / "none.sscap").string());
  EXPECT_NE(missing.exit_code, 0);
  const Outcome help = run("replay --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--json"), std::string::npos);
}

}  // namespace
