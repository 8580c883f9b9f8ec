#include "acquisition/emulated_turntable.hpp"

#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace sailshape {

namespace {
double seconds(TurntableMotion::Clock::duration d) { return std::chrono::duration<double>(d).count(); }
}  // namespace

TurntableMotion::TurntableMotion(const EmulatedTurntableParams& params)
    : params_(params),
      epoch_(Clock::now()),
      velocity_(params.velocity_deg_s),
      acceleration_(params.acceleration_deg_s2) {
  profile_.t0 = epoch_;
}

TurntableMotion::Profile TurntableMotion::profileTo(Clock::time_point t0, double from, double to,
                                                    double speed) const {
  Profile p;
  p.t0 = t0;
  p.p0 = from;
  p.dir = to >= from ? 1.0 : -1.0;
  p.a = acceleration_;
  const double d = std::abs(to - from);
  // Trapezoid, or triangle when the move is too short to reach `speed`.
  p.vp = std::min(speed, std::sqrt(p.a * d));
  p.t1 = p.vp / p.a;
  p.d1 = 0.5 * p.vp * p.t1;
  p.t3 = p.t1;
  p.d3 = p.d1;
  p.d2 = std::max(0.0, d - p.d1 - p.d3);
  p.t2 = p.vp > 0 ? p.d2 / p.vp : 0;
  return p;
}

double TurntableMotion::mechAt(const Profile& p, Clock::time_point t, double* velocity) const {
  const double tau = std::max(0.0, seconds(t - p.t0));
  double s, v;
  if (tau < p.t1) {
    s = p.v0 * tau + 0.5 * p.a * tau * tau;
    v = p.v0 + p.a * tau;
  } else if (tau < p.t1 + p.t2) {
    s = p.d1 + p.vp * (tau - p.t1);
    v = p.vp;
  } else if (tau < p.duration()) {
    const double u = tau - p.t1 - p.t2;
    s = p.d1 + p.d2 + p.vp * u - 0.5 * p.a * u * u;
    v = p.vp - p.a * u;
  } else {
    s = p.d1 + p.d2 + p.d3;
    v = 0;
  }
  if (velocity) *velocity = p.dir * v;
  return p.p0 + p.dir * s;
}

void TurntableMotion::update(Clock::time_point now) {
  if (state_ != TurntableState::Moving && state_ != TurntableState::Homing) return;
  if (seconds(now - profile_.t0) < profile_.duration()) return;
  rest_mech_ = profile_.end();
  if (homing_) {
    homing_ = false;
    if (params_.home_sensor_works) {
      zero_mech_ = rest_mech_;
      homed_ = true;
      state_ = TurntableState::Idle;
    } else {
      error_ = TurntableErrorCode::HomeNotFound;
      state_ = TurntableState::Error;
    }
    return;
  }
  state_ = TurntableState::Idle;
}

TurntableErrorCode TurntableMotion::home() {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  update(now);
  if (state_ == TurntableState::Moving || state_ == TurntableState::Homing) return TurntableErrorCode::Busy;
  // Seek forward to the next crossing of the sensor (or give up after the search travel).
  double target = rest_mech_ + params_.home_search_deg;
  if (params_.home_sensor_works) {
    double ahead = std::fmod(params_.home_sensor_deg - rest_mech_, 360.0);
    if (ahead <= 0) ahead += 360.0;
    target = rest_mech_ + ahead;
  }
  profile_ = profileTo(now, rest_mech_, target, params_.home_speed_deg_s);
  homing_ = true;
  homed_ = false;
  error_ = TurntableErrorCode::None;
  state_ = TurntableState::Homing;
  return TurntableErrorCode::None;
}

TurntableErrorCode TurntableMotion::setVelocity(double v) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!(v > 0 && v <= params_.max_velocity_deg_s)) return TurntableErrorCode::BadArgument;
  velocity_ = v;
  return TurntableErrorCode::None;
}

TurntableErrorCode TurntableMotion::setAcceleration(double a) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!(a > 0 && a <= params_.max_acceleration_deg_s2)) return TurntableErrorCode::BadArgument;
  acceleration_ = a;
  return TurntableErrorCode::None;
}

TurntableErrorCode TurntableMotion::moveTo(double deg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  update(now);
  if (state_ == TurntableState::Moving || state_ == TurntableState::Homing) return TurntableErrorCode::Busy;
  if (!homed_) return TurntableErrorCode::NotHomed;
  if (!std::isfinite(deg) || std::abs(deg) > kTurntableTravelDeg) return TurntableErrorCode::OutOfRange;
  profile_ = profileTo(now, rest_mech_, zero_mech_ + deg, velocity_);
  state_ = TurntableState::Moving;
  error_ = TurntableErrorCode::None;
  return TurntableErrorCode::None;
}

TurntableErrorCode TurntableMotion::moveBy(double deg) {
  double target;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    update(Clock::now());
    target = rest_mech_ - zero_mech_ + deg;
  }
  return moveTo(target);
}

void TurntableMotion::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  update(now);
  if (state_ != TurntableState::Moving && state_ != TurntableState::Homing) return;
  double v = 0;
  const double p = mechAt(profile_, now, &v);
  // Pure deceleration from the current speed.
  Profile s;
  s.t0 = now;
  s.p0 = p;
  s.dir = v >= 0 ? 1.0 : -1.0;
  s.a = acceleration_;
  s.v0 = s.vp = std::abs(v);
  s.t3 = s.vp / s.a;
  s.d3 = 0.5 * s.vp * s.t3;
  profile_ = s;
  if (homing_) {  // an interrupted search neither homes nor faults
    homing_ = false;
    state_ = TurntableState::Moving;
  }
}

TurntableStatus TurntableMotion::status() {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  update(now);
  TurntableStatus s;
  s.state = state_;
  s.homed = homed_;
  s.error = error_;
  double v = 0;
  const double mech =
      (state_ == TurntableState::Moving || state_ == TurntableState::Homing) ? mechAt(profile_, now, &v) : rest_mech_;
  s.counts = std::llround((mech - zero_mech_) / 360.0 * kTurntableCountsPerRev);
  s.velocity_deg_s = v;
  return s;
}

TurntablePosition TurntableMotion::position() {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  update(now);
  const double mech =
      (state_ == TurntableState::Moving || state_ == TurntableState::Homing) ? mechAt(profile_, now) : rest_mech_;
  return {std::llround((mech - zero_mech_) / 360.0 * kTurntableCountsPerRev),
          static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(now - epoch_).count())};
}

double TurntableMotion::angleDegAt(Clock::time_point t) {
  std::lock_guard<std::mutex> lock(mutex_);
  update(Clock::now());
  // Before the current profile began the table stood at its start.
  const double mech = t < profile_.t0 ? profile_.p0 : mechAt(profile_, t);
  return mech - zero_mech_;
}

EmulatedTurntable::EmulatedTurntable(const EmulatedTurntableParams& params) : params_(params), motion_(params) {
  char name[256] = {0};
  if (openpty(&master_, &slave_, name, nullptr, nullptr) != 0)
    throw std::runtime_error(std::string("[EmulatedTurntable] openpty failed: ") + std::strerror(errno));
  device_ = name;
  // Raw on our side too: no echo, no line editing, no CR/NL translation.
  termios t{};
  tcgetattr(slave_, &t);
  cfmakeraw(&t);
  tcsetattr(slave_, TCSANOW, &t);
  thread_ = std::thread([this] { serve(); });
}

EmulatedTurntable::~EmulatedTurntable() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
}

std::string EmulatedTurntable::handle(const std::string& raw) {
  std::string line = raw;
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  if (line.size() > kTurntableMaxLine) return formatError(TurntableErrorCode::BadArgument, "line too long");
  std::istringstream in(line);
  std::string cmd;
  in >> cmd;
  const auto reply = [](TurntableErrorCode c, const std::string& detail) {
    return c == TurntableErrorCode::None ? formatOk() : formatError(c, detail);
  };
  const auto argument = [&](double& value) {
    std::string extra;
    return static_cast<bool>(in >> value) && !(in >> extra) && std::isfinite(value);
  };
  double value = 0;
  if (cmd == "ID?") return "ID sailshape-turntable-emulator 1 " + std::to_string(kTurntableCountsPerRev);
  if (cmd == "STAT?") return formatStatus(motion_.status());
  if (cmd == "POS?") return formatPosition(motion_.position());
  if (cmd == "HOME") return reply(motion_.home(), "moving");
  if (cmd == "STOP") {
    motion_.stop();
    return formatOk();
  }
  if (cmd == "VEL" || cmd == "ACC" || cmd == "MOVA" || cmd == "MOVR") {
    if (!argument(value)) return formatError(TurntableErrorCode::BadArgument, cmd + " needs one number");
    if (cmd == "VEL") return reply(motion_.setVelocity(value), "velocity must be in (0, " +
                                                                  std::to_string(params_.max_velocity_deg_s) + "]");
    if (cmd == "ACC")
      return reply(motion_.setAcceleration(value),
                   "acceleration must be in (0, " + std::to_string(params_.max_acceleration_deg_s2) + "]");
    const TurntableErrorCode c = cmd == "MOVA" ? motion_.moveTo(value) : motion_.moveBy(value);
    return reply(c, c == TurntableErrorCode::OutOfRange ? "travel is ±720 deg" : "");
  }
  return formatError(TurntableErrorCode::UnknownCommand, cmd.empty() ? "empty line" : cmd);
}

void EmulatedTurntable::serve() {
  std::string pending;
  char buf[256];
  while (!stop_) {
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) continue;
    pending.append(buf, static_cast<size_t>(n));
    size_t nl;
    while ((nl = pending.find('\n')) != std::string::npos) {
      const std::string line = pending.substr(0, nl);
      pending.erase(0, nl + 1);
      if (params_.silent) continue;
      const std::string out = handle(line) + "\n";
      size_t done = 0;
      while (done < out.size()) {
        const ssize_t w = ::write(master_, out.data() + done, out.size() - done);
        if (w <= 0) break;
        done += static_cast<size_t>(w);
      }
    }
    if (pending.size() > 4 * kTurntableMaxLine) pending.clear();  // garbage without newline
  }
}

}  // namespace sailshape
