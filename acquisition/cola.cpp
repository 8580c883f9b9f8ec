#include "acquisition/cola.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace sailshape {
namespace {

constexpr char kBinaryStx[4] = {0x02, 0x02, 0x02, 0x02};
constexpr size_t kBinaryHeader = 8;  // 4 × STX + u32 length

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string printable(std::string_view text) {
  std::string out;
  for (unsigned char c : text.substr(0, 40)) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static const char* digits = "0123456789ABCDEF";
      out += "\\x";
      out += digits[c >> 4];
      out += digits[c & 15];
    }
  }
  if (text.size() > 40) out += "...";
  return out;
}

// Offset of the first complete, well-formed CoLa B frame in `view` at or after `from`: start marker, a
// length of 1..max_payload, the bytes all there, the checksum matching and a payload that begins as a
// telegram does ('s' and two letters). npos when there is none (yet).
size_t completeFrameAt(std::string_view view, size_t from, size_t max_payload) {
  const std::string_view stx(kBinaryStx, 4);
  for (size_t at = view.find(stx, from); at != std::string_view::npos; at = view.find(stx, at + 1)) {
    if (view.size() - at < kBinaryHeader) return std::string_view::npos;
    uint32_t length = 0;
    for (size_t i = 4; i < 8; ++i) length = (length << 8) | static_cast<unsigned char>(view[at + i]);
    if (length < 3 || length > max_payload || view.size() - at < kBinaryHeader + length + 1) continue;
    const std::string_view payload = view.substr(at + kBinaryHeader, length);
    if (payload[0] != 's' || !std::isalpha(static_cast<unsigned char>(payload[1])) ||
        !std::isalpha(static_cast<unsigned char>(payload[2])))
      continue;
    if (colaChecksum(payload) == static_cast<unsigned char>(view[at + kBinaryHeader + length])) return at;
  }
  return std::string_view::npos;
}

}  // namespace

const char* colaDialectName(ColaDialect dialect) { return dialect == ColaDialect::kBinary ? "binary" : "ascii"; }

ColaDialect parseColaDialect(std::string_view text) {
  const std::string t = lower(text);
  if (t == "binary" || t == "b" || t == "cola-b" || t == "colab") return ColaDialect::kBinary;
  if (t == "ascii" || t == "a" || t == "cola-a" || t == "colaa") return ColaDialect::kAscii;
  throw ColaError("[parseColaDialect] unknown CoLa dialect '" + std::string(text) + "' (binary or ascii)");
}

uint8_t colaChecksum(std::string_view payload) {
  uint8_t sum = 0;
  for (unsigned char c : payload) sum ^= c;
  return sum;
}

std::string frameCola(ColaDialect dialect, std::string_view payload) {
  if (payload.empty()) throw ColaError("[frameCola] empty payload");
  if (payload.size() > kColaMaxPayloadBytes)
    throw ColaError("[frameCola] payload of " + std::to_string(payload.size()) + " bytes exceeds " +
                    std::to_string(kColaMaxPayloadBytes));
  std::string out;
  if (dialect == ColaDialect::kBinary) {
    out.reserve(payload.size() + 9);
    out.append(kBinaryStx, 4);
    const auto n = static_cast<uint32_t>(payload.size());
    for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((n >> shift) & 0xff);
    out.append(payload);
    out += static_cast<char>(colaChecksum(payload));
  } else {
    if (payload.find_first_of(std::string_view("\x02\x03", 2)) != std::string_view::npos)
      throw ColaError("[frameCola] CoLa A payload holds STX or ETX: '" + printable(payload) + "'");
    out.reserve(payload.size() + 2);
    out += static_cast<char>(kColaStx);
    out.append(payload);
    out += static_cast<char>(kColaEtx);
  }
  return out;
}

ColaTelegram splitColaTelegram(std::string_view payload) {
  if (payload.size() < 3 || payload[0] != 's' || !std::isalpha(static_cast<unsigned char>(payload[1])) ||
      !std::isalpha(static_cast<unsigned char>(payload[2])))
    throw ColaError("[splitColaTelegram] not a CoLa telegram: '" + printable(payload) + "'");
  ColaTelegram t;
  t.type = std::string(payload.substr(0, 3));
  if (t.type == "sFA") {
    if (payload.size() == 3) return t;
    // Error reply: binary "sFA" + u16 code, ASCII "sFA <code>".
    size_t from = payload[3] == ' ' ? 4 : 3;
    t.space_after_name = false;
    t.arguments = std::string(payload.substr(from));
    return t;
  }
  if (payload.size() == 3 || payload[3] != ' ')
    throw ColaError("[splitColaTelegram] no name after the type: '" + printable(payload) + "'");
  const size_t name_end = payload.find(' ', 4);
  if (name_end == std::string_view::npos) {
    t.name = std::string(payload.substr(4));
  } else {
    t.name = std::string(payload.substr(4, name_end - 4));
    t.space_after_name = true;
    t.arguments = std::string(payload.substr(name_end + 1));
  }
  if (t.name.empty()) throw ColaError("[splitColaTelegram] empty name: '" + printable(payload) + "'");
  return t;
}

std::string joinColaTelegram(const ColaTelegram& t) {
  std::string out = t.type;
  if (t.type == "sFA") {
    if (!t.arguments.empty() && t.space_after_name) out += ' ';
    return out + t.arguments;
  }
  out += ' ';
  out += t.name;
  if (t.space_after_name || !t.arguments.empty()) out += ' ';
  out += t.arguments;
  return out;
}

std::string colaPayload(std::string_view type, std::string_view name, std::string_view arguments) {
  std::string out(type);
  out += ' ';
  out += name;
  if (!arguments.empty()) {
    out += ' ';
    out += arguments;
  }
  return out;
}

// ---------------------------------------------------------------- ColaWriter

void ColaWriter::separate() {
  if (!out_.empty()) out_ += ' ';
}

void ColaWriter::hex(uint64_t value) {
  static const char* digits = "0123456789ABCDEF";
  char buf[17];
  int n = 0;
  do {
    buf[n++] = digits[value & 15];
    value >>= 4;
  } while (value != 0);
  separate();
  while (n > 0) out_ += buf[--n];
}

ColaWriter& ColaWriter::u8(uint8_t value) {
  if (dialect_ == ColaDialect::kBinary) out_ += static_cast<char>(value);
  else hex(value);
  return *this;
}

ColaWriter& ColaWriter::u16(uint16_t value) {
  if (dialect_ == ColaDialect::kBinary) {
    out_ += static_cast<char>(value >> 8);
    out_ += static_cast<char>(value & 0xff);
  } else {
    hex(value);
  }
  return *this;
}

ColaWriter& ColaWriter::u32(uint32_t value) {
  if (dialect_ == ColaDialect::kBinary) {
    for (int shift = 24; shift >= 0; shift -= 8) out_ += static_cast<char>((value >> shift) & 0xff);
  } else {
    hex(value);
  }
  return *this;
}

ColaWriter& ColaWriter::i16(int16_t value) { return u16(static_cast<uint16_t>(value)); }
ColaWriter& ColaWriter::i32(int32_t value) { return u32(static_cast<uint32_t>(value)); }

ColaWriter& ColaWriter::f32(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  if (dialect_ == ColaDialect::kBinary) return u32(bits);
  // Floats keep all eight hex digits, as the devices send them ("3F800000", "00000000").
  static const char* digits = "0123456789ABCDEF";
  separate();
  for (int shift = 28; shift >= 0; shift -= 4) out_ += digits[(bits >> shift) & 15];
  return *this;
}

ColaWriter& ColaWriter::fixedString(std::string_view text) {
  if (dialect_ == ColaDialect::kAscii) {
    if (text.empty() || text.find(' ') != std::string_view::npos)
      throw ColaError("[ColaWriter::fixedString] CoLa A token must be non-empty without spaces: '" +
                      std::string(text) + "'");
    separate();
  }
  out_.append(text);
  return *this;
}

ColaWriter& ColaWriter::string(std::string_view text) {
  if (text.size() > 0xffff)
    throw ColaError("[ColaWriter::string] string of " + std::to_string(text.size()) + " bytes exceeds 65535");
  u16(static_cast<uint16_t>(text.size()));
  if (dialect_ == ColaDialect::kAscii && !text.empty()) separate();
  out_.append(text);
  return *this;
}

ColaWriter& ColaWriter::token(std::string_view text) {
  if (dialect_ != ColaDialect::kAscii) throw ColaError("[ColaWriter::token] tokens exist only in CoLa A");
  return fixedString(text);
}

// ---------------------------------------------------------------- ColaReader

ColaReader::ColaReader(ColaDialect dialect, std::string_view arguments, std::string context)
    : dialect_(dialect), data_(arguments), context_(std::move(context)) {}

void ColaReader::fail(const char* field, const std::string& what) const {
  throw ColaError("[" + context_ + "] " + field + ": " + what + " (at byte " + std::to_string(pos_) + " of " +
                  std::to_string(data_.size()) + ")");
}

std::string_view ColaReader::takeToken(const char* field) {
  while (pos_ < data_.size() && data_[pos_] == ' ') ++pos_;
  if (pos_ >= data_.size()) fail(field, "telegram ends before this field");
  const size_t end = std::min(data_.find(' ', pos_), data_.size());
  std::string_view token = std::string_view(data_).substr(pos_, end - pos_);
  pos_ = end;
  return token;
}

uint64_t ColaReader::unsignedValue(const char* field, int bytes) {
  if (dialect_ == ColaDialect::kBinary) {
    if (data_.size() - pos_ < static_cast<size_t>(bytes))
      fail(field, "telegram ends before this " + std::to_string(bytes) + "-byte field");
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | static_cast<unsigned char>(data_[pos_ + i]);
    pos_ += bytes;
    return v;
  }
  const std::string_view token = takeToken(field);
  const uint64_t limit = bytes == 8 ? ~0ULL : (1ULL << (8 * bytes)) - 1;
  uint64_t v = 0;
  if (token[0] == '+' || token[0] == '-') {
    if (token.size() < 2) fail(field, "'" + std::string(token) + "' is not a number");
    for (char c : token.substr(1)) {
      if (!std::isdigit(static_cast<unsigned char>(c))) fail(field, "'" + std::string(token) + "' is not decimal");
      v = v * 10 + static_cast<uint64_t>(c - '0');
      if (v > (1ULL << 40)) fail(field, "'" + std::string(token) + "' is out of range");
    }
    if (token[0] == '-') {
      // Two's complement in the field's width, so signed reads get the negative value back.
      if (v > (1ULL << (8 * bytes - 1))) fail(field, "'" + std::string(token) + "' is out of range");
      v = (~v + 1) & limit;
    }
  } else {
    if (token.size() > static_cast<size_t>(2 * bytes))
      fail(field, "'" + std::string(token) + "' is longer than " + std::to_string(2 * bytes) + " hex digits");
    for (char c : token) {
      const int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                    : (c >= 'A' && c <= 'F')                  ? c - 'A' + 10
                    : (c >= 'a' && c <= 'f')                  ? c - 'a' + 10
                                                              : -1;
      if (d < 0) fail(field, "'" + std::string(token) + "' is not hexadecimal");
      v = (v << 4) | static_cast<uint64_t>(d);
    }
  }
  if (v > limit) fail(field, "'" + std::string(token) + "' does not fit in " + std::to_string(bytes) + " bytes");
  return v;
}

int64_t ColaReader::signedValue(const char* field, int bytes) {
  const uint64_t v = unsignedValue(field, bytes);
  const uint64_t sign = 1ULL << (8 * bytes - 1);
  return (v & sign) ? static_cast<int64_t>(v) - static_cast<int64_t>(sign << 1) : static_cast<int64_t>(v);
}

uint8_t ColaReader::u8(const char* field) { return static_cast<uint8_t>(unsignedValue(field, 1)); }
uint16_t ColaReader::u16(const char* field) { return static_cast<uint16_t>(unsignedValue(field, 2)); }
uint32_t ColaReader::u32(const char* field) { return static_cast<uint32_t>(unsignedValue(field, 4)); }
int16_t ColaReader::i16(const char* field) { return static_cast<int16_t>(signedValue(field, 2)); }
int32_t ColaReader::i32(const char* field) { return static_cast<int32_t>(signedValue(field, 4)); }

float ColaReader::f32(const char* field) {
  const auto bits = static_cast<uint32_t>(unsignedValue(field, 4));
  float value;
  std::memcpy(&value, &bits, 4);
  return value;
}

std::string ColaReader::fixedString(size_t length, const char* field) {
  if (dialect_ == ColaDialect::kAscii) {
    const std::string_view token = takeToken(field);
    if (token.size() != length)
      fail(field, "'" + printable(token) + "' is not " + std::to_string(length) + " characters");
    return std::string(token);
  }
  if (data_.size() - pos_ < length) fail(field, "telegram ends inside this " + std::to_string(length) + "-byte text");
  std::string out(data_.substr(pos_, length));
  pos_ += length;
  return out;
}

std::string ColaReader::string(const char* field) {
  const uint16_t length = u16(field);
  if (dialect_ == ColaDialect::kAscii) {
    if (length == 0) return {};
    if (pos_ >= data_.size() || data_[pos_] != ' ') fail(field, "no space between length and text");
    ++pos_;
  }
  if (data_.size() - pos_ < length)
    fail(field, "text of " + std::to_string(length) + " bytes runs past the telegram's end");
  std::string out(data_.substr(pos_, length));
  pos_ += length;
  return out;
}

bool ColaReader::atEnd() const {
  if (dialect_ == ColaDialect::kBinary) return pos_ >= data_.size();
  return data_.find_first_not_of(' ', pos_) == std::string_view::npos;
}

void ColaReader::expectEnd() const {
  if (!atEnd())
    throw ColaError("[" + context_ + "] " + std::to_string(data_.size() - pos_) +
                    " unexpected bytes after the last field: '" + printable(data_.substr(pos_)) + "'");
}

// ---------------------------------------------------------------- ColaStreamDecoder

ColaStreamDecoder::ColaStreamDecoder(const ColaDecoderParams& params) : params_(params) {
  if (params_.max_payload_bytes == 0 || params_.max_payload_bytes > 0x7fffffff)
    throw ColaError("[ColaStreamDecoder] max_payload_bytes must be in 1..2^31-1 (got " +
                    std::to_string(params_.max_payload_bytes) + ")");
}

void ColaStreamDecoder::feed(std::string_view bytes) {
  // Drop what was consumed before growing, so a long stream does not keep its history.
  if (start_ > 0 && (start_ >= buffer_.size() / 2 || start_ > 65536)) {
    buffer_.erase(0, start_);
    start_ = 0;
  }
  buffer_.append(bytes);
}

void ColaStreamDecoder::skip(size_t n, bool garbage) {
  start_ += n;
  if (garbage) stats_.garbage_bytes += n;
}

std::optional<std::string> ColaStreamDecoder::next() {
  return params_.dialect == ColaDialect::kBinary ? nextBinary() : nextAscii();
}

std::optional<std::string> ColaStreamDecoder::nextBinary() {
  const std::string_view stx(kBinaryStx, 4);
  for (;;) {
    std::string_view view(buffer_);
    view.remove_prefix(start_);
    const size_t found = view.find(stx);
    if (found == std::string_view::npos) {
      // Keep a tail that may be the beginning of a start marker split across reads.
      size_t keep = 0;
      while (keep < 3 && keep < view.size() && view[view.size() - 1 - keep] == 0x02) ++keep;
      skip(view.size() - keep, true);
      return std::nullopt;
    }
    skip(found, true);
    view.remove_prefix(found);
    if (view.size() < kBinaryHeader) return std::nullopt;
    uint32_t length = 0;
    for (int i = 4; i < 8; ++i) length = (length << 8) | static_cast<unsigned char>(view[i]);
    if (length == 0 || length > params_.max_payload_bytes) {
      ++stats_.bad_length;
      skip(1, true);
      continue;
    }
    if (view.size() < kBinaryHeader + length + 1) {
      // Not all here yet, or a damaged length field announces more than the frame holds. A complete good
      // frame starting inside the announced span settles it: this one is damaged. Skip to that frame's
      // start instead of waiting for bytes that would swallow it and every frame after it (to the end of
      // a capture, or for up to max_payload_bytes on a live stream).
      const size_t next_frame = completeFrameAt(view, 1, params_.max_payload_bytes);
      if (next_frame == std::string_view::npos) return std::nullopt;
      ++stats_.bad_length;
      skip(next_frame, true);
      continue;
    }
    const std::string_view payload = view.substr(kBinaryHeader, length);
    if (colaChecksum(payload) != static_cast<unsigned char>(view[kBinaryHeader + length])) {
      ++stats_.bad_checksum;
      skip(1, false);
      continue;
    }
    std::string out(payload);
    skip(kBinaryHeader + length + 1, false);
    ++stats_.frames;
    return out;
  }
}

std::optional<std::string> ColaStreamDecoder::nextAscii() {
  for (;;) {
    std::string_view view(buffer_);
    view.remove_prefix(start_);
    const size_t found = view.find(static_cast<char>(kColaStx));
    if (found == std::string_view::npos) {
      skip(view.size(), true);
      return std::nullopt;
    }
    skip(found, true);
    view.remove_prefix(found);
    const size_t end = view.find_first_of(std::string_view("\x02\x03", 2), 1);
    if (end == std::string_view::npos) {
      if (view.size() > params_.max_payload_bytes + 1) {
        ++stats_.unterminated;
        skip(1, true);
        continue;
      }
      return std::nullopt;
    }
    if (view[end] == kColaStx || end == 1 || end - 1 > params_.max_payload_bytes) {
      // A new frame began before this one ended (or it is empty / too long): drop the fragment.
      ++stats_.unterminated;
      skip(end == 1 ? 2 : end, true);
      continue;
    }
    std::string out(view.substr(1, end - 1));
    skip(end + 1, false);
    ++stats_.frames;
    return out;
  }
}

}  // namespace sailshape
