#include "acquisition/capture.hpp"

#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

constexpr char kMagic[8] = {'S', 'S', 'C', 'A', 'P', '0', '0', '1'};
constexpr size_t kRecordHeader = 1 + 8 + 4;

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("[readCapture] cannot open '" + path + "'");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw FileError("[readCapture] cannot read '" + path + "'");
  return data;
}

uint64_t readBigEndian(const std::string& data, size_t pos, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | static_cast<unsigned char>(data[pos + i]);
  return v;
}

void appendBigEndian(std::string& out, uint64_t v, int bytes) {
  for (int shift = 8 * (bytes - 1); shift >= 0; shift -= 8) out += static_cast<char>((v >> shift) & 0xff);
}

Capture readOurs(const std::string& path, const std::string& data) {
  Capture c;
  c.format = "sscap";
  if (data.size() < 9) throw FileError("[readCapture] '" + path + "' ends inside its header");
  const auto dialect = static_cast<unsigned char>(data[8]);
  if (dialect > 1) throw FileError("[readCapture] '" + path + "' has unknown dialect byte " + std::to_string(dialect));
  c.dialect = dialect == 0 ? ColaDialect::kBinary : ColaDialect::kAscii;
  size_t pos = 9;
  while (pos < data.size()) {
    if (data.size() - pos < kRecordHeader) {
      c.warnings.push_back("truncated record header at byte " + std::to_string(pos) + " (file cut short?)");
      break;
    }
    const auto direction = static_cast<unsigned char>(data[pos]);
    if (direction > 1)
      throw FileError("[readCapture] '" + path + "' record at byte " + std::to_string(pos) +
                      " has unknown direction " + std::to_string(direction));
    const uint64_t bits = readBigEndian(data, pos + 1, 8);
    const auto length = static_cast<size_t>(readBigEndian(data, pos + 9, 4));
    if (data.size() - pos - kRecordHeader < length) {
      c.warnings.push_back("truncated record at byte " + std::to_string(pos) + ": " + std::to_string(length) +
                           " bytes announced, " + std::to_string(data.size() - pos - kRecordHeader) +
                           " present (file cut short?)");
      break;
    }
    CaptureRecord r;
    r.direction = direction == 0 ? CaptureDirection::kToDevice : CaptureDirection::kFromDevice;
    std::memcpy(&r.time_s, &bits, 8);
    r.bytes = data.substr(pos + kRecordHeader, length);
    c.records.push_back(std::move(r));
    pos += kRecordHeader + length;
  }
  return c;
}

int hexDigit(char ch) {
  if (ch >= '0' && ch <= '9') return ch - '0';
  if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
  if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
  return -1;
}

std::string parseColonHex(const std::string& text, const std::string& path, size_t element) {
  std::string out;
  out.reserve(text.size() / 3 + 1);
  size_t i = 0;
  while (i < text.size()) {
    if (i + 1 >= text.size() || hexDigit(text[i]) < 0 || hexDigit(text[i + 1]) < 0)
      throw FileError("[readCapture] '" + path + "' element " + std::to_string(element) +
                      ": tcp.payload is not colon-separated hex near character " + std::to_string(i));
    out += static_cast<char>(hexDigit(text[i]) * 16 + hexDigit(text[i + 1]));
    i += 2;
    if (i < text.size()) {
      if (text[i] != ':')
        throw FileError("[readCapture] '" + path + "' element " + std::to_string(element) +
                        ": expected ':' at character " + std::to_string(i) + " of tcp.payload");
      ++i;
    }
  }
  return out;
}

// Requests the driver sends; everything else comes from the device.
bool isRequestType(std::string_view type) {
  return type == "sRN" || type == "sWN" || type == "sMN" || type == "sEN";
}

// Telegram type of the first frame in a segment, or "" when the segment does not start with a frame.
std::string firstTelegramType(const std::string& bytes, ColaDialect& dialect) {
  if (bytes.size() >= 11 && bytes.compare(0, 4, "\x02\x02\x02\x02") == 0) {
    dialect = ColaDialect::kBinary;
    return bytes.substr(8, 3);
  }
  if (bytes.size() >= 4 && bytes[0] == '\x02' && bytes[1] == 's') {
    dialect = ColaDialect::kAscii;
    return bytes.substr(1, 3);
  }
  return {};
}

Capture readPcapJson(const std::string& path, const std::string& data) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(data);
  } catch (const nlohmann::json::exception& e) {
    throw FileError("[readCapture] '" + path + "' is not valid JSON: " + e.what());
  }
  if (!doc.is_array()) throw FileError("[readCapture] '" + path + "' is not a JSON array of packets");
  Capture c;
  c.format = "pcapng-json";
  bool dialect_known = false;
  CaptureDirection last = CaptureDirection::kToDevice;
  for (size_t i = 0; i < doc.size(); ++i) {
    const nlohmann::json* tcp = nullptr;
    const auto& e = doc[i];
    if (e.is_object() && e.contains("_source") && e["_source"].is_object() && e["_source"].contains("layers") &&
        e["_source"]["layers"].is_object() && e["_source"]["layers"].contains("tcp"))
      tcp = &e["_source"]["layers"]["tcp"];
    if (tcp == nullptr || !tcp->is_object())
      throw FileError("[readCapture] '" + path + "' element " + std::to_string(i) + " has no _source.layers.tcp");
    if (!tcp->contains("tcp.payload")) continue;  // a segment without data (ACK)
    const auto& payload = (*tcp)["tcp.payload"];
    if (!payload.is_string())
      throw FileError("[readCapture] '" + path + "' element " + std::to_string(i) + ": tcp.payload is not a string");
    CaptureRecord r;
    r.bytes = parseColonHex(payload.get<std::string>(), path, i);
    if (tcp->contains("Timestamps") && (*tcp)["Timestamps"].contains("tcp.time_relative")) {
      const auto& t = (*tcp)["Timestamps"]["tcp.time_relative"];
      try {
        r.time_s = t.is_string() ? std::stod(t.get<std::string>()) : t.get<double>();
      } catch (const std::exception&) {
        throw FileError("[readCapture] '" + path + "' element " + std::to_string(i) + ": bad tcp.time_relative");
      }
    }
    ColaDialect d = c.dialect;
    const std::string type = firstTelegramType(r.bytes, d);
    if (!type.empty()) {
      if (!dialect_known) {
        c.dialect = d;
        dialect_known = true;
      }
      last = isRequestType(type) ? CaptureDirection::kToDevice : CaptureDirection::kFromDevice;
    }
    r.direction = last;
    c.records.push_back(std::move(r));
  }
  return c;
}

}  // namespace

Capture readCapture(const std::string& path) {
  const std::string data = readWholeFile(path);
  if (data.size() >= 8 && std::memcmp(data.data(), kMagic, 8) == 0) return readOurs(path, data);
  const size_t first = data.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && data[first] == '[') return readPcapJson(path, data);
  throw FileError("[readCapture] '" + path + "' is neither a sailshape capture (SSCAP001) nor a pcapng-JSON array");
}

CaptureTelegrams extractTelegrams(const Capture& capture) {
  CaptureTelegrams out;
  ColaStreamDecoder to({capture.dialect});
  ColaStreamDecoder from({capture.dialect});
  for (const CaptureRecord& r : capture.records) {
    ColaStreamDecoder& d = r.direction == CaptureDirection::kToDevice ? to : from;
    d.feed(r.bytes);
    while (auto payload = d.next()) out.telegrams.push_back({r.direction, r.time_s, std::move(*payload)});
  }
  out.to_device = to.stats();
  out.from_device = from.stats();
  return out;
}

CaptureWriter::CaptureWriter(const std::string& path, ColaDialect dialect) : path_(path) {
  // "x": never overwrite an existing archive.
  file_ = std::fopen(path.c_str(), "wbx");
  if (file_ == nullptr) throw FileError("[CaptureWriter] cannot create '" + path + "' (exists or not writable)");
  std::string header(kMagic, 8);
  header += static_cast<char>(dialect == ColaDialect::kBinary ? 0 : 1);
  if (std::fwrite(header.data(), 1, header.size(), file_) != header.size() || std::fflush(file_) != 0) {
    std::fclose(file_);
    file_ = nullptr;
    throw FileError("[CaptureWriter] cannot write '" + path + "'");
  }
}

CaptureWriter::~CaptureWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void CaptureWriter::append(const CaptureRecord& record) {
  if (record.bytes.size() > 0xffffffffu)
    throw FileError("[CaptureWriter] record of " + std::to_string(record.bytes.size()) + " bytes is too large");
  std::string out;
  out.reserve(kRecordHeader + record.bytes.size());
  out += static_cast<char>(record.direction == CaptureDirection::kToDevice ? 0 : 1);
  uint64_t bits;
  std::memcpy(&bits, &record.time_s, 8);
  appendBigEndian(out, bits, 8);
  appendBigEndian(out, record.bytes.size(), 4);
  out += record.bytes;
  if (std::fwrite(out.data(), 1, out.size(), file_) != out.size() || std::fflush(file_) != 0)
    throw FileError("[CaptureWriter] cannot append to '" + path_ + "'");
}

double captureClockSeconds() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

}  // namespace sailshape
