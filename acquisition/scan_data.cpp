#include "acquisition/scan_data.hpp"

#include <cmath>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {
namespace {

constexpr size_t kChannelNameChars = 5;
constexpr size_t kEventTypeChars = 4;

void readChannels(ColaReader& r, std::vector<ScanChannel>& channels, bool eight_bit) {
  const uint16_t count = r.u16(eight_bit ? "number of 8-bit channels" : "number of 16-bit channels");
  channels.resize(count);
  for (ScanChannel& c : channels) {
    c.name = r.fixedString(kChannelNameChars, "channel name");
    c.scale_factor = r.f32("scale factor");
    c.scale_offset = r.f32("scale offset");
    c.start_angle = r.i32("start angle");
    c.angular_step = r.u16("angular step");
    const uint16_t n = r.u16("number of values");
    c.values.resize(n);
    for (uint16_t& v : c.values) v = eight_bit ? r.u8("8-bit value") : r.u16("16-bit value");
  }
}

uint16_t checkedCount(size_t n, const char* what) {
  if (n > 0xffff)
    throw ColaError(std::string("[encodeScanData] ") + what + " " + std::to_string(n) + " exceeds 65535");
  return static_cast<uint16_t>(n);
}

// Fixed-size texts: any bytes in CoLa B; in CoLa A they are tokens, so no spaces.
void checkFixedText(const std::string& text, size_t chars, const char* what, ColaDialect dialect) {
  if (text.size() != chars || (dialect == ColaDialect::kAscii && text.find(' ') != std::string::npos))
    throw ColaError(std::string("[encodeScanData] ") + what + " must be " + std::to_string(chars) +
                    " characters (without spaces in CoLa A); got '" + text + "'");
}

void writeChannels(ColaWriter& w, const std::vector<ScanChannel>& channels, bool eight_bit) {
  w.u16(checkedCount(channels.size(), eight_bit ? "number of 8-bit channels" : "number of 16-bit channels"));
  for (const ScanChannel& c : channels) {
    checkFixedText(c.name, kChannelNameChars, "channel name", w.dialect());
    w.fixedString(c.name).f32(c.scale_factor).f32(c.scale_offset).i32(c.start_angle).u16(c.angular_step);
    w.u16(checkedCount(c.values.size(), "number of values"));
    for (uint16_t v : c.values) {
      if (eight_bit) {
        if (v > 0xff)
          throw ColaError("[encodeScanData] 8-bit channel " + c.name + " holds " + std::to_string(v) + " (> 255)");
        w.u8(static_cast<uint8_t>(v));
      } else {
        w.u16(v);
      }
    }
  }
}

bool readFlag(ColaReader& r, const char* field) {
  const uint16_t flag = r.u16(field);
  if (flag > 1) throw ColaError(std::string("[LMDscandata] ") + field + " must be 0 or 1 (got " + std::to_string(flag) + ")");
  return flag == 1;
}

}  // namespace

const ScanChannel* ScanData::channel(std::string_view name) const {
  for (const ScanChannel& c : channels16)
    if (c.name == name) return &c;
  for (const ScanChannel& c : channels8)
    if (c.name == name) return &c;
  return nullptr;
}

bool isScanDataTelegram(std::string_view payload) {
  return payload.substr(0, 16) == "sSN LMDscandata " || payload.substr(0, 16) == "sRA LMDscandata ";
}

ScanData decodeScanData(std::string_view payload, ColaDialect dialect) {
  if (!isScanDataTelegram(payload)) {
    std::string head(payload.substr(0, 24));
    for (char& c : head)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '.';
    throw ColaError("[decodeScanData] not an sSN/sRA LMDscandata telegram: '" + head + "'");
  }
  ScanData s;
  s.command_type = std::string(payload.substr(0, 3));
  ColaReader r(dialect, payload.substr(16), "LMDscandata");
  s.version = r.u16("version");
  s.device_number = r.u16("device number");
  s.serial_number = r.u32("serial number");
  s.device_status[0] = r.u8("device status");
  s.device_status[1] = r.u8("device status");
  s.telegram_counter = r.u16("telegram counter");
  s.scan_counter = r.u16("scan counter");
  s.time_since_startup_us = r.u32("time since start-up");
  s.time_of_transmission_us = r.u32("time of transmission");
  s.digital_inputs[0] = r.u8("digital inputs");
  s.digital_inputs[1] = r.u8("digital inputs");
  s.digital_outputs[0] = r.u8("digital outputs");
  s.digital_outputs[1] = r.u8("digital outputs");
  s.layer_angle = r.u16("layer angle");
  s.scan_frequency = r.u32("scan frequency");
  s.measurement_frequency = r.u32("measurement frequency");
  const uint16_t encoders = r.u16("number of encoders");
  s.encoders.resize(encoders);
  for (ScanEncoder& e : s.encoders) {
    e.position = r.u32("encoder position");
    e.speed = r.u16("encoder speed");
  }
  readChannels(r, s.channels16, false);
  readChannels(r, s.channels8, true);
  if (readFlag(r, "position flag")) {
    ScanPosition p;
    p.x = r.f32("position x");
    p.y = r.f32("position y");
    p.z = r.f32("position z");
    p.rot_x = r.f32("rotation x");
    p.rot_y = r.f32("rotation y");
    p.rot_z = r.f32("rotation z");
    p.rotation_type = r.u8("rotation type");
    p.transmit_device_name = r.u8("transmit device name");
    s.position = p;
  }
  if (readFlag(r, "device name flag")) s.device_name = r.string("device name");
  if (readFlag(r, "comment flag")) s.comment = r.string("comment");
  if (readFlag(r, "time flag")) {
    ScanTime t;
    t.year = r.u16("year");
    t.month = r.u8("month");
    t.day = r.u8("day");
    t.hour = r.u8("hour");
    t.minute = r.u8("minute");
    t.second = r.u8("second");
    t.microsecond = r.u32("microsecond");
    s.time = t;
  }
  if (readFlag(r, "event info flag")) {
    ScanEventInfo e;
    e.type = r.fixedString(kEventTypeChars, "event type");
    e.encoder_position = r.u32("event encoder position");
    e.time_us = r.u32("event time");
    e.angle = r.i32("event angle");
    s.event_info = e;
  }
  r.expectEnd();
  return s;
}

std::string encodeScanData(const ScanData& s, ColaDialect dialect) {
  if (s.command_type != "sSN" && s.command_type != "sRA")
    throw ColaError("[encodeScanData] command_type must be sSN or sRA (got '" + s.command_type + "')");
  ColaWriter w(dialect);
  w.u16(s.version).u16(s.device_number).u32(s.serial_number);
  w.u8(s.device_status[0]).u8(s.device_status[1]);
  w.u16(s.telegram_counter).u16(s.scan_counter);
  w.u32(s.time_since_startup_us).u32(s.time_of_transmission_us);
  w.u8(s.digital_inputs[0]).u8(s.digital_inputs[1]).u8(s.digital_outputs[0]).u8(s.digital_outputs[1]);
  w.u16(s.layer_angle).u32(s.scan_frequency).u32(s.measurement_frequency);
  w.u16(checkedCount(s.encoders.size(), "number of encoders"));
  for (const ScanEncoder& e : s.encoders) w.u32(e.position).u16(e.speed);
  writeChannels(w, s.channels16, false);
  writeChannels(w, s.channels8, true);
  w.u16(s.position ? 1 : 0);
  if (s.position) {
    const ScanPosition& p = *s.position;
    w.f32(p.x).f32(p.y).f32(p.z).f32(p.rot_x).f32(p.rot_y).f32(p.rot_z).u8(p.rotation_type).u8(p.transmit_device_name);
  }
  w.u16(s.device_name ? 1 : 0);
  if (s.device_name) w.string(*s.device_name);
  w.u16(s.comment ? 1 : 0);
  if (s.comment) w.string(*s.comment);
  w.u16(s.time ? 1 : 0);
  if (s.time) {
    const ScanTime& t = *s.time;
    w.u16(t.year).u8(t.month).u8(t.day).u8(t.hour).u8(t.minute).u8(t.second).u32(t.microsecond);
  }
  w.u16(s.event_info ? 1 : 0);
  if (s.event_info) {
    const ScanEventInfo& e = *s.event_info;
    checkFixedText(e.type, kEventTypeChars, "event type", dialect);
    w.fixedString(e.type).u32(e.encoder_position).u32(e.time_us).i32(e.angle);
  }
  return s.command_type + " LMDscandata " + w.bytes();
}

double scanRangeMm(const ScanChannel& c, size_t i) {
  if (i >= c.values.size())
    throw InvalidInput("[scanRangeMm] index " + std::to_string(i) + " out of range for channel " + c.name + " of " +
                       std::to_string(c.values.size()) + " values");
  return static_cast<double>(c.values[i]) * c.scale_factor + c.scale_offset;
}

double scanAngleDeg(const ScanChannel& c, size_t i) {
  if (i >= c.values.size())
    throw InvalidInput("[scanAngleDeg] index " + std::to_string(i) + " out of range for channel " + c.name + " of " +
                       std::to_string(c.values.size()) + " values");
  return (static_cast<double>(c.start_angle) + static_cast<double>(i) * c.angular_step) / 10000.0;
}

double scanAngleRad(const ScanChannel& c, size_t i) { return scanAngleDeg(c, i) * kRadPerDeg; }

}  // namespace sailshape
