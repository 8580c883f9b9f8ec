#include "acquisition/turntable.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "analysis/core/errors.hpp"

namespace sailshape {

namespace {

speed_t baudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
  }
  throw InvalidInput("[TurntableClient] unsupported baud rate " + std::to_string(baud) +
                     " (9600, 19200, 38400, 57600, 115200, 230400, 460800 or 921600)");
}

}  // namespace

double hostTimeSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

TurntableClient::TurntableClient(const TurntableLinkParams& params) : params_(params) {
  const speed_t speed = baudConstant(params.baud);
  if (params.reply_timeout_ms <= 0)
    throw InvalidInput("[TurntableClient] reply_timeout_ms must be > 0 (got " +
                       std::to_string(params.reply_timeout_ms) + ")");
  fd_ = ::open(params.device.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (fd_ < 0)
    throw TurntableError("[TurntableClient] cannot open " + params.device + ": " + std::strerror(errno));
  termios t{};
  if (tcgetattr(fd_, &t) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw TurntableError("[TurntableClient] " + params.device + " is not a serial line (tcgetattr: " + why + ")");
  }
  cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  cfsetispeed(&t, speed);
  cfsetospeed(&t, speed);
  if (tcsetattr(fd_, TCSANOW, &t) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw TurntableError("[TurntableClient] cannot configure " + params.device + ": " + why);
  }
  tcflush(fd_, TCIOFLUSH);
}

TurntableClient::~TurntableClient() {
  if (fd_ >= 0) ::close(fd_);
}

std::string TurntableClient::readLine() {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(params_.reply_timeout_ms);
  for (;;) {
    const size_t nl = buffer_.find('\n');
    if (nl != std::string::npos) {
      std::string line = buffer_.substr(0, nl);
      buffer_.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      throw TurntableError("[TurntableClient] no reply from " + params_.device + " within " +
                           std::to_string(params_.reply_timeout_ms) + " ms");
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(left.count()));
    if (r < 0 && errno != EINTR)
      throw TurntableError("[TurntableClient] poll on " + params_.device + ": " + std::strerror(errno));
    if (r <= 0) continue;
    char buf[256];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && errno != EAGAIN && errno != EINTR)
      throw TurntableError("[TurntableClient] read from " + params_.device + ": " + std::strerror(errno));
    if (n > 0) buffer_.append(buf, static_cast<size_t>(n));
    if (buffer_.size() > 16 * kTurntableMaxLine)
      throw TurntableError("[TurntableClient] " + params_.device + " sends a line longer than " +
                           std::to_string(16 * kTurntableMaxLine) + " bytes");
  }
}

std::string TurntableClient::request(const std::string& line) {
  buffer_.clear();  // a late reply to an earlier, timed-out request must not answer this one
  tcflush(fd_, TCIFLUSH);
  const std::string out = line + "\n";
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t w = ::write(fd_, out.data() + done, out.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw TurntableError("[TurntableClient] write to " + params_.device + ": " + std::strerror(errno));
    done += static_cast<size_t>(w);
  }
  std::string reply = readLine();
  if (auto err = parseError(reply))
    throw TurntableError("[TurntableClient] " + line + " refused by the drive: " + reply, err->first);
  return reply;
}

std::string TurntableClient::identify() {
  const std::string r = request("ID?");
  if (r.rfind("ID ", 0) != 0) throw TurntableError("[TurntableClient] ID? got an unexpected reply: " + r);
  return r.substr(3);
}

TurntableStatus TurntableClient::status() {
  const std::string r = request("STAT?");
  const auto s = parseStatus(r);
  if (!s) throw TurntableError("[TurntableClient] STAT? got an unexpected reply: " + r);
  return *s;
}

TurntableSample TurntableClient::sample() {
  const double t0 = hostTimeSeconds();
  const std::string r = request("POS?");
  const double t1 = hostTimeSeconds();
  const auto p = parsePosition(r);
  if (!p) throw TurntableError("[TurntableClient] POS? got an unexpected reply: " + r);
  return {0.5 * (t0 + t1), p->counts, p->device_time_us};
}

namespace {
void expectOk(const std::string& command, const std::string& reply) {
  if (reply != "OK") throw TurntableError("[TurntableClient] " + command + " got an unexpected reply: " + reply);
}
std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}
}  // namespace

void TurntableClient::setVelocity(double v) { expectOk("VEL", request("VEL " + number(v))); }
void TurntableClient::setAcceleration(double a) { expectOk("ACC", request("ACC " + number(a))); }
void TurntableClient::moveAbsolute(double deg) { expectOk("MOVA", request("MOVA " + number(deg))); }
void TurntableClient::moveRelative(double deg) { expectOk("MOVR", request("MOVR " + number(deg))); }
void TurntableClient::stop() { expectOk("STOP", request("STOP")); }

bool TurntableClient::waitIdle(double timeout_s) {
  const double end = hostTimeSeconds() + timeout_s;
  for (;;) {
    const TurntableStatus s = status();
    if (s.state == TurntableState::Error)
      throw TurntableError("[TurntableClient] drive fault: " + turntableErrorWord(s.error), s.error);
    if (s.state == TurntableState::Idle) return true;
    if (hostTimeSeconds() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void TurntableClient::home(double timeout_s, const Progress& progress) {
  expectOk("HOME", request("HOME"));
  const double start = hostTimeSeconds();
  for (;;) {
    const TurntableStatus s = status();
    if (s.state == TurntableState::Error) {
      if (s.error == TurntableErrorCode::HomeNotFound)
        throw TurntableError("[TurntableClient::home] the drive on " + params_.device +
                                 " never found the home sensor (check the proximity sensor and its wiring)",
                             s.error);
      throw TurntableError("[TurntableClient::home] drive fault " + turntableErrorWord(s.error), s.error);
    }
    if (s.state == TurntableState::Idle && s.homed) {
      progress("home", 1.0);
      return;
    }
    const double elapsed = hostTimeSeconds() - start;
    if (elapsed > timeout_s) {
      try {
        stop();
      } catch (const TurntableError&) {
      }
      throw TurntableError("[TurntableClient::home] not homed after " + std::to_string(timeout_s) + " s on " +
                           params_.device);
    }
    progress("home", std::min(0.99, elapsed / timeout_s));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace sailshape
