#pragma once
// An emulated SICK LMS111/LMS511 on a TCP port: answers the start-up sequence
// SICK's driver sends (replies of the types and layouts the recorded devices
// gave, ../shared/sick-recordings) in CoLa B or CoLa A (detected per
// connection), and streams LMDscandata at the configured frequency and
// resolution with ranges ray-cast from the unit's pose at the turntable's
// current β through the sensor model. Serves one connection at a time on a
// background thread until destroyed.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sensor_model.hpp"

namespace sailshape {

struct ScannerEmulatorParams {
  std::string bind_address = "127.0.0.1";  // another address only when asked for explicitly
  uint16_t port = 2112;                    // 0: any free port (see ScannerEmulator::port())
  SensorModelParams sensor;                // model, noise, ...
  uint64_t seed = 1;                       // scan k uses seed + k: repeatable
  // Unit geometry (SPEC §2): the emulated hardware's true p and θ and its pose in the scene.
  double p_m = 0.0;
  double theta_rad = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  uint32_t serial_number = 0;              // 0: the recorded unit's (LMS111 18090362, LMS511 18110550)
  // Seconds after power-on (the emulator's construction) during which the device is still starting: it
  // answers SCdevicestate 0 (busy), as the recorded units did, and streams no scan before then.
  double spin_up_s = 0.0;
  // A device measures in real time and never falls behind. An emulator whose host cannot ray-cast its
  // scans at the configured rate (a slow or sanitised build) would: it drops the scans it is more than
  // this late for, as a device drops what its output cannot send, and its scan counter still counts them.
  double max_lag_s = 0.25;
  // Faults, for the client's tests.
  bool refuse_login = false;               // SetAccessMode answers 0
  bool mute = false;                       // accepts and reads, never answers
  int drop_after_scans = -1;               // closes the connection after this many streamed scans (≥ 0)
  double slow_host_s = 0.0;                // each streamed scan takes at least this long to compute (a slow host)
};

class ScannerEmulator {
 public:
  // `turntable` (may be null: β = 0) must outlive the emulator. Throws std::runtime_error naming the address
  // when the port cannot be bound.
  ScannerEmulator(const Scene& scene, const ScannerEmulatorParams& params, TurntableMotion* turntable = nullptr);
  ~ScannerEmulator();
  ScannerEmulator(const ScannerEmulator&) = delete;
  ScannerEmulator& operator=(const ScannerEmulator&) = delete;

  uint16_t port() const { return port_; }
  uint64_t scansSent() const { return scans_sent_; }
  // Scans dropped because the host could not compute them in time (see ScannerEmulatorParams::max_lag_s).
  uint64_t scansDropped() const { return scans_dropped_; }
  uint64_t connections() const { return connections_; }

  // The reply payloads (unframed) to one request payload in `binary` or ASCII; what a connection gets.
  // Public so tests can check replies telegram by telegram. An unknown request, one that needs a login
  // first or one with bad arguments gets an sFA error reply (codes as SICK's driver reads them, README).
  std::string reply(const std::string& request_payload, bool binary);

 private:
  struct Session;
  struct Request;  // one request being answered: its telegram, argument reader and reply writer
  std::string replyMethod(Request& r);  // sMN
  std::string replyRead(Request& r);    // sRN
  std::string replyWrite(Request& r);   // sWN
  std::string replyEvent(Request& r);   // sEN
  void serve();
  void runSession(int fd);
  // One LMDscandata payload for the scan that began at scan_start (β per beam from the turntable).
  std::string scanPayload(bool binary, bool polled, std::chrono::steady_clock::time_point scan_start);

  ScannerEmulatorParams params_;
  EmulatedSensor sensor_;
  TurntableMotion* turntable_;
  std::chrono::steady_clock::time_point epoch_;
  std::chrono::steady_clock::time_point ready_at_;  // power-on + spin_up_s
  int listen_fd_ = -1;
  uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> scans_sent_{0}, scans_dropped_{0}, connections_{0};
  std::thread thread_;
  std::unique_ptr<Session> session_;  // state of the current connection (serve thread only)
};

}  // namespace sailshape
