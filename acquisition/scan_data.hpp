#pragma once
// One LMDscandata telegram (`sSN LMDscandata`, streamed; `sRA LMDscandata`, polled) of a SICK LMS111/LMS511,
// every field as the device sends it, in CoLa B (binary) and CoLa A (ASCII).
//
// API:
//   bool isScanDataTelegram(payload)              -> payload is "sSN LMDscandata ..." or "sRA LMDscandata ..."
//   ScanData decodeScanData(payload, dialect)     -> all fields; throws ColaError naming the bad field
//   std::string encodeScanData(scan, dialect)     -> the payload; wrap it with frameCola(dialect, payload)
//   scanRangeMm(channel, i), scanAngleRad(channel, i), scanAngleDeg(channel, i)
// Emulator use: fill a ScanData (command_type "sSN", one DIST1 channel with scale 1, offset 0, start angle and
// step in 1/10000°, values in mm; optionally RSSI1 as an 8-bit channel), then
//   socket_write(frameCola(dialect, encodeScanData(scan, dialect)));
// A decoded frame re-encodes to the same bytes (tested on the SICK recordings).
//
// Field order (SICK telegram listing; sick_scan_xd parses the same):
//   version u16, device number u16, serial u32, device status 2×u8, telegram counter u16, scan counter u16,
//   time since start-up u32 µs, time of transmission u32 µs, digital inputs 2×u8, digital outputs 2×u8,
//   layer angle u16 (reserved on LMS1xx/5xx), scan frequency u32 (1/100 Hz), measurement frequency u32 (100 Hz),
//   encoders u16 count × {position u32, speed u16},
//   16-bit channels u16 count × {name 5 chars, scale f32, offset f32, start angle i32 (1/10000°),
//   step u16 (1/10000°), count u16, values u16[count]}, 8-bit channels likewise with u8 values,
//   position u16 flag {x, y, z, rot x, rot y, rot z f32, rotation type u8, transmit device name u8},
//   device name u16 flag {string}, comment u16 flag {string},
//   time u16 flag {year u16, month, day, hour, minute, second u8, microseconds u32},
//   event info u16 flag {type 4 chars "FDIN", encoder position u32, time u32 µs, angle i32 (1/10000°)}.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/cola.hpp"

namespace sailshape {

struct ScanChannel {
  std::string name;            // "DIST1".."DIST5" (range), "RSSI1".."RSSI5" (intensity): 5 characters
  float scale_factor = 1.0f;   // value × scale_factor + scale_offset = millimetres (DIST channels)
  float scale_offset = 0.0f;
  int32_t start_angle = 0;     // 1/10000 degree, angle of values[0] in the scanner frame
  uint16_t angular_step = 0;   // 1/10000 degree between consecutive values
  std::vector<uint16_t> values;  // raw as sent; 8-bit channels hold 0..255
};

struct ScanEncoder {
  uint32_t position = 0;  // ticks
  uint16_t speed = 0;     // ticks/mm (device units)
};

struct ScanPosition {
  float x = 0, y = 0, z = 0;                 // device position
  float rot_x = 0, rot_y = 0, rot_z = 0;     // device rotation
  uint8_t rotation_type = 0;
  uint8_t transmit_device_name = 0;
};

struct ScanTime {
  uint16_t year = 0;
  uint8_t month = 0, day = 0, hour = 0, minute = 0, second = 0;
  uint32_t microsecond = 0;
};

struct ScanEventInfo {
  std::string type = "FDIN";  // 4 characters
  uint32_t encoder_position = 0;
  uint32_t time_us = 0;
  int32_t angle = 0;  // 1/10000 degree
};

struct ScanData {
  std::string command_type = "sSN";  // "sSN" streamed, "sRA" polled reply
  uint16_t version = 1;
  uint16_t device_number = 1;
  uint32_t serial_number = 0;
  std::array<uint8_t, 2> device_status{};   // {0, 0} = OK
  uint16_t telegram_counter = 0;
  uint16_t scan_counter = 0;
  uint32_t time_since_startup_us = 0;
  uint32_t time_of_transmission_us = 0;
  std::array<uint8_t, 2> digital_inputs{};
  std::array<uint8_t, 2> digital_outputs{};
  uint16_t layer_angle = 0;                 // reserved on LMS1xx/5xx
  uint32_t scan_frequency = 0;              // 1/100 Hz (2500 = 25 Hz)
  uint32_t measurement_frequency = 0;       // 100 Hz units: inverse of the time between two shots
  std::vector<ScanEncoder> encoders;
  std::vector<ScanChannel> channels16;      // DIST and (16-bit) RSSI channels
  std::vector<ScanChannel> channels8;       // 8-bit RSSI channels
  std::optional<ScanPosition> position;
  std::optional<std::string> device_name;
  std::optional<std::string> comment;
  std::optional<ScanTime> time;
  std::optional<ScanEventInfo> event_info;

  // The channel called `name` among 16-bit then 8-bit channels, or nullptr.
  const ScanChannel* channel(std::string_view name) const;
};

bool isScanDataTelegram(std::string_view payload);

// Decodes a whole payload (framing removed). Throws ColaError for another telegram, a truncated or malformed
// field (named in the message), a channel name of other than 5 characters, or bytes after the last block.
ScanData decodeScanData(std::string_view payload, ColaDialect dialect);

// The payload of `scan`. Throws ColaError when a channel name is not 5 characters or an event type not 4
// (in CoLa A also when they hold a space),
// a count exceeds 65535, or an 8-bit channel holds a value over 255.
std::string encodeScanData(const ScanData& scan, ColaDialect dialect);

// Millimetres of value i: value × scale_factor + scale_offset. Throws InvalidInput for i out of range.
double scanRangeMm(const ScanChannel& channel, size_t i);
// Scanner-frame angle α of value i.
double scanAngleDeg(const ScanChannel& channel, size_t i);
double scanAngleRad(const ScanChannel& channel, size_t i);

}  // namespace sailshape
