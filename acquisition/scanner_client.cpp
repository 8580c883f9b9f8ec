#include "acquisition/scanner_client.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "acquisition/capture.hpp"

namespace sailshape {
namespace {

using Clock = std::chrono::steady_clock;

double secondsUntil(Clock::time_point deadline) {
  return std::chrono::duration<double>(deadline - Clock::now()).count();
}

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g s", s);
  return buf;
}

// Owns a socket descriptor.
class Socket {
 public:
  Socket() = default;
  explicit Socket(int fd) : fd_(fd) {}
  ~Socket() { reset(); }
  Socket(Socket&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  Socket& operator=(Socket&& o) noexcept {
    if (this != &o) {
      reset();
      fd_ = o.fd_;
      o.fd_ = -1;
    }
    return *this;
  }
  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

enum class ReadResult { kData, kTimeout, kClosed };

}  // namespace

std::string colaReplyType(const std::string& request_type) {
  if (request_type == "sRN") return "sRA";
  if (request_type == "sWN") return "sWA";
  if (request_type == "sMN") return "sAN";
  if (request_type == "sEN") return "sEA";
  throw ScannerError("[colaReplyType] '" + request_type + "' is not a request type (sRN, sWN, sMN, sEN)");
}

struct ScannerClient::Impl {
  Socket socket;
  std::optional<ColaStreamDecoder> decoder;
  ColaStreamStats previous;  // decoder statistics of earlier connections
  std::deque<std::pair<std::string, double>> pending_scans;  // payload, receive time
  std::unique_ptr<CaptureWriter> capture;
  ScannerStats stats;
  std::string where;
  bool streaming = false;
  size_t incomplete_bytes_at_close = 0;

  void syncStats() {
    const ColaStreamStats now = decoder ? decoder->stats() : ColaStreamStats{};
    stats.bad_checksum = previous.bad_checksum + now.bad_checksum;
    stats.bad_length = previous.bad_length + now.bad_length;
    stats.garbage_bytes = previous.garbage_bytes + now.garbage_bytes + previous.unterminated + now.unterminated;
  }

  void closeSocket() {
    if (decoder) {
      const ColaStreamStats s = decoder->stats();
      previous.bad_checksum += s.bad_checksum;
      previous.bad_length += s.bad_length;
      previous.garbage_bytes += s.garbage_bytes;
      previous.unterminated += s.unterminated;
      decoder.reset();
    }
    socket.reset();
    streaming = false;
  }

  void record(CaptureDirection direction, std::string_view bytes) {
    if (capture) capture->append({direction, captureClockSeconds(), std::string(bytes)});
  }

  void connectTo(const ScannerClientParams& p) {
    where = p.host + ":" + std::to_string(p.port);
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    const int rc = ::getaddrinfo(p.host.c_str(), std::to_string(p.port).c_str(), &hints, &found);
    if (rc != 0) throw ScannerError("[ScannerClient] cannot resolve '" + p.host + "': " + gai_strerror(rc));
    std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> list(found, &::freeaddrinfo);
    std::string last_error = "no address";
    for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
      Socket s(::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol));
      if (!s.valid()) {
        last_error = std::strerror(errno);
        continue;
      }
      const int flags = ::fcntl(s.get(), F_GETFL, 0);
      ::fcntl(s.get(), F_SETFL, flags | O_NONBLOCK);
      if (::connect(s.get(), a->ai_addr, a->ai_addrlen) != 0) {
        if (errno != EINPROGRESS) {
          last_error = std::strerror(errno);
          continue;
        }
        pollfd pfd{s.get(), POLLOUT, 0};
        const int n = ::poll(&pfd, 1, static_cast<int>(p.connect_timeout_s * 1000));
        if (n == 0) {
          last_error = "no answer within " + seconds(p.connect_timeout_s);
          continue;
        }
        int err = 0;
        socklen_t len = sizeof err;
        ::getsockopt(s.get(), SOL_SOCKET, SO_ERROR, &err, &len);
        if (n < 0 || err != 0) {
          last_error = std::strerror(n < 0 ? errno : err);
          continue;
        }
      }
      const int one = 1;
      ::setsockopt(s.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      socket = std::move(s);
      decoder.emplace(ColaDecoderParams{p.dialect, kColaMaxPayloadBytes});
      return;
    }
    throw ScannerError("[ScannerClient] cannot connect to " + where + ": " + last_error);
  }

  void send(const std::string& bytes, const std::string& what) {
    if (!socket.valid()) throw ScannerError("[ScannerClient] not connected to " + where + " (sending '" + what + "')");
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::send(socket.get(), bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        pollfd pfd{socket.get(), POLLOUT, 0};
        ::poll(&pfd, 1, 1000);
        continue;
      }
      if (n <= 0) {
        const std::string err = std::strerror(errno);
        closeSocket();
        throw ScannerError("[ScannerClient] connection to " + where + " broke sending '" + what + "': " + err);
      }
      done += static_cast<size_t>(n);
    }
    record(CaptureDirection::kToDevice, bytes);
  }

  // Reads what is there, waiting until `deadline` at most; feeds the decoder.
  ReadResult readSome(Clock::time_point deadline) {
    if (!socket.valid()) return ReadResult::kClosed;
    for (;;) {
      const double left = secondsUntil(deadline);
      if (left <= 0) return ReadResult::kTimeout;
      pollfd pfd{socket.get(), POLLIN, 0};
      const int n = ::poll(&pfd, 1, static_cast<int>(left * 1000) + 1);
      if (n < 0 && errno == EINTR) continue;
      if (n == 0) return ReadResult::kTimeout;
      char buf[65536];
      const ssize_t got = ::recv(socket.get(), buf, sizeof buf, 0);
      if (got < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      if (got <= 0) {
        // Complete frames were handed out before this read; only an incomplete one can be left.
        incomplete_bytes_at_close = decoder ? decoder->bufferedBytes() : 0;
        closeSocket();
        return ReadResult::kClosed;
      }
      const std::string_view data(buf, static_cast<size_t>(got));
      record(CaptureDirection::kFromDevice, data);
      decoder->feed(data);
      return ReadResult::kData;
    }
  }

  // Keeps a streamed scan for receiveScans(); counts anything else that is not the awaited reply.
  void keepUnsolicited(const ColaTelegram& t, std::string payload, double now) {
    if (t.type == "sSN") {
      if (t.name == "LMDscandata") pending_scans.emplace_back(std::move(payload), now);
      else ++stats.other_events;
    } else {
      ++stats.stray_replies;
    }
  }

  ColaTelegram awaitReply(const std::string& type, const std::string& name, const std::string& what,
                          double timeout_s) {
    const auto deadline = after(timeout_s);
    for (;;) {
      while (decoder) {
        auto payload = decoder->next();
        if (!payload) break;
        ColaTelegram t;
        try {
          t = splitColaTelegram(*payload);
        } catch (const ColaError&) {
          ++stats.stray_replies;
          continue;
        }
        if (t.type == "sFA") {
          std::string code = t.arguments;
          try {
            ColaReader r(decoder->dialect(), t.arguments, "sFA");
            code = std::to_string(r.u16("error code"));
          } catch (const ColaError&) {
          }
          throw ScannerError("[ScannerClient] " + where + " refused '" + what + "' with error sFA " + code);
        }
        if (t.type == type && t.name == name) return t;
        keepUnsolicited(t, std::move(*payload), captureClockSeconds());
      }
      const ReadResult r = readSome(deadline);
      if (r == ReadResult::kTimeout)
        throw ScannerError("[ScannerClient] " + where + " did not answer '" + what + "' within " + seconds(timeout_s));
      if (r == ReadResult::kClosed)
        throw ScannerError("[ScannerClient] " + where + " closed the connection while '" + what + "' awaited its reply");
    }
  }
};

ScannerClient::ScannerClient(ScannerClientParams params) : params_(std::move(params)), impl_(std::make_unique<Impl>()) {
  if (params_.host.empty()) throw ScannerError("[ScannerClient] host is empty");
  if (params_.port == 0) throw ScannerError("[ScannerClient] port must be 1..65535 (got 0)");
  for (double t : {params_.connect_timeout_s, params_.reply_timeout_s, params_.scan_timeout_s})
    if (!(t > 0) || t > 3600) throw ScannerError("[ScannerClient] timeouts must be in (0, 3600] s (got " + std::to_string(t) + ")");
  if (params_.start_angle >= params_.stop_angle)
    throw ScannerError("[ScannerClient] start_angle must be below stop_angle (got " + std::to_string(params_.start_angle) +
                       " >= " + std::to_string(params_.stop_angle) + ")");
  if (params_.angular_resolution == 0) throw ScannerError("[ScannerClient] angular_resolution must be > 0");
  if (!params_.capture_path.empty()) impl_->capture = std::make_unique<CaptureWriter>(params_.capture_path, params_.dialect);
}

ScannerClient::~ScannerClient() = default;

bool ScannerClient::connected() const { return impl_->socket.valid(); }

void ScannerClient::close() { impl_->closeSocket(); }

const ScannerStats& ScannerClient::stats() const {
  impl_->syncStats();
  return impl_->stats;
}

ColaTelegram ScannerClient::request(const std::string& type, const std::string& name, const std::string& arguments) {
  const std::string reply_type = colaReplyType(type);
  const std::string what = type + " " + name;
  impl_->send(frameCola(params_.dialect, colaPayload(type, name, arguments)), what);
  return impl_->awaitReply(reply_type, name, what, params_.reply_timeout_s);
}

ScannerStartup ScannerClient::start() {
  impl_->closeSocket();
  impl_->pending_scans.clear();
  impl_->connectTo(params_);
  try {
    return startupSequence();
  } catch (...) {
    // A half-configured device is left alone: the connection closes, the caller may reconnect().
    impl_->closeSocket();
    throw;
  }
}

ScannerStartup ScannerClient::startupSequence() {
  const ColaDialect d = params_.dialect;
  const std::string& where = impl_->where;
  ScannerStartup out;

  {
    ColaWriter w(d);
    w.u8(params_.access_level).u32(params_.password_hash);
    const ColaTelegram t = request("sMN", "SetAccessMode", w.bytes());
    const uint8_t ok = ColaReader(d, t.arguments, "SetAccessMode").u8("result");
    if (ok != 1)
      throw ScannerError("[ScannerClient] " + where + " refused the login (SetAccessMode level " +
                         std::to_string(params_.access_level) + " answered " + std::to_string(ok) + ")");
  }
  {
    const ColaTelegram t = request("sRN", "FirmwareVersion");
    out.firmware_version = ColaReader(d, t.arguments, "FirmwareVersion").string("version");
  }
  {
    const ColaTelegram t = request("sRN", "SCdevicestate");
    out.device_state = ColaReader(d, t.arguments, "SCdevicestate").u8("state");
    if (out.device_state == 2) throw ScannerError("[ScannerClient] " + where + " reports device state 2 (error)");
  }
  if (params_.set_scan_config) {
    ColaWriter w(d);
    if (d == ColaDialect::kAscii) {
      // SICK documents this method in CoLa A with signed decimals: "+2500 +1 +1667 -50000 +1850000".
      auto decimal = [](int64_t v) { return (v < 0 ? "-" : "+") + std::to_string(v < 0 ? -v : v); };
      w.token(decimal(params_.scan_frequency)).token("+1").token(decimal(params_.angular_resolution));
      w.token(decimal(params_.start_angle)).token(decimal(params_.stop_angle));
    } else {
      w.u32(params_.scan_frequency).i16(1).u32(params_.angular_resolution).i32(params_.start_angle).i32(params_.stop_angle);
    }
    const ColaTelegram t = request("sMN", "mLMPsetscancfg", w.bytes());
    const uint8_t status = ColaReader(d, t.arguments, "mLMPsetscancfg").u8("status");
    static const char* reasons[] = {"no error", "frequency not supported", "resolution not supported",
                                    "frequency and resolution not supported", "scan area not supported"};
    if (status != 0)
      throw ScannerError("[ScannerClient] " + where + " rejected scan frequency " + std::to_string(params_.scan_frequency) +
                         "/100 Hz, resolution " + std::to_string(params_.angular_resolution) + "/10000 deg: " +
                         (status < 5 ? reasons[status] : "error " + std::to_string(status)));
  }
  {
    // Output channel bytes {1, 0} (DIST1), remission, 8-bit RSSI, unit digits, encoder bytes {0, 0}, no
    // position/name/comment, time as asked, every scan. Two-byte fields are two tokens in CoLa A ("01 00").
    ColaWriter w(d);
    w.u8(1).u8(0).u8(params_.rssi ? 1 : 0).u8(0).u8(0).u8(0).u8(0).u8(0).u8(0).u8(0);
    w.u8(params_.time_block ? 1 : 0).u16(1);
    request("sWN", "LMDscandatacfg", w.bytes());
  }
  {
    ColaWriter w(d);
    w.u16(1).u32(params_.angular_resolution).i32(params_.start_angle).i32(params_.stop_angle);
    request("sWN", "LMPoutputRange", w.bytes());
    const ColaTelegram t = request("sRN", "LMPoutputRange");
    ColaReader r(d, t.arguments, "LMPoutputRange");
    r.u16("sectors");
    out.output_resolution = r.u32("resolution");
    out.output_start = r.i32("start angle");
    out.output_stop = r.i32("stop angle");
    if (out.output_resolution != params_.angular_resolution || out.output_start != params_.start_angle ||
        out.output_stop != params_.stop_angle)
      out.warnings.push_back("output range reads back as " + std::to_string(out.output_start) + ".." +
                             std::to_string(out.output_stop) + " step " + std::to_string(out.output_resolution) +
                             " (1/10000 deg), not as written");
  }
  {
    const ColaTelegram t = request("sMN", "LMCstartmeas");
    const uint8_t status = ColaReader(d, t.arguments, "LMCstartmeas").u8("status");
    if (status != 0) throw ScannerError("[ScannerClient] " + where + " refused LMCstartmeas (status " + std::to_string(status) + ")");
  }
  {
    const ColaTelegram t = request("sMN", "Run");
    const uint8_t ok = ColaReader(d, t.arguments, "Run").u8("result");
    if (ok != 1) throw ScannerError("[ScannerClient] " + where + " refused Run (result " + std::to_string(ok) + ")");
  }
  {
    ColaWriter w(d);
    w.u8(1);
    const ColaTelegram t = request("sEN", "LMDscandata", w.bytes());
    const uint8_t on = ColaReader(d, t.arguments, "LMDscandata").u8("event state");
    if (on != 1) throw ScannerError("[ScannerClient] " + where + " did not enable the LMDscandata stream (answered " + std::to_string(on) + ")");
  }
  impl_->streaming = true;
  return out;
}

void ScannerClient::stop() {
  if (!connected()) return;
  const ColaDialect d = params_.dialect;
  ColaWriter off(d);
  off.u8(0);
  const ColaTelegram t = request("sEN", "LMDscandata", off.bytes());
  const uint8_t state = ColaReader(d, t.arguments, "LMDscandata").u8("event state");
  if (state != 0) throw ScannerError("[ScannerClient] " + impl_->where + " kept the LMDscandata stream on");
  impl_->streaming = false;
  const ColaTelegram s = request("sMN", "LMCstopmeas");
  const uint8_t status = ColaReader(d, s.arguments, "LMCstopmeas").u8("status");
  if (status != 0) throw ScannerError("[ScannerClient] " + impl_->where + " refused LMCstopmeas (status " + std::to_string(status) + ")");
  impl_->closeSocket();
}

ScannerStartup ScannerClient::reconnect() {
  impl_->closeSocket();
  ++impl_->stats.reconnects;
  return start();
}

ScanBatch ScannerClient::receiveScans(size_t max_scans, double max_seconds) {
  ScanBatch batch;
  const auto end = after(max_seconds);
  auto last_scan = Clock::now();
  Impl& m = *impl_;
  while (batch.scans.size() < max_scans) {
    // Frames already buffered first: telegrams kept while waiting for replies, then the decoder's.
    while (m.pending_scans.empty() && m.decoder) {
      auto payload = m.decoder->next();
      if (!payload) break;
      ColaTelegram t;
      try {
        t = splitColaTelegram(*payload);
      } catch (const ColaError&) {
        ++m.stats.stray_replies;
        continue;
      }
      m.keepUnsolicited(t, std::move(*payload), captureClockSeconds());
    }
    if (!m.pending_scans.empty()) {
      auto [payload, when] = std::move(m.pending_scans.front());
      m.pending_scans.pop_front();
      try {
        batch.scans.push_back(decodeScanData(payload, params_.dialect));
        batch.receive_times_s.push_back(when);
        ++m.stats.scans;
        last_scan = Clock::now();
      } catch (const ColaError&) {
        ++m.stats.undecodable;
      }
      continue;
    }
    const auto scan_deadline = last_scan + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(params_.scan_timeout_s));
    const auto deadline = std::min(end, scan_deadline);
    if (Clock::now() >= end) break;
    const ReadResult r = m.readSome(deadline);
    if (r == ReadResult::kClosed) {
      batch.connection_lost = true;
      // The scans the client received in all (a batch of one, nextScan's, would count none).
      batch.message = "connection to " + m.where + " lost after " + std::to_string(m.stats.scans) + " scans";
      if (m.incomplete_bytes_at_close > 0)
        batch.message += " (an incomplete frame of " + std::to_string(m.incomplete_bytes_at_close) + " bytes was discarded)";
      break;
    }
    if (r == ReadResult::kTimeout && Clock::now() >= scan_deadline && Clock::now() < end) {
      batch.timed_out = true;
      batch.message = "no scan from " + m.where + " within " + seconds(params_.scan_timeout_s);
      break;
    }
  }
  return batch;
}

ScanData ScannerClient::nextScan() {
  ScanBatch b = receiveScans(1, params_.scan_timeout_s);
  if (b.scans.empty()) {
    if (b.connection_lost) throw ScannerError("[ScannerClient::nextScan] " + b.message);
    throw ScannerError("[ScannerClient::nextScan] no scan from " + impl_->where + " within " + seconds(params_.scan_timeout_s));
  }
  return std::move(b.scans.front());
}

ScanData ScannerClient::pollScan() {
  const ColaTelegram t = request("sRN", "LMDscandata");
  try {
    ScanData s = decodeScanData(joinColaTelegram(t), params_.dialect);
    ++impl_->stats.scans;
    return s;
  } catch (const ColaError& e) {
    ++impl_->stats.undecodable;
    throw ScannerError("[ScannerClient::pollScan] " + impl_->where + " sent an undecodable scan: " + e.what());
  }
}

}  // namespace sailshape
