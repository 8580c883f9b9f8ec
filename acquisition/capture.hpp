#pragma once
// Archives of the raw bytes exchanged with a scanner, with time stamps, so a session can be decoded again
// later (`sailshape replay`).
//
// Two formats are read:
// - ours (written by CaptureWriter, extension .sscap): an 8-byte magic "SSCAP001", one byte dialect
//   (0 binary, 1 ASCII), then records {u8 direction (0 to device, 1 from device), f64 time (IEEE-754 bits,
//   u64 big-endian; seconds since the Unix epoch), u32 big-endian length, bytes}. Records are appended and
//   flushed one by one; a file cut short by a crash reads back every complete record plus a warning.
// - pcapng-JSON (Wireshark's JSON export as in ../shared/sick-recordings): a JSON array whose elements hold
//   `_source.layers.tcp["tcp.payload"]` (colon-separated hex) and `Timestamps["tcp.time_relative"]`.
//   Those files carry no addresses; the direction is taken from the telegram type (sRN/sWN/sMN/sEN are
//   requests to the device), a segment not starting a frame keeps the direction of the one before.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "acquisition/cola.hpp"

namespace sailshape {

enum class CaptureDirection : uint8_t { kToDevice = 0, kFromDevice = 1 };

struct CaptureRecord {
  CaptureDirection direction = CaptureDirection::kFromDevice;
  double time_s = 0;  // seconds: since the Unix epoch (ours) or since the capture's start (pcapng-JSON)
  std::string bytes;  // as sent or received, framing included, cut wherever the socket cut it
};

struct Capture {
  ColaDialect dialect = ColaDialect::kBinary;
  std::string format;  // "sscap" or "pcapng-json"
  std::vector<CaptureRecord> records;
  std::vector<std::string> warnings;  // e.g. a truncated last record
};

// Reads either format (told apart by content). Throws FileError for a missing or unreadable file,
// an unknown format, or malformed JSON/hex.
Capture readCapture(const std::string& path);

// One decoded telegram of a capture.
struct CapturedTelegram {
  CaptureDirection direction = CaptureDirection::kFromDevice;
  double time_s = 0;    // time of the record that completed the frame
  std::string payload;  // framing removed
};

struct CaptureTelegrams {
  std::vector<CapturedTelegram> telegrams;
  ColaStreamStats to_device;    // decoder statistics per direction
  ColaStreamStats from_device;
};

// Runs each direction's bytes through its own stream decoder (frames may be split across records).
CaptureTelegrams extractTelegrams(const Capture& capture);

// Appends records to a capture file in our format; every record is flushed at once so a crash loses at most
// the record being written. Throws FileError when the file cannot be created or written.
class CaptureWriter {
 public:
  CaptureWriter(const std::string& path, ColaDialect dialect);
  ~CaptureWriter();
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;
  void append(const CaptureRecord& record);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

// Seconds since the Unix epoch, for CaptureRecord::time_s.
double captureClockSeconds();

}  // namespace sailshape
