#pragma once
// TCP client for a SICK LMS111/LMS511 speaking CoLa A or CoLa B (port 2112 by default).
//
//   ScannerClient client(params);
//   ScannerStartup s = client.start();            // connect + start-up sequence, each reply checked
//   ScanBatch b = client.receiveScans(100, 10.0); // streamed sSN LMDscandata
//   client.stop();                                // stop sequence
//
// Start-up sequence (what SICK's driver sends; the replies' types and arguments are those the recorded
// LMS111/LMS511 gave, see tests/acquisition/scanner_client_test.cpp):
//   sMN SetAccessMode 3 F4724744   -> sAN SetAccessMode 1            (0 = refused: ScannerError)
//   sRN FirmwareVersion            -> sRA FirmwareVersion <string>
//   sRN SCdevicestate              -> sRA SCdevicestate <u8>          (2 = error: ScannerError)
//   sMN mLMPsetscancfg f 1 res start stop -> sAN mLMPsetscancfg 0 ...  (only with set_scan_config; CoLa A
//                                  writes these as signed decimals, "+2500 +1 +1667 -50000 +1850000", as SICK documents)
//   sWN LMDscandatacfg ...         -> sWA LMDscandatacfg
//   sWN LMPoutputRange 1 res start stop -> sWA LMPoutputRange; sRN LMPoutputRange -> sRA (checked)
//   sMN LMCstartmeas               -> sAN LMCstartmeas 0
//   sMN Run                        -> sAN Run 1
//   sEN LMDscandata 1              -> sEA LMDscandata 1
// Stop: sEN LMDscandata 0 -> sEA LMDscandata 0; sMN LMCstopmeas -> sAN LMCstopmeas 0.
// Any "sFA <code>" reply, a wrong reply or a reply missing after reply_timeout_s is a ScannerError naming
// the command. Streamed telegrams arriving while a reply is awaited are kept for receiveScans().
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "acquisition/cola.hpp"
#include "acquisition/scan_data.hpp"

namespace sailshape {

// Connection, timeout or protocol failure talking to a scanner; the message names host:port and the command.
struct ScannerError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ScannerClientParams {
  std::string host = "127.0.0.1";
  uint16_t port = 2112;
  ColaDialect dialect = ColaDialect::kBinary;
  double connect_timeout_s = 5.0;
  double reply_timeout_s = 5.0;   // per command
  double scan_timeout_s = 2.0;    // longest wait for the next streamed scan
  // SetAccessMode: level 3 "authorised client" and its documented password hash.
  uint8_t access_level = 3;
  uint32_t password_hash = 0xF4724744u;
  // mLMPsetscancfg: scan frequency and angular resolution (the device may need a restart to apply them).
  bool set_scan_config = true;
  uint32_t scan_frequency = 2500;      // 1/100 Hz: 2500 = 25 Hz
  uint32_t angular_resolution = 1667;  // 1/10000 degree: 1667 = 0.1667°
  // LMPoutputRange: the sector sent, 1/10000 degree in the scanner frame.
  int32_t start_angle = -50000;
  int32_t stop_angle = 1850000;
  // LMDscandatacfg
  bool rssi = true;         // add an 8-bit RSSI1 channel
  bool time_block = false;  // add the device's clock to each scan
  // Raw bytes both ways with time stamps (CaptureWriter); empty = none. Must not exist yet.
  std::string capture_path;
};

struct ScannerStartup {
  std::string firmware_version;
  uint8_t device_state = 0;  // 0 busy, 1 ready, 2 error (the recorded devices answered 0 while starting)
  // Output range the device reports after it was written (1/10000 degree).
  uint32_t output_resolution = 0;
  int32_t output_start = 0;
  int32_t output_stop = 0;
  std::vector<std::string> warnings;
};

struct ScannerStats {
  uint64_t scans = 0;          // LMDscandata telegrams decoded
  uint64_t bad_checksum = 0;   // frames dropped by the stream decoder (all connections)
  uint64_t bad_length = 0;
  uint64_t garbage_bytes = 0;
  uint64_t undecodable = 0;    // good frames whose LMDscandata could not be decoded: dropped
  uint64_t other_events = 0;   // sSN telegrams other than LMDscandata (LIDoutputstate, ...): ignored
  uint64_t stray_replies = 0;  // replies to no pending request (the LMS111 repeats some): ignored
  uint64_t reconnects = 0;
};

struct ScanBatch {
  std::vector<ScanData> scans;
  std::vector<double> receive_times_s;  // host clock (seconds since the Unix epoch) per scan
  bool connection_lost = false;  // the device closed the connection or it broke: scans so far are kept
  bool timed_out = false;        // no scan within scan_timeout_s: scans so far are kept
  std::string message;           // why the batch ended early
};

class ScannerClient {
 public:
  explicit ScannerClient(ScannerClientParams params);
  ~ScannerClient();
  ScannerClient(const ScannerClient&) = delete;
  ScannerClient& operator=(const ScannerClient&) = delete;

  // Connects and runs the start-up sequence. Throws ScannerError (refused connection, refused login,
  // device error state, wrong or missing reply, timeout); the connection is closed then.
  ScannerStartup start();
  // Sends the stop sequence and closes. Throws ScannerError when a reply is wrong or missing.
  void stop();
  // Closes and runs start() again.
  ScannerStartup reconnect();
  void close();
  bool connected() const;

  // Up to max_scans streamed scans, within max_seconds overall. Ends early (flagged, scans kept) when the
  // connection drops or no scan arrives within scan_timeout_s.
  ScanBatch receiveScans(size_t max_scans, double max_seconds);
  // The next streamed scan. Throws ScannerError on timeout or a dropped connection.
  ScanData nextScan();
  // One scan on request (sRN LMDscandata -> sRA LMDscandata), whether or not streaming is on.
  ScanData pollScan();

  // Sends one request and returns its reply telegram (checked for sFA and for the expected reply type).
  ColaTelegram request(const std::string& type, const std::string& name, const std::string& arguments = {});

  const ScannerStats& stats() const;
  const ScannerClientParams& params() const { return params_; }

 private:
  ScannerStartup startupSequence();
  struct Impl;
  ScannerClientParams params_;
  std::unique_ptr<Impl> impl_;
};

// "sRN" -> "sRA", "sWN" -> "sWA", "sMN" -> "sAN", "sEN" -> "sEA". Throws ScannerError for other types.
std::string colaReplyType(const std::string& request_type);

}  // namespace sailshape
