#pragma once
// Client for the turntable drive over a serial line (termios, 8N1, raw), speaking
// the protocol of acquisition/README.md. Works the same on a USB-serial adapter
// and on the emulator's pseudo-terminal.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "acquisition/turntable_protocol.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

// The drive answered with an error, did not answer, or the line failed.
struct TurntableError : std::runtime_error {
  TurntableError(const std::string& what, TurntableErrorCode code = TurntableErrorCode::None)
      : std::runtime_error(what), code(code) {}
  TurntableErrorCode code;
};

struct TurntableLinkParams {
  std::string device = "/dev/ttyUSB0";
  int baud = 115200;            // 9600 … 921600 (standard rates only)
  int reply_timeout_ms = 1000;  // per request line
};

// One encoder reading with the host time it was taken at (middle of the round trip).
struct TurntableSample {
  double host_time_s = 0;  // steady clock, seconds
  int64_t counts = 0;
  uint64_t device_time_us = 0;
  double deg() const { return countsToDeg(counts); }
};

double hostTimeSeconds();  // steady clock in seconds: the time base of samples and sweeps

class TurntableClient {
 public:
  // Opens and configures the device; throws TurntableError naming the device and
  // the failing call, InvalidInput for an unsupported baud rate.
  explicit TurntableClient(const TurntableLinkParams& params);
  ~TurntableClient();
  TurntableClient(const TurntableClient&) = delete;
  TurntableClient& operator=(const TurntableClient&) = delete;

  std::string identify();
  // Seeks the proximity sensor and waits; throws TurntableError (HomeNotFound) when the
  // drive reports it never found the sensor, or a timeout error after timeout_s.
  void home(double timeout_s = 30.0, const Progress& progress = {});
  void setVelocity(double deg_s);
  void setAcceleration(double deg_s2);
  void moveAbsolute(double deg);
  void moveRelative(double deg);
  void stop();
  // Polls until the drive is idle; false on timeout. Throws if the drive faults.
  bool waitIdle(double timeout_s);
  TurntableStatus status();
  TurntableSample sample();

  // One request line → its reply line; an "ERR" reply throws TurntableError with its code.
  std::string request(const std::string& line);

 private:
  std::string readLine();
  TurntableLinkParams params_;
  int fd_ = -1;
  std::string buffer_;
};

}  // namespace sailshape
