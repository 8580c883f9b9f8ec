#pragma once
// The turntable's line protocol (acquisition/README.md documents it): ASCII
// lines ending in "\n" both ways, one reply line per request. Shared by the
// termios client and the emulated drive so both read and write the same text.
#include <cstdint>
#include <optional>
#include <string>

namespace sailshape {

enum class TurntableErrorCode : int {
  None = 0,
  UnknownCommand = 1,
  BadArgument = 2,
  NotHomed = 3,
  HomeNotFound = 4,
  OutOfRange = 5,
  Busy = 6,
};
std::string turntableErrorWord(TurntableErrorCode code);  // "UNKNOWN_COMMAND", ...

enum class TurntableState { Idle, Homing, Moving, Error };
std::string turntableStateWord(TurntableState state);  // "IDLE", "HOMING", "MOVING", "ERROR"

constexpr int64_t kTurntableCountsPerRev = 360000;  // encoder: 0.001° per count
constexpr double kTurntableTravelDeg = 720.0;        // cable wrap: |position| ≤ 720° after homing
constexpr size_t kTurntableMaxLine = 80;

struct TurntableStatus {
  TurntableState state = TurntableState::Idle;
  bool homed = false;
  int64_t counts = 0;           // encoder position
  double velocity_deg_s = 0;    // current angular velocity
  TurntableErrorCode error = TurntableErrorCode::None;  // last fault (state Error)
};

struct TurntablePosition {
  int64_t counts = 0;
  uint64_t device_time_us = 0;  // drive clock when the encoder was latched
};

inline double countsToDeg(int64_t counts) { return 360.0 * static_cast<double>(counts) / kTurntableCountsPerRev; }

// Reply lines.
std::string formatOk();
std::string formatError(TurntableErrorCode code, const std::string& detail);
std::string formatStatus(const TurntableStatus& status);
std::string formatPosition(const TurntablePosition& position);

// Parse a reply; nullopt when the line is not of that kind. An "ERR ..." line
// parses into `code` and `detail` through parseError.
std::optional<TurntableStatus> parseStatus(const std::string& line);
std::optional<TurntablePosition> parsePosition(const std::string& line);
std::optional<std::pair<TurntableErrorCode, std::string>> parseError(const std::string& line);

}  // namespace sailshape
