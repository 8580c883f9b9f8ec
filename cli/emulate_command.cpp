// `sailshape emulate`: an emulated scanner unit (SICK LMS111/LMS511 on TCP, turntable on a pty) ray-casting
// into a scene, for running `sailshape scan` and the client without hardware.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "cli/commands.hpp"

namespace sailshape::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop = true; }

struct EmulateOptions {
  std::string model = "lms511";
  std::string scene;
  int port = 2112;
  std::string bind = "127.0.0.1";
  std::string serial_link;
  std::string unit;
  uint64_t seed = 1;
  double noise_scale = 1.0;
  double home_sensor_deg = 37.0;
  double duration_s = 0;
  double spin_up_s = 0;
};

// The symlink to the pty, removed again on exit; an existing file that is not our kind of link is refused.
class SerialLink {
 public:
  SerialLink(const std::string& link, const std::string& target) : link_(link) {
    if (link_.empty()) return;
    namespace fs = std::filesystem;
    const fs::path p(link_);
    if (fs::is_symlink(p)) {
      const std::string old = fs::read_symlink(p).string();
      if (old.rfind("/dev/pts/", 0) != 0)
        throw InvalidInput("[emulate] --serial-link " + link_ + " is a link to " + old + ", not to a pty; not replaced");
      fs::remove(p);
    } else if (fs::exists(p)) {
      throw InvalidInput("[emulate] --serial-link " + link_ + " exists and is not a link; not replaced");
    }
    fs::create_symlink(target, p);
  }
  ~SerialLink() {
    if (!link_.empty()) {
      std::error_code ec;
      std::filesystem::remove(link_, ec);
    }
  }

 private:
  std::string link_;
};

void run(const EmulateOptions& o) {
  if (o.port < 0 || o.port > 65535) throw InvalidInput("[emulate] --port must be 0..65535 (got " + std::to_string(o.port) + ")");
  const Scene scene = o.scene.empty() ? builtInTunnelScene() : readSceneFile(o.scene);
  ScannerEmulatorParams sp;
  sp.bind_address = o.bind;
  sp.port = static_cast<uint16_t>(o.port);
  sp.sensor.model = parseScannerModel(o.model);
  sp.sensor.noise_scale = o.noise_scale;
  sp.seed = o.seed;
  sp.spin_up_s = o.spin_up_s;
  if (!o.unit.empty()) {
    const UnitConfig u = readUnitFile(o.unit);
    sp.p_m = u.p_m;
    sp.theta_rad = u.theta_rad;
    sp.pose = u.pose;
  } else {
    // Without a unit file: leeward of the built-in tunnel model's sails, as assets/unit-tunnel-leeward.json.
    sp.p_m = 0.105;
    sp.theta_rad = 12.0 * kRadPerDeg;
    sp.pose = makePose(Vec3(0.2, 4.0, 1.3), 0, 0, M_PI);
  }
  EmulatedTurntableParams tp;
  tp.home_sensor_deg = o.home_sensor_deg;
  EmulatedTurntable table(tp);
  ScannerEmulator scanner(scene, sp, &table.motion());
  SerialLink link(o.serial_link, table.devicePath());
  std::printf("emulated %s on %s:%u, turntable on %s%s%s; scene '%s' (%zu triangles). Ctrl-C stops.\n",
              scannerModelName(sp.sensor.model).c_str(), o.bind.c_str(), scanner.port(), table.devicePath().c_str(),
              o.serial_link.empty() ? "" : " (link ", o.serial_link.empty() ? "" : (o.serial_link + ")").c_str(),
              scene.name.c_str(), scene.triangleCount());
  std::fflush(stdout);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop) {
    if (o.duration_s > 0 && std::chrono::steady_clock::now() - start > std::chrono::duration<double>(o.duration_s)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::printf("stopped after %llu scans over %llu connections\n", static_cast<unsigned long long>(scanner.scansSent()),
              static_cast<unsigned long long>(scanner.connections()));
}

}  // namespace

void addEmulateCommand(CLI::App& app) {
  auto o = std::make_shared<EmulateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "emulate",
      "Run an emulated scanner unit: SICK LMS111/LMS511 on TCP, its turntable on a pty\n\n"
      "Run an emulated scanner unit: a SICK LMS111/LMS511 speaking CoLa A/B on TCP (answering the start-up sequence "
      "as the recorded devices do and streaming LMDscandata) and its turntable on a pseudo-terminal, with ranges "
      "ray-cast into a scene through the sensor model of SPEC §3. Runs until Ctrl-C.");
  cmd->add_option("--model", o->model, "Scanner model: lms511 (0.7-80 m, 190°) or lms111 (0.5-20 m, 270°)")
      ->check(CLI::IsMember({"lms511", "lms111"}))
      ->capture_default_str();
  cmd->add_option("--scene", o->scene,
                  "SCENE.json (format in acquisition/README.md); default: the built-in wind tunnel with a yacht "
                  "model, its mainsail and an A2 gennaker")
      ->check(CLI::ExistingFile);
  cmd->add_option("--port", o->port, "TCP port of the scanner (0: any free port, printed)")->capture_default_str();
  cmd->add_option("--bind", o->bind, "Address to listen on; only loopback unless given explicitly")->capture_default_str();
  cmd->add_option("--serial-link", o->serial_link,
                  "Make this path a symbolic link to the turntable's pty (what a unit file's serial_device names); "
                  "removed on exit");
  cmd->add_option("--unit", o->unit,
                  "Unit file giving the emulated unit's true p, θ and pose in the scene (default: leeward of the "
                  "built-in tunnel model, p 0.105 m, θ 12°)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", o->seed, "Noise seed (scan k uses seed + k)")->capture_default_str();
  cmd->add_option("--noise-scale", o->noise_scale, "Multiplies every material's range noise (0: noise-free)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--home-sensor-deg", o->home_sensor_deg,
                  "Where the turntable's proximity sensor sits from its power-on angle, degrees")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Stop after this many seconds (0: run until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--spin-up", o->spin_up_s,
                  "Seconds after start during which the scanner is still starting, as a unit just powered on: it "
                  "answers device state 0 (busy) and streams no scan")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace sailshape::cli
