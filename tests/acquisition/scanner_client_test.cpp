// ScannerClient against a scripted TCP peer on 127.0.0.1 (real sockets, ephemeral port). The binary
// start-up test answers with the replies the real LMS511 gave SICK's driver in the recordings.
#include "acquisition/scanner_client.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

#include "acquisition/capture.hpp"

namespace sailshape {
namespace {

const std::string kRecordings = std::string(SAILSHAPE_SHARED) + "/sick-recordings/";

// One accepted connection of the scripted peer.
class PeerConnection {
 public:
  PeerConnection(int fd, ColaDialect dialect) : fd_(fd), decoder_({dialect}), dialect_(dialect) {}
  ~PeerConnection() { ::close(fd_); }
  // The next request payload, or nothing when the client closed or `timeout_s` passed.
  std::optional<std::string> nextRequest(double timeout_s = 5.0) {
    for (;;) {
      if (auto p = decoder_.next()) {
        requests.push_back(*p);
        return p;
      }
      pollfd pfd{fd_, POLLIN, 0};
      if (::poll(&pfd, 1, static_cast<int>(timeout_s * 1000)) <= 0) return std::nullopt;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return std::nullopt;
      decoder_.feed(std::string_view(buf, static_cast<size_t>(n)));
    }
  }
  void sendRaw(const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return;
      done += static_cast<size_t>(n);
    }
  }
  void send(const std::string& payload) { sendRaw(frameCola(dialect_, payload)); }
  ColaDialect dialect() const { return dialect_; }
  std::vector<std::string> requests;

 private:
  int fd_;
  ColaStreamDecoder decoder_;
  ColaDialect dialect_;
};

// Listens on 127.0.0.1:0 and runs `script` on each of `connections` accepted connections in turn.
class ScriptedPeer {
 public:
  using Script = std::function<void(PeerConnection&, int index)>;
  ScriptedPeer(ColaDialect dialect, Script script, int connections = 1) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listen_fd_, 4) != 0)
      throw std::runtime_error("test peer: cannot listen");
    socklen_t len = sizeof addr;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    thread_ = std::thread([this, dialect, script, connections] {
      for (int i = 0; i < connections; ++i) {
        pollfd pfd{listen_fd_, POLLIN, 0};
        if (::poll(&pfd, 1, 10000) <= 0) return;
        const int fd = ::accept(listen_fd_, nullptr, nullptr);
        if (fd < 0) return;
        PeerConnection c(fd, dialect);
        try {
          script(c, i);
        } catch (const std::exception& e) {
          ADD_FAILURE() << "test peer: " << e.what();
        }
        std::lock_guard<std::mutex> lock(mutex_);
        requests_.push_back(c.requests);
      }
    });
  }
  ~ScriptedPeer() {
    if (thread_.joinable()) thread_.join();
    ::close(listen_fd_);
  }
  uint16_t port() const { return port_; }
  // Requests each finished connection received (call after the client is done and the script returned).
  std::vector<std::vector<std::string>> requests() {
    if (thread_.joinable()) thread_.join();
    return requests_;
  }

 private:
  int listen_fd_ = -1;
  uint16_t port_ = 0;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::vector<std::string>> requests_;
};

std::string bytes(std::initializer_list<int> list) {
  std::string out;
  for (int b : list) out += static_cast<char>(b);
  return out;
}

// What a recording's device replied to each request of SICK's driver, and its streamed scans.
struct RecordedDevice {
  std::map<std::string, std::string> replies;        // "sRN FirmwareVersion" -> reply payload
  std::map<std::string, std::string> request_args;   // what the driver sent, by "type name"
  std::vector<std::string> scans;                     // sSN LMDscandata payloads in order
};

RecordedDevice loadRecordedDevice(const std::string& file) {
  const CaptureTelegrams all = extractTelegrams(readCapture(kRecordings + file));
  RecordedDevice dev;
  for (size_t i = 0; i < all.telegrams.size(); ++i) {
    const auto& t = all.telegrams[i];
    if (t.direction == CaptureDirection::kFromDevice) {
      if (isScanDataTelegram(t.payload) && t.payload[1] == 'S') dev.scans.push_back(t.payload);
      continue;
    }
    const ColaTelegram req = splitColaTelegram(t.payload);
    const std::string key = req.type + " " + req.name;
    dev.request_args[key] = req.arguments;
    const std::string want = colaReplyType(req.type);
    for (size_t j = i + 1; j < all.telegrams.size(); ++j) {
      const auto& r = all.telegrams[j];
      if (r.direction != CaptureDirection::kFromDevice) continue;
      const ColaTelegram rep = splitColaTelegram(r.payload);
      if (rep.type == "sFA" || (rep.type == want && rep.name == req.name)) {
        if (!dev.replies.count(key)) dev.replies[key] = r.payload;
        break;
      }
    }
  }
  return dev;
}

// A device answering like the recorded LMS511 (binary) or, generically, in either dialect.
// `after_start` runs once streaming was enabled; when it returns true the script goes on answering (the stop
// sequence), when false it hangs up at once.
void answerStartup(PeerConnection& c, const RecordedDevice* recorded,
                   const std::function<bool(PeerConnection&)>& after_start, bool stray_reply = false,
                   const std::string& before_stream_reply = {}) {
  const ColaDialect d = c.dialect();
  std::string output_range_args;
  while (auto p = c.nextRequest()) {
    const ColaTelegram t = splitColaTelegram(*p);
    const std::string key = t.type + " " + t.name;
    if (t.type == "sMN" && t.name == "mLMPsetscancfg") {
      // Not in the recordings (SICK's driver did not send it there): status 0, then the configuration.
      ColaWriter w(d);
      w.u8(0);
      c.send(colaPayload("sAN", t.name, w.bytes() + (d == ColaDialect::kAscii ? " " : "") + t.arguments));
      continue;
    }
    if (t.type == "sEN" && t.name == "LMDscandata") {
      if (!before_stream_reply.empty()) c.send(before_stream_reply);
      c.send(colaPayload("sEA", t.name, t.arguments));
      ColaReader r(d, t.arguments, "test");
      if (r.u8("on") == 1 && !after_start(c)) return;
      continue;
    }
    if (t.type == "sMN" && t.name == "LMCstopmeas") {
      ColaWriter w(d);
      w.u8(0);
      c.send(colaPayload("sAN", t.name, w.bytes()));
      continue;
    }
    if (stray_reply && key == "sWN LMDscandatacfg") {
      // The recorded LMS111 repeated an earlier reply here; the client must skip it.
      c.send("sRA LIDinputstate " + bytes({0, 1, 0, 0, 0, 0, 2, 2, 2, 2, 0, 0}));
    }
    if (recorded != nullptr && recorded->replies.count(key)) {
      c.send(recorded->replies.at(key));
      continue;
    }
    ColaWriter w(d);
    if (key == "sMN SetAccessMode") c.send(colaPayload("sAN", t.name, w.u8(1).bytes()));
    else if (key == "sRN FirmwareVersion") c.send(colaPayload("sRA", t.name, w.string("V1.80").bytes()));
    else if (key == "sRN SCdevicestate") c.send(colaPayload("sRA", t.name, w.u8(1).bytes()));
    else if (key == "sWN LMDscandatacfg") c.send("sWA LMDscandatacfg ");
    else if (key == "sWN LMPoutputRange") {
      output_range_args = t.arguments;
      c.send("sWA LMPoutputRange ");
    } else if (key == "sRN LMPoutputRange") c.send(colaPayload("sRA", t.name, output_range_args));
    else if (key == "sMN LMCstartmeas") c.send(colaPayload("sAN", t.name, w.u8(0).bytes()));
    else if (key == "sMN Run") c.send(colaPayload("sAN", t.name, w.u8(1).bytes()));
    else c.send("sFA" + (d == ColaDialect::kBinary ? bytes({0, 3}) : std::string(" 3")));
  }
}

ScanData syntheticScan(uint16_t counter) {
  ScanData s;
  s.serial_number = 18110550;
  s.telegram_counter = counter;
  s.scan_counter = counter;
  s.scan_frequency = 2500;
  s.measurement_frequency = 360;
  ScanChannel dist{"DIST1", 1.0f, 0.0f, -50000, 1667, std::vector<uint16_t>(1141, 2000)};
  s.channels16 = {dist};
  return s;
}

ScannerClientParams paramsFor(uint16_t port, ColaDialect d = ColaDialect::kBinary) {
  ScannerClientParams p;
  p.port = port;
  p.dialect = d;
  p.reply_timeout_s = 5;
  p.scan_timeout_s = 5;
  return p;
}

std::string tempPath(const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / ("sailshape_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove(path);
  return path.string();
}

// What a recorded device is expected to tell the client.
struct RecordedCase {
  const char* file;
  ScannerClientParams params;  // port and capture path are filled in by the test
  const char* firmware;
  uint16_t first_scan_counter;      // README fact
  uint32_t resolution;              // LMPoutputRange as the device reads it back
  int32_t start, stop;
  bool same_output_range_request;   // our sWN LMPoutputRange equals the driver's byte for byte
};

void runRecordedStartup(const RecordedCase& rc) {
  const RecordedDevice dev = loadRecordedDevice(rc.file);
  ASSERT_GE(dev.scans.size(), 5u);
  ScriptedPeer peer(ColaDialect::kBinary, [&](PeerConnection& c, int) {
    answerStartup(
        c, &dev,
        [&](PeerConnection& conn) {
          for (size_t i = 0; i < 5; ++i) {
            conn.send("sSN LIDoutputstate " + bytes({0, 0, 0, 1}));
            conn.send(dev.scans[i]);
          }
          return true;
        },
        true);
  });
  const std::string capture = tempPath("startup.sscap");
  ScannerClientParams p = rc.params;
  p.port = peer.port();
  p.capture_path = capture;
  {
    ScannerClient client(p);
    const ScannerStartup s = client.start();
    EXPECT_EQ(s.firmware_version, rc.firmware);  // as the device sends it, padded
    EXPECT_EQ(s.device_state, 0);                 // both recorded devices said "busy" while starting
    EXPECT_EQ(s.output_resolution, rc.resolution);
    EXPECT_EQ(s.output_start, rc.start);
    EXPECT_EQ(s.output_stop, rc.stop);
    // A read-back that differs from what was written is reported, not hidden.
    EXPECT_EQ(s.warnings.empty(), rc.same_output_range_request);
    const ScanBatch b = client.receiveScans(5, 20.0);
    ASSERT_EQ(b.scans.size(), 5u);
    EXPECT_FALSE(b.connection_lost);
    EXPECT_FALSE(b.timed_out);
    for (size_t i = 0; i < 5; ++i)
      EXPECT_EQ(b.scans[i].scan_counter, decodeScanData(dev.scans[i], ColaDialect::kBinary).scan_counter);
    EXPECT_EQ(b.scans[0].scan_counter, rc.first_scan_counter);
    EXPECT_EQ(client.stats().other_events, 5u);  // LIDoutputstate events ignored
    EXPECT_EQ(client.stats().bad_checksum, 0u);
    EXPECT_EQ(client.stats().stray_replies, 1u);
    client.stop();
    EXPECT_FALSE(client.connected());
  }
  const auto requests = peer.requests();
  ASSERT_EQ(requests.size(), 1u);
  std::vector<std::string> names;
  for (const auto& r : requests[0]) {
    const ColaTelegram t = splitColaTelegram(r);
    names.push_back(t.type + " " + t.name);
  }
  const std::vector<std::string> expected = {
      "sMN SetAccessMode", "sRN FirmwareVersion", "sRN SCdevicestate", "sMN mLMPsetscancfg",
      "sWN LMDscandatacfg", "sWN LMPoutputRange", "sRN LMPoutputRange", "sMN LMCstartmeas",
      "sMN Run", "sEN LMDscandata", "sEN LMDscandata", "sMN LMCstopmeas"};
  ASSERT_EQ(names, expected);
  // Login and data configuration are byte for byte what SICK's driver sent the device.
  EXPECT_EQ(splitColaTelegram(requests[0][0]).arguments, dev.request_args.at("sMN SetAccessMode"));
  EXPECT_EQ(splitColaTelegram(requests[0][4]).arguments, dev.request_args.at("sWN LMDscandatacfg"));
  EXPECT_EQ(splitColaTelegram(requests[0][5]).arguments == dev.request_args.at("sWN LMPoutputRange"),
            rc.same_output_range_request);
  // Every request the client sends is one the recorded device answered with the type the client checks
  // (mLMPsetscancfg and LMCstopmeas are not in the recordings).
  for (const std::string& name : names) {
    if (name == "sMN mLMPsetscancfg" || name == "sMN LMCstopmeas") continue;
    ASSERT_TRUE(dev.replies.count(name)) << name;
    const ColaTelegram reply = splitColaTelegram(dev.replies.at(name));
    EXPECT_EQ(reply.type, colaReplyType(name.substr(0, 3))) << name;
  }

  // The archive holds every byte both ways: the same five scans decode from it.
  const CaptureTelegrams archived = extractTelegrams(readCapture(capture));
  size_t scans = 0;
  for (const auto& t : archived.telegrams) scans += isScanDataTelegram(t.payload) ? 1 : 0;
  EXPECT_EQ(scans, 5u);
  std::filesystem::remove(capture);
}

TEST(ScannerClient, StartupSequenceAgainstRecordedLms511Replies) {
  ScannerClientParams p = paramsFor(0);
  p.time_block = true;  // as SICK's driver configured it
  runRecordedStartup({"20210302_lms511.pcapng.json", p, "V1.80    ", 54484, 1667, -50000, 1850000, true});
}

TEST(ScannerClient, StartupSequenceAgainstRecordedLms111Replies) {
  ScannerClientParams p = paramsFor(0);
  p.scan_frequency = 5000;
  p.angular_resolution = 5000;
  p.start_angle = -450000;
  p.stop_angle = 2250000;
  p.rssi = false;  // the recorded LMS111 sent DIST1 only
  p.time_block = true;
  // SICK's driver wrote -449997..2249997 and the device reads that back: ours differs, so a warning.
  runRecordedStartup({"20210302_lms111.pcapng.json", p, "V1.80.2  ", 4, 5000, -449997, 2249997, false});
}

TEST(ScannerClient, AsciiDialectStartupStreamAndPoll) {
  ScriptedPeer peer(ColaDialect::kAscii, [](PeerConnection& c, int) {
    answerStartup(c, nullptr, [](PeerConnection& conn) {
      for (uint16_t i = 1; i <= 3; ++i) conn.send(encodeScanData(syntheticScan(i), ColaDialect::kAscii));
      // A polled scan: answered with sRA on the next request.
      auto req = conn.nextRequest();
      if (!req) {
        ADD_FAILURE() << "no sRN LMDscandata";
        return false;
      }
      EXPECT_EQ(*req, "sRN LMDscandata");
      ScanData polled = syntheticScan(99);
      polled.command_type = "sRA";
      conn.send(encodeScanData(polled, ColaDialect::kAscii));
      return true;
    });
  });
  ScannerClient client(paramsFor(peer.port(), ColaDialect::kAscii));
  const ScannerStartup s = client.start();
  EXPECT_EQ(s.firmware_version, "V1.80");
  EXPECT_EQ(s.device_state, 1);
  const ScanBatch b = client.receiveScans(3, 20.0);
  ASSERT_EQ(b.scans.size(), 3u);
  EXPECT_EQ(b.scans[2].scan_counter, 3);
  ASSERT_EQ(b.scans[0].channels16.size(), 1u);
  EXPECT_EQ(b.scans[0].channels16[0].values.size(), 1141u);
  const ScanData polled = client.pollScan();
  EXPECT_EQ(polled.command_type, "sRA");
  EXPECT_EQ(polled.scan_counter, 99);
  client.stop();
}

TEST(ScannerClient, RefusedLoginIsAClearError) {
  ScriptedPeer peer(ColaDialect::kBinary, [](PeerConnection& c, int) {
    if (c.nextRequest()) c.send("sAN SetAccessMode " + bytes({0}));
    c.nextRequest(2.0);  // wait for the client to hang up
  });
  ScannerClient client(paramsFor(peer.port()));
  try {
    client.start();
    FAIL() << "no exception";
  } catch (const ScannerError& e) {
    EXPECT_NE(std::string(e.what()).find("refused the login"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(client.connected());
}

TEST(ScannerClient, ScannerThatNeverAnswersTimesOut) {
  ScriptedPeer peer(ColaDialect::kBinary, [](PeerConnection& c, int) {
    c.nextRequest();
    c.nextRequest(3.0);  // reads, never answers
  });
  ScannerClientParams p = paramsFor(peer.port());
  p.reply_timeout_s = 0.3;
  ScannerClient client(p);
  try {
    client.start();
    FAIL() << "no exception";
  } catch (const ScannerError& e) {
    EXPECT_NE(std::string(e.what()).find("did not answer 'sMN SetAccessMode'"), std::string::npos) << e.what();
  }
}

TEST(ScannerClient, ErrorReplyNamesTheCommand) {
  ScriptedPeer peer(ColaDialect::kBinary, [](PeerConnection& c, int) {
    answerStartup(c, nullptr, [](PeerConnection&) { return true; });
  });
  ScannerClient client(paramsFor(peer.port()));
  client.start();
  try {
    client.request("sRN", "NoSuchVariable");
    FAIL() << "no exception";
  } catch (const ScannerError& e) {
    EXPECT_NE(std::string(e.what()).find("refused 'sRN NoSuchVariable' with error sFA 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(client.request("sAN", "Run"), ScannerError);  // not a request type
  client.stop();
}

TEST(ScannerClient, ConnectionDroppedMidStreamKeepsWhatArrived) {
  const std::string capture = tempPath("dropped.sscap");
  ScriptedPeer peer(
      ColaDialect::kBinary,
      [](PeerConnection& c, int index) {
        answerStartup(c, nullptr, [index](PeerConnection& conn) {
          for (uint16_t i = 1; i <= 3; ++i) conn.send(encodeScanData(syntheticScan(i), ColaDialect::kBinary));
          if (index > 0) return true;
          const std::string fourth = frameCola(ColaDialect::kBinary, encodeScanData(syntheticScan(4), ColaDialect::kBinary));
          conn.sendRaw(fourth.substr(0, fourth.size() / 2));
          return false;  // hang up mid-frame
        });
      },
      2);
  ScannerClientParams p = paramsFor(peer.port());
  p.capture_path = capture;
  ScannerClient client(p);
  client.start();
  const ScanBatch b = client.receiveScans(10, 20.0);
  ASSERT_EQ(b.scans.size(), 3u);
  EXPECT_TRUE(b.connection_lost);
  EXPECT_FALSE(b.timed_out);
  EXPECT_NE(b.message.find("lost after 3 scans"), std::string::npos) << b.message;
  EXPECT_NE(b.message.find("incomplete frame"), std::string::npos) << b.message;
  EXPECT_FALSE(client.connected());
  EXPECT_THROW(client.nextScan(), ScannerError);

  // Reconnect on request: the start-up runs again and streaming resumes.
  client.reconnect();
  EXPECT_EQ(client.stats().reconnects, 1u);
  const ScanBatch again = client.receiveScans(3, 20.0);
  EXPECT_EQ(again.scans.size(), 3u);
  client.stop();
  // The archive kept the half frame too: nothing received is lost.
  const Capture archived = readCapture(capture);
  size_t from_device = 0;
  for (const auto& r : archived.records) from_device += r.direction == CaptureDirection::kFromDevice ? r.bytes.size() : 0;
  EXPECT_GT(from_device, 3 * 2282u);
  std::filesystem::remove(capture);
}

TEST(ScannerClient, GarbageAndBadChecksumInTheStreamAreDroppedAndCounted) {
  std::string bad = frameCola(ColaDialect::kBinary, encodeScanData(syntheticScan(2), ColaDialect::kBinary));
  bad.back() = static_cast<char>(bad.back() ^ 1);
  ScriptedPeer peer(ColaDialect::kBinary, [&bad](PeerConnection& c, int) {
    answerStartup(c, nullptr, [&bad](PeerConnection& conn) {
      const std::string one = frameCola(ColaDialect::kBinary, encodeScanData(syntheticScan(1), ColaDialect::kBinary));
      const std::string three = frameCola(ColaDialect::kBinary, encodeScanData(syntheticScan(3), ColaDialect::kBinary));
      // Split a frame across two sends, with garbage between frames.
      conn.sendRaw(one.substr(0, 100));
      conn.sendRaw(one.substr(100) + "garbage" + bad + three);
      return true;
    });
  });
  ScannerClient client(paramsFor(peer.port()));
  client.start();
  const ScanBatch b = client.receiveScans(2, 20.0);
  ASSERT_EQ(b.scans.size(), 2u);
  EXPECT_EQ(b.scans[0].scan_counter, 1);
  EXPECT_EQ(b.scans[1].scan_counter, 3);  // scan 2 had a bad checksum
  EXPECT_EQ(client.stats().bad_checksum, 1u);
  // The 7 garbage bytes, and the dropped frame after its first byte (skipped while resynchronising).
  EXPECT_EQ(client.stats().garbage_bytes, 7u + bad.size() - 1);
  client.stop();
}

TEST(ScannerClient, NoScanWithinTheTimeoutIsReported) {
  ScriptedPeer peer(ColaDialect::kBinary, [](PeerConnection& c, int) {
    // One scan only, sent before the reply that enables streaming: the client holds it before it waits.
    answerStartup(
        c, nullptr, [](PeerConnection&) { return true; }, false,
        encodeScanData(syntheticScan(1), ColaDialect::kBinary));
  });
  ScannerClientParams p = paramsFor(peer.port());
  p.scan_timeout_s = 0.3;
  ScannerClient client(p);
  client.start();
  const ScanBatch b = client.receiveScans(5, 30.0);
  EXPECT_EQ(b.scans.size(), 1u);
  EXPECT_TRUE(b.timed_out);
  EXPECT_FALSE(b.connection_lost);
  EXPECT_THROW(client.nextScan(), ScannerError);
  client.stop();
}

TEST(ScannerClient, RefusedConnectionAndBadParameters) {
  // A port nobody listens on: bind one, then close it.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const uint16_t port = ntohs(addr.sin_port);
  ::close(fd);
  ScannerClient client(paramsFor(port));
  try {
    client.start();
    FAIL() << "no exception";
  } catch (const ScannerError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot connect to 127.0.0.1:" + std::to_string(port)), std::string::npos)
        << e.what();
  }
  ScannerClientParams bad = paramsFor(port);
  bad.port = 0;
  EXPECT_THROW(ScannerClient{bad}, ScannerError);
  bad = paramsFor(port);
  bad.host = "";
  EXPECT_THROW(ScannerClient{bad}, ScannerError);
  bad = paramsFor(port);
  bad.reply_timeout_s = 0;
  EXPECT_THROW(ScannerClient{bad}, ScannerError);
  bad = paramsFor(port);
  bad.start_angle = bad.stop_angle;
  EXPECT_THROW(ScannerClient{bad}, ScannerError);
  bad = paramsFor(port);
  bad.angular_resolution = 0;
  EXPECT_THROW(ScannerClient{bad}, ScannerError);
  EXPECT_THROW(colaReplyType("sSN"), ScannerError);
}

}  // namespace
}  // namespace sailshape
