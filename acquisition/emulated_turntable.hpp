#pragma once
// The emulated turntable drive: trapezoidal motion (velocity and acceleration
// limits, over real time), a proximity sensor for homing at an angle the client
// does not know, an encoder, and the line protocol served on a pseudo-terminal
// (openpty) so the client's termios code runs unchanged.
#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include "acquisition/turntable_protocol.hpp"

namespace sailshape {

struct EmulatedTurntableParams {
  double home_sensor_deg = 37.0;       // sensor position from the power-on angle (mechanical)
  bool home_sensor_works = true;       // false: homing searches home_search_deg and fails
  double home_search_deg = 400.0;      // travel before HOME gives up
  double home_speed_deg_s = 90.0;
  double velocity_deg_s = 20.0;        // initial settings
  double acceleration_deg_s2 = 90.0;
  double max_velocity_deg_s = 360.0;
  double max_acceleration_deg_s2 = 3600.0;
  bool silent = false;                 // fault injection: reads requests, never answers
};

// Motion state; every member is thread-safe (the scanner emulator reads β while the pty thread commands).
class TurntableMotion {
 public:
  using Clock = std::chrono::steady_clock;
  explicit TurntableMotion(const EmulatedTurntableParams& params);

  TurntableErrorCode home();
  TurntableErrorCode setVelocity(double deg_s);
  TurntableErrorCode setAcceleration(double deg_s2);
  TurntableErrorCode moveTo(double deg);  // encoder frame (0 = home)
  TurntableErrorCode moveBy(double deg);
  void stop();                            // decelerates at the set acceleration

  TurntableStatus status();
  TurntablePosition position();
  // Encoder-frame angle (degrees) at time t (not after now); what β the scanner sees.
  double angleDegAt(Clock::time_point t);
  Clock::time_point epoch() const { return epoch_; }

 private:
  struct Profile {
    Clock::time_point t0;
    double p0 = 0, dir = 1, v0 = 0, vp = 0, a = 1;  // mechanical degrees, speeds ≥ 0
    double t1 = 0, t2 = 0, t3 = 0, d1 = 0, d2 = 0, d3 = 0;
    double end() const { return p0 + dir * (d1 + d2 + d3); }
    double duration() const { return t1 + t2 + t3; }
  };
  Profile profileTo(Clock::time_point t0, double from, double to, double speed) const;
  double mechAt(const Profile& p, Clock::time_point t, double* velocity = nullptr) const;
  void update(Clock::time_point now);  // finishes a profile whose time is up; caller holds mutex_

  const EmulatedTurntableParams params_;
  const Clock::time_point epoch_;
  std::mutex mutex_;
  TurntableState state_ = TurntableState::Idle;
  TurntableErrorCode error_ = TurntableErrorCode::None;
  bool homed_ = false, homing_ = false;
  double zero_mech_ = 0;  // mechanical angle of encoder zero
  double rest_mech_ = 0;  // position while idle
  double velocity_, acceleration_;
  Profile profile_;
};

// Serves the protocol on a pty until destroyed.
class EmulatedTurntable {
 public:
  // Throws std::runtime_error naming the failing call when no pty can be opened.
  explicit EmulatedTurntable(const EmulatedTurntableParams& params = {});
  ~EmulatedTurntable();
  EmulatedTurntable(const EmulatedTurntable&) = delete;
  EmulatedTurntable& operator=(const EmulatedTurntable&) = delete;

  const std::string& devicePath() const { return device_; }  // the pty's slave, e.g. /dev/pts/7
  TurntableMotion& motion() { return motion_; }
  // The reply to one request line (without its "\n"); what the pty thread sends.
  std::string handle(const std::string& line);

 private:
  void serve();

  EmulatedTurntableParams params_;
  TurntableMotion motion_;
  int master_ = -1, slave_ = -1;
  std::string device_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace sailshape
