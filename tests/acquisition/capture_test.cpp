// Capture archives: our format written and read back (also cut short), pcapng-JSON recordings, bad files,
// and replayCapture's frames and JSON.
#include "acquisition/capture.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "acquisition/capture_replay.hpp"
#include "analysis/errors.hpp"

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

}  // namespace
}  // namespace sailshape
