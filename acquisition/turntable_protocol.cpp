#include "acquisition/turntable_protocol.hpp"

#include <cstdio>
#include <sstream>

namespace sailshape {

std::string turntableErrorWord(TurntableErrorCode code) {
  switch (code) {
    case TurntableErrorCode::None: return "NONE";
    case TurntableErrorCode::UnknownCommand: return "UNKNOWN_COMMAND";
    case TurntableErrorCode::BadArgument: return "BAD_ARGUMENT";
    case TurntableErrorCode::NotHomed: return "NOT_HOMED";
    case TurntableErrorCode::HomeNotFound: return "HOME_NOT_FOUND";
    case TurntableErrorCode::OutOfRange: return "OUT_OF_RANGE";
    case TurntableErrorCode::Busy: return "BUSY";
  }
  return "UNKNOWN";
}

std::string turntableStateWord(TurntableState state) {
  switch (state) {
    case TurntableState::Idle: return "IDLE";
    case TurntableState::Homing: return "HOMING";
    case TurntableState::Moving: return "MOVING";
    case TurntableState::Error: return "ERROR";
  }
  return "ERROR";
}

std::string formatOk() { return "OK"; }

std::string formatError(TurntableErrorCode code, const std::string& detail) {
  return "ERR " + std::to_string(static_cast<int>(code)) + " " + turntableErrorWord(code) +
         (detail.empty() ? "" : " " + detail);
}

std::string formatStatus(const TurntableStatus& s) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "STAT %s %d %lld %.4f %d", turntableStateWord(s.state).c_str(), s.homed ? 1 : 0,
                static_cast<long long>(s.counts), s.velocity_deg_s, static_cast<int>(s.error));
  return buf;
}

std::string formatPosition(const TurntablePosition& p) {
  return "POS " + std::to_string(p.counts) + " " + std::to_string(p.device_time_us);
}

std::optional<TurntableStatus> parseStatus(const std::string& line) {
  std::istringstream in(line);
  std::string tag, state;
  int homed = 0, error = 0;
  long long counts = 0;
  double vel = 0;
  if (!(in >> tag >> state >> homed >> counts >> vel >> error) || tag != "STAT") return std::nullopt;
  TurntableStatus s;
  if (state == "IDLE") s.state = TurntableState::Idle;
  else if (state == "HOMING") s.state = TurntableState::Homing;
  else if (state == "MOVING") s.state = TurntableState::Moving;
  else if (state == "ERROR") s.state = TurntableState::Error;
  else return std::nullopt;
  if (error < 0 || error > 6 || (homed != 0 && homed != 1)) return std::nullopt;
  s.homed = homed == 1;
  s.counts = counts;
  s.velocity_deg_s = vel;
  s.error = static_cast<TurntableErrorCode>(error);
  return s;
}

std::optional<TurntablePosition> parsePosition(const std::string& line) {
  std::istringstream in(line);
  std::string tag;
  long long counts = 0;
  unsigned long long t = 0;
  if (!(in >> tag >> counts >> t) || tag != "POS") return std::nullopt;
  return TurntablePosition{counts, t};
}

std::optional<std::pair<TurntableErrorCode, std::string>> parseError(const std::string& line) {
  std::istringstream in(line);
  std::string tag;
  int code = 0;
  if (!(in >> tag >> code) || tag != "ERR" || code < 1 || code > 6) return std::nullopt;
  std::string rest;
  std::getline(in, rest);
  if (!rest.empty() && rest[0] == ' ') rest.erase(0, 1);
  return std::make_pair(static_cast<TurntableErrorCode>(code), rest);
}

}  // namespace sailshape
