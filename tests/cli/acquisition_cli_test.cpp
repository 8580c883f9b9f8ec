// `sailshape emulate`, `scan` and `scanner calibrate` run as a user would: an emulator process serving a
// room, a scan through its TCP port and pty link, a calibration from the stored samples.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "tests/cli/run_sailshape.hpp"

namespace fs = std::filesystem;
using sailshape::testing::readText;
using sailshape::testing::runSailshape;

namespace {

// A test's own directory under the test temp dir. It goes when the test passes and
// stays, with the emulator's and the command's output, when it fails.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(fs::path(::testing::TempDir()) / ("acq_cli_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    if (!::testing::Test::HasFailure()) fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  operator const fs::path&() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// A wall y = 3 and a floor z = -1.5 around the unit (unit frame = scene frame), cloth.
const char* kRoom = R"({"name": "room", "objects": [
  {"type": "quad", "name": "wall", "material": "cloth", "corners": [[-20, 3, -20], [20, 3, -20], [20, 3, 20], [-20, 3, 20]]},
  {"type": "quad", "name": "floor", "material": "cloth", "corners": [[-20, -20, -1.5], [20, -20, -1.5], [20, 20, -1.5], [-20, 20, -1.5]]}]})";

// The emulator as a child process, stopped (by its pid) at the end of the test.
class EmulatorProcess {
 public:
  EmulatorProcess(const fs::path& dir, const std::string& args) : out_(dir / "emulator.txt") {
    pid_ = ::fork();
    if (pid_ == 0) {
      const std::string cmd = std::string("exec '") + SAILSHAPE_BIN + "' emulate " + args + " >'" + out_.string() +
                              "' 2>&1 </dev/null";
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~EmulatorProcess() { stop(SIGTERM); }
  // Ends the emulator with `signal` (SIGKILL: a unit losing power, its TCP connection and pty gone at once).
  void stop(int signal) {
    if (pid_ > 0) {
      ::kill(pid_, signal);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }
  // The port it printed, or 0 after the timeout.
  int port(double timeout_s = 20) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    const std::regex re("127\\.0\\.0\\.1:([0-9]+)");
    while (std::chrono::steady_clock::now() < end) {
      std::smatch m;
      const std::string text = readText(out_);
      if (std::regex_search(text, m, re)) return std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return 0;
  }

 private:
  fs::path out_;
  pid_t pid_ = -1;
};

}  // namespace

TEST(AcquisitionCli, HelpExplainsTheOptions) {
  const ScratchDir d("help");
  auto r = runSailshape(d, "emulate --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--model", "--scene", "--port", "--serial-link", "--unit", "--bind", "--spin-up"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  r = runSailshape(d, "scan --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--unit", "--out", "--trigger", "--home-timeout", "--ready-timeout", "--sync-timeout"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  r = runSailshape(d, "scanner calibrate --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--plane", "--cylinder", "--radius", "--write-unit"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}

TEST(AcquisitionCli, EmulateScanAndCalibrate) {
  const ScratchDir d("e2e");
  writeText(d / "room.json", kRoom);
  writeText(d / "truth.json", R"({"name": "truth", "p_m": 0.105, "theta_deg": 12})");
  EmulatorProcess emu(d, "--model lms511 --port 0 --scene '" + (d / "room.json").string() + "' --unit '" +
                             (d / "truth.json").string() + "' --serial-link '" + (d / "tt").string() +
                             "' --duration 120");
  const int port = emu.port();
  ASSERT_GT(port, 0) << readText(d / "emulator.txt");
  nlohmann::json unit{{"name", "room-unit"}, {"port", port}, {"serial_device", (d / "tt").string()},
                      {"model", "lms511"},   {"p_m", 0.08},  {"theta_deg", 0},
                      {"frequency_hz", 25},  {"resolution_deg", 0.1667},
                      {"start_angle_deg", -160}, {"sweep_angle_deg", 230}, {"speed_deg_s", 90},
                      {"acceleration_deg_s2", 900}};
  writeText(d / "unit.json", unit.dump());
  auto r = runSailshape(d, "scan --quiet --unit '" + (d / "unit.json").string() + "' --out '" + (d / "out").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"room-unit.ply", "room-unit.samples.csv", "room-unit.sscap", "scan.json"})
    EXPECT_TRUE(fs::exists(d / "out" / f)) << f;
  const auto doc = nlohmann::json::parse(readText(d / "out" / "scan.json"));
  EXPECT_FALSE(doc["units"][0]["partial"].get<bool>());
  EXPECT_GT(doc["units"][0]["points"].get<int>(), 20000);

  // A second scan into the same directory is refused, and the stored scan stays as it was.
  const auto size_before = fs::file_size(d / "out" / "room-unit.samples.csv");
  r = runSailshape(d, "scan --quiet --unit '" + (d / "unit.json").string() + "' --out '" + (d / "out").string() + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("exists already"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(fs::file_size(d / "out" / "room-unit.samples.csv"), size_before);

  // Calibrate from the wall and the floor, cropped under the starting guess (the unit file's p, θ).
  const std::string samples = (d / "out" / "room-unit.samples.csv").string();
  r = runSailshape(d, "scanner calibrate --unit '" + (d / "unit.json").string() + "' --plane '" + samples +
                          "@-20,20,2.8,3.2,-1.2,20' --plane '" + samples + "@-20,20,-20,2.7,-1.7,-1.3' --json '" +
                          (d / "cal.json").string() + "' --write-unit '" + (d / "calibrated.json").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto cal = nlohmann::json::parse(readText(d / "cal.json"));
  EXPECT_NEAR(cal["p_m"].get<double>(), 0.105, 0.002);
  // This fast, sparse sweep (90 °/s, 3.6° of β between scans) checks the command's plumbing; θ to 0.1° needs
  // the slower, denser sweep of tests/acquisition/calibration_test.cpp.
  EXPECT_NEAR(cal["theta_deg"].get<double>(), 12.0, 0.5);
  const auto written = nlohmann::json::parse(readText(d / "calibrated.json"));
  EXPECT_NEAR(written["p_m"].get<double>(), cal["p_m"].get<double>(), 1e-9);
  EXPECT_EQ(written["port"].get<int>(), port);
}

TEST(AcquisitionCli, AScannerStillSpinningUpPastTheReadyTimeoutIsOneErrorAndNoScanIsWritten) {
  const ScratchDir d("spinup");
  writeText(d / "room.json", kRoom);
  EmulatorProcess emu(d, "--model lms511 --port 0 --spin-up 60 --scene '" + (d / "room.json").string() +
                             "' --serial-link '" + (d / "tt").string() + "' --duration 60");
  const int port = emu.port();
  ASSERT_GT(port, 0) << readText(d / "emulator.txt");
  nlohmann::json unit{{"name", "room-unit"}, {"port", port}, {"serial_device", (d / "tt").string()},
                      {"model", "lms511"},   {"frequency_hz", 25}, {"resolution_deg", 0.1667},
                      {"start_angle_deg", -20}, {"sweep_angle_deg", 40}, {"speed_deg_s", 90},
                      {"acceleration_deg_s2", 900}};
  writeText(d / "unit.json", unit.dump());
  auto scan = [&](const std::string& out) {
    return "scan --quiet --unit '" + (d / "unit.json").string() + "' --out '" + (d / out).string() + "'";
  };
  auto r = runSailshape(d, scan("out") + " --ready-timeout 1.5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("streamed no scan within 1.5 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("busy"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "out" / "room-unit.ply"));
  // A wait that is no wait is refused before anything is opened.
  r = runSailshape(d, scan("out2") + " --ready-timeout 0");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("ready_timeout_s must be > 0"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(d / "out2")) << "refused before anything is written";
}

TEST(AcquisitionCli, AUnitDroppingMidSweepKeepsWhatItSentAndFailsTheCommand) {
  const ScratchDir d("dropped");
  writeText(d / "room.json", kRoom);
  EmulatorProcess emu(d, "--model lms511 --port 0 --scene '" + (d / "room.json").string() + "' --serial-link '" +
                             (d / "tt").string() + "' --duration 120");
  const int port = emu.port();
  ASSERT_GT(port, 0) << readText(d / "emulator.txt");
  // A slow sweep (200° at 20 °/s: 10 s) so the unit drops while the turntable moves.
  nlohmann::json unit{{"name", "room-unit"}, {"port", port}, {"serial_device", (d / "tt").string()},
                      {"model", "lms511"},   {"frequency_hz", 25}, {"resolution_deg", 0.1667},
                      {"start_angle_deg", -100}, {"sweep_angle_deg", 200}, {"speed_deg_s", 20},
                      {"acceleration_deg_s2", 200}};
  writeText(d / "unit.json", unit.dump());
  sailshape::testing::Outcome r;
  std::thread scan([&] {
    r = runSailshape(d, "scan --quiet --unit '" + (d / "unit.json").string() + "' --out '" + (d / "out").string() + "'");
  });
  // The capture starts when the scanner streams, before the move to the start angle (under 2 s at the
  // positioning speed); 6 s later the turntable is 4-6 s into its 10 s sweep. Then pull the plug.
  const fs::path capture = d / "out" / "room-unit.sscap";
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  auto captured = [&] {
    std::error_code ec;
    const auto size = fs::file_size(capture, ec);
    return ec ? 0 : size;
  };
  while (std::chrono::steady_clock::now() < give_up && captured() == 0)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::seconds(6));
  emu.stop(SIGKILL);
  scan.join();
  EXPECT_NE(r.exit_code, 0) << "a sweep cut short fails the command";
  // One error line; the turntable, gone with the unit, may still turn: one warning says so.
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  EXPECT_NE(r.err.find("sailshape: error: room-unit: partial sweep"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("warning: room-unit: the turntable may still be turning"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("after 0 scans"), std::string::npos) << r.err;
  // What arrived before the drop is written, as the help promises.
  ASSERT_TRUE(fs::exists(d / "out" / "room-unit.ply")) << r.err;
  ASSERT_TRUE(fs::exists(d / "out" / "scan.json"));
  const auto doc = nlohmann::json::parse(readText(d / "out" / "scan.json"));
  EXPECT_TRUE(doc["units"][0]["partial"].get<bool>());
  const int points = doc["units"][0]["points"].get<int>();
  EXPECT_GT(points, 1000) << "the scans received before the drop";
  // The sweep stopped short of its end angle (start -100 + 200).
  EXPECT_LT(doc["units"][0]["beta_end_deg"].get<double>(), 95.0);
  // The cloud file holds exactly the kept points.
  const std::string ply = readText(d / "out" / "room-unit.ply");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ply, m, std::regex("element vertex ([0-9]+)")));
  EXPECT_EQ(std::stoi(m[1]), points);
}

TEST(AcquisitionCli, ErrorsAreOneLine) {
  const ScratchDir d("errors");
  writeText(d / "bad_scene.json", R"({"objects": [{"type": "torus"}]})");
  writeText(d / "bad_unit.json", R"({"speed_deg_s": -1})");
  writeText(d / "bad.csv", "range_m,alpha_rad,beta_rad,rssi,time_s\n1,2\n");
  const std::vector<std::string> cases{
      "emulate --scene '" + (d / "bad_scene.json").string() + "' --port 0 --duration 1",
      "emulate --model lms999",
      "scan --unit '" + (d / "bad_unit.json").string() + "' --out '" + (d / "o").string() + "'",
      "scanner calibrate",
      "scanner calibrate --plane '" + (d / "bad.csv").string() + "'",
      "scanner calibrate --cylinder '" + (d / "bad.csv").string() + "'",
  };
  for (const std::string& c : cases) {
    const auto r = runSailshape(d, c);
    EXPECT_NE(r.exit_code, 0) << c;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c << ": " << r.err;
  }
}
