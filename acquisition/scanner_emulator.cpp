#include "acquisition/scanner_emulator.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <iterator>
#include <random>
#include <stdexcept>
#include <vector>

#include "acquisition/cola.hpp"
#include "acquisition/scan_data.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

namespace {

using Clock = std::chrono::steady_clock;

// SOPAS error numbers sent in sFA replies, as SICK's driver names them (sick_scan_xd, SopasBase's
// convertSopasErrorCodeToText).
constexpr uint16_t kErrMethodAccessDenied = 1;  // METHODIN_ACCESSDENIED: a method that needs a login
constexpr uint16_t kErrUnknownMethod = 2;       // METHODIN_UNKNOWNINDEX
constexpr uint16_t kErrUnknownVariable = 3;     // VARIABLE_UNKNOWNINDEX (what the LMS511 answers an unknown sRN)
constexpr uint16_t kErrLocalCondition = 4;      // LOCALCONDITIONFAILED: a value outside what the device accepts
constexpr uint16_t kErrInvalidData = 5;         // INVALID_DATA: arguments missing or not parsable
constexpr uint16_t kErrWriteAccessDenied = 10;  // VARIABLE_WRITE_ACCESSDENIED: a write that needs a login
constexpr uint16_t kErrUnknownCommand = 12;     // UNKNOWN_COLA_COMMAND: a type other than sRN, sWN, sMN, sEN
constexpr uint16_t kErrUnknownEvent = 15;       // EVENTREG_UNKNOWNINDEX

// "sFA" + u16 code (CoLa B) or "sFA <code>" (CoLa A, hex like every number there).
std::string sopasError(bool binary, uint16_t code) {
  return "sFA" + (binary ? ColaWriter(ColaDialect::kBinary).u16(code).bytes()
                         : " " + ColaWriter(ColaDialect::kAscii).u16(code).bytes());
}

std::vector<uint8_t> hexBytes(const char* hex) {
  std::vector<uint8_t> out;
  for (size_t i = 0; hex[i] && hex[i + 1]; i += 2) out.push_back(static_cast<uint8_t>(std::stoi(std::string(hex + i, 2), nullptr, 16)));
  return out;
}

// Field dictionaries the recorded devices returned for unconfigured evaluation fields 000-009 (the first
// byte pair is the field's scale, the last byte its index; see ../shared/sick-recordings).
const char* kFieldTemplate111 = "3f8000000000000000001388fff9223002000000000000000000000100000000";
const char* kFieldTemplate511 = "400000000000000000001388ffff3cb002000000000000000000000100000000";
// LIDinputstate replies as recorded.
const char* kInputState111 = "000100000000020202020000";
const char* kInputState511 = "00000029742d00000000000107b2010100000200079950";

int64_t roundToInt(double v) { return static_cast<int64_t>(std::llround(v)); }

}  // namespace

struct ScannerEmulator::Session {
  // Device configuration (kept across connections, as on a real device). Angles in 1/10000°.
  // The scan configuration (LMPscancfg, set by mLMPsetscancfg): frequency in 1/100 Hz, step, and the one
  // sector the mirror measures over.
  uint32_t frequency = 2500;
  uint32_t resolution = 1667;
  int32_t sector_start = -50000, sector_stop = 1850000;
  // The output range (LMPoutputRange): the part of the sector LMDscandata carries, at the scan's step.
  int32_t start = -50000, stop = 1850000;
  uint8_t echo_filter = 0;  // FREchoFilter (LMS5xx): 0 first echo, 1 all echoes, 2 last echo
  bool remission = true, encoder = false, time_block = false;
  std::string scandatacfg_args;  // as last written, echoed by sRN LMDscandatacfg
  // Per connection.
  int access_level = 0;
  bool measuring = false, running = false, streaming = false;
  Clock::time_point stream_start;
  uint64_t next_scan = 0;
  uint16_t telegram_counter = 0, scan_counter = 0;
  uint64_t sent_this_connection = 0;
};

ScannerEmulator::ScannerEmulator(const Scene& scene, const ScannerEmulatorParams& params, TurntableMotion* turntable)
    : params_(params),
      sensor_(scene, params.sensor),
      turntable_(turntable),
      epoch_(turntable ? turntable->epoch() : Clock::now()),
      ready_at_(Clock::now() + std::chrono::microseconds(roundToInt(std::max(0.0, params.spin_up_s) * 1e6))),
      session_(std::make_unique<Session>()) {
  const ScannerSpec spec = sensor_.spec();
  session_->frequency = static_cast<uint32_t>(std::lround(spec.default_frequency_hz * 100));
  session_->resolution = static_cast<uint32_t>(std::lround(spec.default_resolution_deg * 10000));
  session_->start = session_->sector_start = static_cast<int32_t>(std::lround(spec.first_angle_deg * 10000));
  session_->stop = session_->sector_stop = static_cast<int32_t>(std::lround(spec.last_angle_deg * 10000));
  session_->remission = params.sensor.model == ScannerModel::Lms511;

  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) throw std::runtime_error(std::string("[ScannerEmulator] socket: ") + std::strerror(errno));
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(params.port);
  if (inet_pton(AF_INET, params.bind_address.c_str(), &addr.sin_addr) != 1) {
    ::close(listen_fd_);
    throw std::runtime_error("[ScannerEmulator] not an IPv4 address: '" + params.bind_address + "'");
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listen_fd_, 4) != 0) {
    const std::string why = std::strerror(errno);
    ::close(listen_fd_);
    throw std::runtime_error("[ScannerEmulator] cannot listen on " + params.bind_address + ":" +
                             std::to_string(params.port) + ": " + why);
  }
  socklen_t len = sizeof addr;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  thread_ = std::thread([this] { serve(); });
}

ScannerEmulator::~ScannerEmulator() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

void ScannerEmulator::serve() {
  while (!stop_) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;
    const int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    ++connections_;
    runSession(fd);
    ::close(fd);
  }
}

void ScannerEmulator::runSession(int fd) {
  Session& s = *session_;
  s.access_level = 0;
  s.measuring = s.running = s.streaming = false;
  s.sent_this_connection = 0;
  std::unique_ptr<ColaStreamDecoder> decoder;
  std::string pending;  // bytes before the dialect is known
  bool binary = true;
  const auto sendAll = [&](const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t w = ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) return false;
      done += static_cast<size_t>(w);
    }
    return true;
  };
  char buf[4096];
  // When scan k of the stream starts (scan k + 1's start is when scan k is due).
  // Read at each use: a request may change the frequency or restart the stream.
  auto scanTime = [&](uint64_t k) {
    const double period_s = 100.0 / s.frequency;
    return s.stream_start + std::chrono::microseconds(roundToInt(static_cast<double>(k) * period_s * 1e6));
  };
  while (!stop_) {
    int wait_ms = 20;
    if (s.streaming && s.measuring) {
      const Clock::time_point due = scanTime(s.next_scan + 1);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(due - Clock::now()).count();
      wait_ms = static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(left, 20)));
    }
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, wait_ms);
    if (r > 0) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) return;  // the client closed or the connection broke
      if (!decoder) {
        pending.append(buf, static_cast<size_t>(n));
        const size_t stx = pending.find('\x02');
        if (stx == std::string::npos || pending.size() < stx + 2) continue;
        binary = pending[stx + 1] == '\x02';
        decoder = std::make_unique<ColaStreamDecoder>(
            ColaDecoderParams{binary ? ColaDialect::kBinary : ColaDialect::kAscii, kColaMaxPayloadBytes});
        decoder->feed(pending);
        pending.clear();
      } else {
        decoder->feed(std::string_view(buf, static_cast<size_t>(n)));
      }
      while (auto payload = decoder->next()) {
        if (params_.mute) continue;
        const std::string out = reply(*payload, binary);
        if (!out.empty() && !sendAll(frameCola(binary ? ColaDialect::kBinary : ColaDialect::kAscii, out))) return;
      }
    }
    // Due as the stream now stands: a request just read may have started it (or the spin-up holds it).
    if (s.streaming && s.measuring && Clock::now() >= scanTime(s.next_scan + 1)) {
      // Behind by more than max_lag_s: the scans in between are lost, counted but never sent.
      const Clock::time_point now = Clock::now();
      const auto max_lag = std::chrono::microseconds(roundToInt(std::max(0.0, params_.max_lag_s) * 1e6));
      while (now - scanTime(s.next_scan + 1) > max_lag) {
        ++s.next_scan;
        ++s.scan_counter;
        ++scans_dropped_;
      }
      const Clock::time_point scan_start = scanTime(s.next_scan);
      ++s.next_scan;
      if (params_.slow_host_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(params_.slow_host_s));
      if (!sendAll(frameCola(binary ? ColaDialect::kBinary : ColaDialect::kAscii,
                             scanPayload(binary, false, scan_start))))
        return;
      ++scans_sent_;
      ++s.sent_this_connection;
      if (params_.drop_after_scans >= 0 && s.sent_this_connection >= static_cast<uint64_t>(params_.drop_after_scans))
        return;  // fault injection: the device goes away mid-stream
    }
  }
}

std::string ScannerEmulator::scanPayload(bool binary, bool polled, Clock::time_point scan_start) {
  Session& s = *session_;
  const ColaDialect dialect = binary ? ColaDialect::kBinary : ColaDialect::kAscii;
  const double period_s = 100.0 / s.frequency;
  // As the devices count: 1141 values for -5°..185° in 0.1667° steps.
  const size_t count = static_cast<size_t>(std::lround(static_cast<double>(s.stop - s.start) / s.resolution)) + 1;
  const double start_deg = s.start / 10000.0, step_deg = s.resolution / 10000.0;
  const uint64_t scan_index = s.scan_counter;
  std::mt19937_64 rng(params_.seed + scan_index);

  ScanChannel dist;
  dist.name = "DIST1";
  dist.start_angle = s.start;
  dist.angular_step = static_cast<uint16_t>(s.resolution);
  dist.values.resize(count);
  ScanChannel rssi = dist;
  rssi.name = "RSSI1";
  const Eigen::Matrix3d R = params_.pose.linear();
  const Vec3 T = params_.pose.translation();
  for (size_t i = 0; i < count; ++i) {
    const double alpha_deg = start_deg + step_deg * static_cast<double>(i);
    // The mirror turns once per period: beam i fires (α_i − α_first)/360° of a period after the first.
    const auto fire = scan_start + std::chrono::microseconds(
                                       roundToInt((alpha_deg - start_deg) / 360.0 * period_s * 1e6));
    const double beta = turntable_ ? turntable_->angleDegAt(fire) * kRadPerDeg : 0.0;
    const Vec3 origin(0, params_.p_m * std::cos(beta + params_.theta_rad), params_.p_m * std::sin(beta + params_.theta_rad));
    const double a = alpha_deg * kRadPerDeg;
    const Vec3 dir(std::cos(a), std::sin(a) * std::cos(beta), std::sin(a) * std::sin(beta));
    const BeamReturn b = sensor_.measure(R * origin + T, R * dir, rng);
    if (b.status == ReturnStatus::Valid) {
      dist.values[i] = static_cast<uint16_t>(std::clamp<int64_t>(roundToInt(b.range_m * 1000.0), 1, 65535));
      rssi.values[i] = b.rssi;
    }
  }
  ScanData scan;
  scan.command_type = polled ? "sRA" : "sSN";
  scan.version = params_.sensor.model == ScannerModel::Lms111 ? 1 : 0;
  scan.device_number = 1;
  scan.serial_number = params_.serial_number ? params_.serial_number
                       : params_.sensor.model == ScannerModel::Lms111 ? 18090362u
                                                                      : 18110550u;
  scan.telegram_counter = ++s.telegram_counter;
  scan.scan_counter = ++s.scan_counter;
  const auto us = [&](Clock::time_point t) {
    return static_cast<uint32_t>(std::chrono::duration_cast<std::chrono::microseconds>(t - epoch_).count());
  };
  scan.time_since_startup_us = us(scan_start);
  scan.scan_frequency = s.frequency;
  scan.measurement_frequency = static_cast<uint32_t>(std::lround(360.0 / step_deg * (s.frequency / 100.0) / 100.0));
  if (s.encoder) {
    const int64_t counts =
        turntable_ ? std::llround(turntable_->angleDegAt(scan_start) / 360.0 * kTurntableCountsPerRev) : 0;
    scan.encoders.push_back({static_cast<uint32_t>(counts), 0});
  }
  scan.channels16.push_back(std::move(dist));
  if (s.remission) scan.channels8.push_back(std::move(rssi));
  if (s.time_block) {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    scan.time = ScanTime{static_cast<uint16_t>(tm.tm_year + 1900), static_cast<uint8_t>(tm.tm_mon + 1),
                         static_cast<uint8_t>(tm.tm_mday), static_cast<uint8_t>(tm.tm_hour),
                         static_cast<uint8_t>(tm.tm_min), static_cast<uint8_t>(tm.tm_sec), 0};
  }
  // Stamped last, as the device stamps the moment it sends.
  scan.time_of_transmission_us = us(Clock::now());
  return encodeScanData(scan, dialect);
}

struct ScannerEmulator::Request {
  Request(const std::string& payload, bool binary_)
      : binary(binary_),
        dialect(binary_ ? ColaDialect::kBinary : ColaDialect::kAscii),
        t(splitColaTelegram(payload)),
        in(dialect, t.arguments, t.type + " " + t.name),
        w(dialect) {}
  std::string out(const char* type, const ColaWriter& writer) const { return colaPayload(type, t.name, writer.bytes()); }
  std::string bare(const char* type) const { return std::string(type) + " " + t.name + " "; }
  std::string fail(uint16_t code) const { return sopasError(binary, code); }
  bool binary;
  ColaDialect dialect;
  ColaTelegram t;
  ColaReader in;  // the request's arguments
  ColaWriter w;   // the reply's
};

std::string ScannerEmulator::reply(const std::string& request, bool binary) {
  try {
    Request r(request, binary);
    if (r.t.type == "sMN") return replyMethod(r);
    if (r.t.type == "sRN") return replyRead(r);
    if (r.t.type == "sWN") return replyWrite(r);
    if (r.t.type == "sEN") return replyEvent(r);
    return r.fail(kErrUnknownCommand);
  } catch (const ColaError&) {  // not a telegram, or arguments missing or unreadable
    return sopasError(binary, kErrInvalidData);
  }
}

// sMN: log in, start and stop measuring, scan configuration.
std::string ScannerEmulator::replyMethod(Request& r) {
  Session& s = *session_;
  const bool lms111 = params_.sensor.model == ScannerModel::Lms111;
  if (r.t.name == "SetAccessMode") {
    const uint8_t level = r.in.u8("user level");
    const uint32_t hash = r.in.u32("password hash");
    // SICK's documented hashes: 2 maintenance, 3 authorised client, 4 service.
    const bool ok = !params_.refuse_login && ((level == 2 && hash == 0xB21ACE26u) ||
                                              (level == 3 && hash == 0xF4724744u) ||
                                              (level == 4 && hash == 0x81BE23AAu));
    if (ok) s.access_level = level;
    return r.out("sAN", r.w.u8(ok ? 1 : 0));
  }
  if (r.t.name == "Run") {
    s.running = true;
    return r.out("sAN", r.w.u8(1));
  }
  static const char* const kMethods[] = {"LMCstartmeas", "LMCstopmeas", "mLMPsetscancfg"};
  if (std::find(std::begin(kMethods), std::end(kMethods), r.t.name) == std::end(kMethods))
    return r.fail(kErrUnknownMethod);
  if (s.access_level < 2) return r.fail(kErrMethodAccessDenied);
  if (r.t.name == "LMCstartmeas") {
    if (!s.measuring) {
      s.stream_start = std::max(Clock::now(), ready_at_);  // a starting device streams nothing yet
      s.next_scan = 0;
    }
    s.measuring = true;
    return r.out("sAN", r.w.u8(0));
  }
  if (r.t.name == "LMCstopmeas") {
    s.measuring = false;
    return r.out("sAN", r.w.u8(0));
  }
  {  // mLMPsetscancfg
    const uint32_t f = r.in.u32("scan frequency");
    r.in.u16("sectors");
    const uint32_t res = r.in.u32("angular resolution");
    const int32_t start = r.in.i32("start angle");
    const int32_t stop = r.in.i32("stop angle");
    const ScannerSpec spec = sensor_.spec();
    const bool f_ok = lms111 ? (f == 2500 || f == 5000)
                             : (f == 2500 || f == 3500 || f == 5000 || f == 7500 || f == 10000);
    const bool res_ok = lms111 ? (res == 2500 || res == 5000)
                               : (res == 1667 || res == 2500 || res == 3333 || res == 5000 || res == 6667 ||
                                  res == 10000);
    // Status: 0 no error, 1 frequency not supported, 2 resolution not supported, 3 both, 4 sector wrong.
    uint8_t status = (f_ok ? 0 : 1) | (res_ok ? 0 : 2);
    if (status == 0 && !(start >= spec.first_angle_deg * 10000 && stop <= spec.last_angle_deg * 10000 && start < stop))
      status = 4;
    if (status == 0) {
      s.frequency = f;
      s.resolution = res;
      s.sector_start = start;
      s.sector_stop = stop;
      // The output range cannot reach beyond what the mirror measures: it becomes the new sector.
      s.start = start;
      s.stop = stop;
    }
    return r.out("sAN", r.w.u8(status).u32(s.frequency).u16(1).u32(s.resolution).i32(s.sector_start).i32(s.sector_stop));
  }
}

// sRN: device facts and configuration as the recorded devices answered, and a polled scan.
std::string ScannerEmulator::replyRead(Request& r) {
  Session& s = *session_;
  const bool lms111 = params_.sensor.model == ScannerModel::Lms111;
  if (r.t.name == "FirmwareVersion") return r.out("sRA", r.w.string(lms111 ? "V1.80.2  " : "V1.80    "));
  if (r.t.name == "SCdevicestate") return r.out("sRA", r.w.u8(Clock::now() < ready_at_ ? 0 : 1));  // 0 busy, 1 ready
  if (r.t.name == "ODoprh") return r.out("sRA", r.w.u32(lms111 ? 0x456 : 0x4ab));
  if (r.t.name == "ODpwrc") return r.out("sRA", r.w.u32(lms111 ? 0x3f : 0x63));
  if (r.t.name == "LocationName") return r.out("sRA", r.w.string(lms111 ? "not defined" : "SN 18110550"));
  if (r.t.name == "DeviceIdent")
    return r.out("sRA", r.w.string(lms111 ? "LMS11x" : "LMS5xx").string(lms111 ? "V1.80.2" : "V1.80"));
  if (r.t.name == "SerialNumber")
    return r.out("sRA", r.w.string(std::to_string(params_.serial_number ? params_.serial_number
                                               : lms111           ? 18090362u
                                                                  : 18110550u)));
  if (r.t.name == "LMPoutputRange") return r.out("sRA", r.w.u16(1).u32(s.resolution).i32(s.start).i32(s.stop));
  // Scan frequency, active sectors (one), then per sector its step, start and stop (LMS1xx/5xx telegram
  // listing; sick_scan_xd reads it as "%4y%2y%4y%4y%4y").
  if (r.t.name == "LMPscancfg")
    return r.out("sRA", r.w.u32(s.frequency).u16(1).u32(s.resolution).i32(s.sector_start).i32(s.sector_stop));
  if (r.t.name == "FREchoFilter" && !lms111) return r.out("sRA", r.w.u8(s.echo_filter));
  if (r.t.name == "LMDscandatacfg") {
    if (!s.scandatacfg_args.empty()) return colaPayload("sRA", r.t.name, s.scandatacfg_args);
    return r.out("sRA", r.w.u8(1).u8(0).u8(s.remission).u8(0).u8(0).u8(s.encoder ? 1 : 0).u8(0).u8(0).u8(0).u8(0)
                          .u8(s.time_block).u16(1));
  }
  if (r.t.name == "LIDinputstate") {
    for (uint8_t b : hexBytes(lms111 ? kInputState111 : kInputState511)) r.w.u8(b);
    return r.out("sRA", r.w);
  }
  if (r.t.name.size() == 8 && r.t.name.rfind("field0", 0) == 0) {
    const int index = std::atoi(r.t.name.c_str() + 5);
    if (index >= 10) return r.out("sRA", r.w.u8(0));  // no field set with that number
    std::vector<uint8_t> bytes = hexBytes(lms111 ? kFieldTemplate111 : kFieldTemplate511);
    bytes.back() = static_cast<uint8_t>(index);
    for (uint8_t b : bytes) r.w.u8(b);
    return r.out("sRA", r.w);
  }
  if (r.t.name == "LMDscandata") {
    const double period_s = 100.0 / s.frequency;
    return scanPayload(r.binary, true, Clock::now() - std::chrono::microseconds(roundToInt(period_s * 1e6)));
  }
  return r.fail(kErrUnknownVariable);
}

// sWN: the CoLa dialect, output range, scan data contents, echo filter and the encoder input.
std::string ScannerEmulator::replyWrite(Request& r) {
  Session& s = *session_;
  const bool lms111 = params_.sensor.model == ScannerModel::Lms111;
  if (r.t.name == "EIHstCola") return r.bare("sWA");
  // FREchoFilter and DO3And4Fnc (inputs 3 and 4 as the encoder's) exist on the LMS5xx only; SICK's driver
  // sends neither to an LMS1xx.
  static const char* const kVariables[] = {"LMPoutputRange", "LMDscandatacfg", "LICsrc", "LICencset", "LICencres"};
  const bool lms5xx_only = r.t.name == "FREchoFilter" || r.t.name == "DO3And4Fnc";
  if ((lms5xx_only && lms111) ||
      (!lms5xx_only && std::find(std::begin(kVariables), std::end(kVariables), r.t.name) == std::end(kVariables)))
    return r.fail(kErrUnknownVariable);
  if (s.access_level < 2) return r.fail(kErrWriteAccessDenied);
  if (r.t.name == "FREchoFilter") {
    const uint8_t filter = r.in.u8("echo filter");
    if (filter > 2) return r.fail(kErrLocalCondition);
    s.echo_filter = filter;
    return r.bare("sWA");
  }
  // The encoder settings SICK's driver writes when asked for an encoder (encoder_mode ≥ 0): increment
  // source (0 fixed speed, 1 encoder), encoder mode (0 off, 1 single increment, 2 and 3 with direction),
  // resolution (float, mm per tick) and inputs 3/4 as the encoder's. Scans carry the turntable's encoder
  // block whatever they say (LMDscandatacfg asks for it).
  if (r.t.name == "LICsrc" || r.t.name == "DO3And4Fnc") {
    if (r.in.u8("setting") > 1) return r.fail(kErrLocalCondition);
    return r.bare("sWA");
  }
  if (r.t.name == "LICencset") {
    if (r.in.u8("encoder mode") > 3) return r.fail(kErrLocalCondition);
    return r.bare("sWA");
  }
  if (r.t.name == "LICencres") {
    r.in.f32("resolution");
    return r.bare("sWA");
  }
  if (r.t.name == "LMPoutputRange") {
    r.in.u16("sectors");
    const uint32_t res = r.in.u32("angular resolution");
    const int32_t start = r.in.i32("start angle");
    const int32_t stop = r.in.i32("stop angle");
    // Within the measured sector, at its step.
    if (res != s.resolution || !(start >= s.sector_start && stop <= s.sector_stop && start < stop))
      return r.fail(kErrLocalCondition);
    s.start = start;
    s.stop = stop;
    return r.bare("sWA");
  }
  {  // LMDscandatacfg
    // Two-byte fields go as byte pairs ("1 0" in CoLa A), as SICK's driver writes them.
    const uint8_t channel = r.in.u8("output channel");
    r.in.u8("output channel (second byte)");
    const uint8_t remission = r.in.u8("remission");
    const uint8_t resolution = r.in.u8("remission resolution");
    r.in.u8("unit");
    const uint8_t encoder = r.in.u8("encoder");
    r.in.u8("encoder (second byte)");
    r.in.u8("position");
    r.in.u8("device name");
    r.in.u8("comment");
    const uint8_t time = r.in.u8("time");
    r.in.u16("output interval");
    if (channel == 0 || resolution > 1) return r.fail(kErrLocalCondition);
    s.remission = remission != 0;
    s.encoder = encoder != 0;
    s.time_block = time != 0;
    s.scandatacfg_args = r.t.arguments;
    return r.bare("sWA");
  }
}

// sEN: subscriptions; only LMDscandata streams anything.
std::string ScannerEmulator::replyEvent(Request& r) {
  Session& s = *session_;
  if (r.t.name != "LMDscandata" && r.t.name != "LFErec" && r.t.name != "LIDoutputstate" && r.t.name != "LIDinputstate")
    return r.fail(kErrUnknownEvent);
  const uint8_t on = r.in.u8("enable");
  if (r.t.name == "LMDscandata") {
    if (on && !s.streaming) {
      s.stream_start = std::max(Clock::now(), ready_at_);  // a starting device streams nothing yet
      s.next_scan = 0;
    }
    s.streaming = on != 0;
  }
  return r.out("sEA", r.w.u8(on));
}

}  // namespace sailshape
