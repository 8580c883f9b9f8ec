#pragma once
// SICK CoLa telegrams as the LMS111/LMS511 send them over TCP.
//
// Framing (a "frame" carries one "payload" = one telegram):
//   CoLa B (binary): 02 02 02 02 | payload length, u32 big-endian | payload | XOR of every payload byte
//   CoLa A (ASCII):  02 | payload | 03
// A payload is "<type> <name> <arguments>": type sRN/sRA (read), sWN/sWA (write), sMN/sAN (method),
// sEN/sEA (event subscription), sSN (event, e.g. streamed scans), sFA (error reply: "sFA" + error code).
// Arguments are big-endian fields in CoLa B and space-separated tokens in CoLa A (numbers in hex,
// negative ones as 32-bit two's complement; "+123"/"-123" decimal is also read; floats as the hex of their
// IEEE-754 bits; strings as length then characters).
//
// Usage:
//   std::string wire = frameCola(ColaDialect::kBinary, "sRN FirmwareVersion");
//   ColaStreamDecoder decoder({ColaDialect::kBinary});
//   decoder.feed(bytes_from_socket);               // any split: partial frames wait for the rest
//   while (auto payload = decoder.next()) { ColaTelegram t = splitColaTelegram(*payload); ... }
//   ColaReader args(ColaDialect::kBinary, t.arguments, "SetAccessMode");  uint8_t ok = args.u8("status");
// No socket or system header here: the codec is pure and shared by the client, the emulator and replay.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sailshape {

// A telegram that does not follow the CoLa grammar (truncated field, bad token, unknown dialect, ...).
struct ColaError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class ColaDialect { kBinary, kAscii };

// "binary" / "ascii".
const char* colaDialectName(ColaDialect dialect);
// Accepts "binary", "b", "cola-b", "ascii", "a", "cola-a" (any case); throws ColaError otherwise.
ColaDialect parseColaDialect(std::string_view text);

constexpr uint8_t kColaStx = 0x02;
constexpr uint8_t kColaEtx = 0x03;
// Largest payload the stream decoder accepts. An LMS511 frame with 5 echoes of DIST and RSSI at 0.1667°
// is about 17 kB; a larger length field is taken as garbage, so garbage cannot stall the stream for long.
constexpr size_t kColaMaxPayloadBytes = 64 * 1024;

// XOR of every byte: the CoLa B checksum.
uint8_t colaChecksum(std::string_view payload);

// One frame on the wire around `payload`. Throws ColaError for an empty payload, a payload over
// kColaMaxPayloadBytes, or (CoLa A) a payload holding STX or ETX.
std::string frameCola(ColaDialect dialect, std::string_view payload);

struct ColaTelegram {
  std::string type;               // "sRN", "sRA", "sWN", "sWA", "sMN", "sAN", "sEN", "sEA", "sSN", "sFA"
  std::string name;               // "LMDscandata"; empty for sFA
  std::string arguments;          // bytes after "<name> " (binary fields or ASCII tokens)
  bool space_after_name = false;  // devices send "sWA EIHstCola " with a space but no argument
};

// Splits a payload (without framing). Throws ColaError when it has no type of three letters starting with 's'.
ColaTelegram splitColaTelegram(std::string_view payload);
// The payload of `telegram` (inverse of splitColaTelegram).
std::string joinColaTelegram(const ColaTelegram& telegram);
// Convenience: the payload "<type> <name>" + (" " + arguments if any).
std::string colaPayload(std::string_view type, std::string_view name, std::string_view arguments = {});

// Builds the arguments of a telegram field by field in either dialect.
class ColaWriter {
 public:
  explicit ColaWriter(ColaDialect dialect) : dialect_(dialect) {}
  ColaWriter& u8(uint8_t value);
  ColaWriter& u16(uint16_t value);
  ColaWriter& u32(uint32_t value);
  ColaWriter& i16(int16_t value);
  ColaWriter& i32(int32_t value);
  ColaWriter& f32(float value);
  // Characters of a fixed-size field ("DIST1", "FDIN"): no length prefix.
  ColaWriter& fixedString(std::string_view text);
  // u16 length then characters (binary); hex length, space, characters (ASCII).
  ColaWriter& string(std::string_view text);
  // CoLa A only: a token written as is (decimal "+2500" for commands that want it).
  ColaWriter& token(std::string_view text);
  const std::string& bytes() const { return out_; }
  ColaDialect dialect() const { return dialect_; }

 private:
  void separate();
  void hex(uint64_t value);
  ColaDialect dialect_;
  std::string out_;
};

// Reads telegram arguments field by field. Every read names its field so that a truncated or malformed
// telegram fails with "[<context>] <field>: ..." (ColaError). The reader keeps its own copy of the
// arguments, so it may outlive the telegram it was made from.
class ColaReader {
 public:
  ColaReader(ColaDialect dialect, std::string_view arguments, std::string context);
  uint8_t u8(const char* field);
  uint16_t u16(const char* field);
  uint32_t u32(const char* field);
  int16_t i16(const char* field);
  int32_t i32(const char* field);
  float f32(const char* field);
  std::string fixedString(size_t length, const char* field);
  std::string string(const char* field);
  bool atEnd() const;
  size_t position() const { return pos_; }
  // Throws ColaError when anything but spaces is left.
  void expectEnd() const;

 private:
  uint64_t unsignedValue(const char* field, int bytes);
  int64_t signedValue(const char* field, int bytes);
  std::string_view takeToken(const char* field);
  [[noreturn]] void fail(const char* field, const std::string& what) const;
  ColaDialect dialect_;
  std::string data_;
  size_t pos_ = 0;
  std::string context_;
};

struct ColaDecoderParams {
  ColaDialect dialect = ColaDialect::kBinary;
  size_t max_payload_bytes = kColaMaxPayloadBytes;
};

// What the stream decoder saw. Dropped frames are counted, never returned.
struct ColaStreamStats {
  uint64_t frames = 0;             // good frames returned by next()
  uint64_t bad_checksum = 0;       // CoLa B frames whose XOR did not match: dropped
  uint64_t bad_length = 0;         // CoLa B length 0, over max_payload_bytes, or running past the start of a
                                   // complete good frame: skipped up to the next start marker or that frame
  uint64_t unterminated = 0;       // CoLa A frames cut by a new STX or longer than the limit: dropped
  uint64_t garbage_bytes = 0;      // bytes skipped while looking for a start marker (incl. a dropped frame's)
};

// Turns a byte stream cut anywhere into payloads.
// Behaviour on faults (tested in tests/acquisition/cola_test.cpp):
// - garbage before or between frames is skipped up to the next start marker and counted;
// - a CoLa B frame with a bad checksum is dropped and counted, and the search restarts one byte after its
//   start marker, so a good frame that the bogus length had covered is still found;
// - a CoLa B frame whose length field announces more bytes than have come is not waited for once a
//   complete good frame (checksum matching, payload starting as a telegram) has come after its start: it
//   counts as a bad length and decoding resumes at that frame;
// - a frame split across feeds waits for the rest; nothing is returned twice or lost.
class ColaStreamDecoder {
 public:
  explicit ColaStreamDecoder(const ColaDecoderParams& params = {});
  void feed(std::string_view bytes);
  // The next complete good payload, or nothing until more bytes arrive.
  std::optional<std::string> next();
  const ColaStreamStats& stats() const { return stats_; }
  // Bytes held for an incomplete frame (or not yet examined).
  size_t bufferedBytes() const { return buffer_.size() - start_; }
  ColaDialect dialect() const { return params_.dialect; }

 private:
  std::optional<std::string> nextBinary();
  std::optional<std::string> nextAscii();
  void skip(size_t n, bool garbage);
  ColaDecoderParams params_;
  std::string buffer_;
  size_t start_ = 0;  // first unexamined byte in buffer_
  ColaStreamStats stats_;
};

}  // namespace sailshape
