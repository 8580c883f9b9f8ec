#include "acquisition/capture_replay.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "acquisition/sweep.hpp"
#include "acquisition/turntable_protocol.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

namespace {

std::string plural(uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// One line for every damaged frame and stray byte the stream decoders passed over while looking for the
// next frame start (both directions together), or "" when they passed over nothing.
std::string skippedWarning(const ColaStreamStats& to, const ColaStreamStats& from) {
  const uint64_t bad_length = to.bad_length + from.bad_length, bad_checksum = to.bad_checksum + from.bad_checksum;
  const uint64_t unterminated = to.unterminated + from.unterminated;
  const uint64_t frames = bad_length + bad_checksum + unterminated, bytes = to.garbage_bytes + from.garbage_bytes;
  if (frames == 0 && bytes == 0) return {};
  std::string why;
  const auto add = [&](uint64_t n, const char* one, const char* many) {
    if (n == 0) return;
    why += why.empty() ? "" : ", ";
    why += plural(n, one, many);
  };
  add(bad_length, "with a bad length field", "with a bad length field");
  add(bad_checksum, "with a bad checksum", "with a bad checksum");
  add(unterminated, "cut short", "cut short");
  return "skipped " + plural(frames, "damaged frame", "damaged frames") + (why.empty() ? "" : " (" + why + ")") +
         " and " + plural(bytes, "byte", "bytes") + " in all, resuming at the next frame start each time";
}

}  // namespace

ReplayResult replayCapture(const std::string& path, const Progress& progress) {
  progress("read capture", 0.0);
  const Capture capture = readCapture(path);
  progress("read capture", 1.0);
  const CaptureTelegrams telegrams = extractTelegrams(capture);
  ReplayResult out;
  out.format = capture.format;
  out.dialect = capture.dialect;
  out.warnings = capture.warnings;
  out.to_device = telegrams.to_device;
  out.from_device = telegrams.from_device;
  if (std::string skipped = skippedWarning(out.to_device, out.from_device); !skipped.empty())
    out.warnings.push_back(std::move(skipped));
  const size_t n = telegrams.telegrams.size();
  for (size_t i = 0; i < n; ++i) {
    const CapturedTelegram& t = telegrams.telegrams[i];
    if (isScanDataTelegram(t.payload)) {
      try {
        out.frames.push_back({t.time_s, decodeScanData(t.payload, capture.dialect)});
      } catch (const ColaError& e) {
        ++out.undecodable;
        if (out.undecodable <= 10) out.warnings.push_back(std::string("undecodable frame: ") + e.what());
      }
    } else {
      try {
        const ColaTelegram split = splitColaTelegram(t.payload);
        ++out.other_telegrams[split.name.empty() ? split.type : split.type + " " + split.name];
      } catch (const ColaError&) {
        ++out.other_telegrams["(not a telegram)"];
      }
    }
    if (i % 256 == 0) progress("decode", static_cast<double>(i) / static_cast<double>(n));
  }
  progress("decode", 1.0);
  return out;
}

namespace {

double encoderDeg(const ScanData& s) { return countsToDeg(static_cast<int32_t>(s.encoders.front().position)); }

}  // namespace

ReplayCloud replayToCloud(const ReplayResult& replay, const UnitConfig& unit) {
  validateUnit(unit);
  ReplayCloud out;
  size_t without_encoder = 0, without_dist = 0;
  std::vector<std::pair<uint16_t, double>> line_beta_deg;  // per frame used: counter, β at the middle beam
  const auto& frames = replay.frames;
  for (size_t k = 0; k < frames.size(); ++k) {
    const ScanData& s = frames[k].scan;
    const ScanChannel* dist = s.channel("DIST1");
    if (dist == nullptr || dist->values.empty()) {
      ++without_dist;
      continue;
    }
    if (s.encoders.empty()) {
      ++without_encoder;
      continue;
    }
    // β advances over one mirror turn towards the next frame's reading (or at the previous frame's rate).
    const double beta0 = encoderDeg(s);
    double rate_deg_per_turn = 0;
    const ScanData* next = k + 1 < frames.size() ? &frames[k + 1].scan : nullptr;
    const ScanData* prev = k > 0 ? &frames[k - 1].scan : nullptr;
    if (next && !next->encoders.empty() && next->scan_counter != s.scan_counter)
      rate_deg_per_turn = (encoderDeg(*next) - beta0) / static_cast<uint16_t>(next->scan_counter - s.scan_counter);
    else if (prev && !prev->encoders.empty() && prev->scan_counter != s.scan_counter)
      rate_deg_per_turn = (beta0 - encoderDeg(*prev)) / static_cast<uint16_t>(s.scan_counter - prev->scan_counter);
    const ScanChannel* rssi = s.channel("RSSI1");
    ++out.scans_used;
    out.beams += dist->values.size();
    const double alpha0_deg = scanAngleDeg(*dist, 0);
    const double mid_deg = 0.5 * (scanAngleDeg(*dist, dist->values.size() - 1) - alpha0_deg);
    line_beta_deg.emplace_back(s.scan_counter, beta0 + mid_deg / 360.0 * rate_deg_per_turn);
    for (size_t i = 0; i < dist->values.size(); ++i) {
      if (dist->values[i] == 0) continue;
      const double range_m = scanRangeMm(*dist, i) / 1000.0;
      const double alpha_deg = scanAngleDeg(*dist, i);
      const double beta_deg = beta0 + (alpha_deg - alpha0_deg) / 360.0 * rate_deg_per_turn;
      const double alpha = alpha_deg * kRadPerDeg, beta = beta_deg * kRadPerDeg;
      out.cloud.points.push_back(sweepPointPosition(unit, range_m, alpha, beta));
      out.cloud.alpha_rad.push_back(alpha);
      out.cloud.beta_rad.push_back(beta);
      out.cloud.intensity.push_back(rssi && i < rssi->values.size() ? static_cast<float>(rssi->values[i]) : 0.0f);
    }
  }
  if (out.scans_used == 0)
    throw InvalidInput("[replayToCloud] none of the " + std::to_string(frames.size()) +
                       " LMDscandata frames has both DIST1 and an encoder block, so the turntable angle β is "
                       "unknown (a scanner capture holds no turntable positions)");
  if (without_encoder > 0)
    out.warnings.push_back(std::to_string(without_encoder) + " frames without an encoder block skipped (β unknown)");
  if (without_dist > 0) out.warnings.push_back(std::to_string(without_dist) + " frames without DIST1 skipped");
  out.cloud.viewpoint = unit.pose.translation();
  out.cloud.lost_beta_rad = lostLineBetas(line_beta_deg);
  return out;
}

namespace {

nlohmann::json channelJson(const ScanChannel& c) {
  return {{"name", c.name},
          {"scale_factor", c.scale_factor},
          {"scale_offset", c.scale_offset},
          {"start_angle", c.start_angle},
          {"start_angle_deg", c.start_angle / 10000.0},
          {"angular_step", c.angular_step},
          {"angular_step_deg", c.angular_step / 10000.0},
          {"count", c.values.size()},
          {"values", c.values}};
}

}  // namespace

nlohmann::json scanDataJson(const ScanData& s) {
  nlohmann::json j;
  j["command_type"] = s.command_type;
  j["version"] = s.version;
  j["device_number"] = s.device_number;
  j["serial_number"] = s.serial_number;
  j["device_status"] = s.device_status;
  j["telegram_counter"] = s.telegram_counter;
  j["scan_counter"] = s.scan_counter;
  j["time_since_startup_us"] = s.time_since_startup_us;
  j["time_of_transmission_us"] = s.time_of_transmission_us;
  j["digital_inputs"] = s.digital_inputs;
  j["digital_outputs"] = s.digital_outputs;
  j["layer_angle"] = s.layer_angle;
  j["scan_frequency"] = s.scan_frequency;
  j["scan_frequency_hz"] = s.scan_frequency / 100.0;
  j["measurement_frequency"] = s.measurement_frequency;
  j["measurement_frequency_hz"] = s.measurement_frequency * 100.0;
  j["encoders"] = nlohmann::json::array();
  for (const ScanEncoder& e : s.encoders) j["encoders"].push_back({{"position", e.position}, {"speed", e.speed}});
  j["channels16"] = nlohmann::json::array();
  for (const ScanChannel& c : s.channels16) j["channels16"].push_back(channelJson(c));
  j["channels8"] = nlohmann::json::array();
  for (const ScanChannel& c : s.channels8) j["channels8"].push_back(channelJson(c));
  if (s.position) {
    const ScanPosition& p = *s.position;
    j["position"] = {{"x", p.x},           {"y", p.y},         {"z", p.z},
                     {"rot_x", p.rot_x},   {"rot_y", p.rot_y}, {"rot_z", p.rot_z},
                     {"rotation_type", p.rotation_type}, {"transmit_device_name", p.transmit_device_name}};
  }
  if (s.device_name) j["device_name"] = *s.device_name;
  if (s.comment) j["comment"] = *s.comment;
  if (s.time) {
    const ScanTime& t = *s.time;
    j["time"] = {{"year", t.year},     {"month", t.month},   {"day", t.day},
                 {"hour", t.hour},     {"minute", t.minute}, {"second", t.second},
                 {"microsecond", t.microsecond}};
  }
  if (s.event_info) {
    const ScanEventInfo& e = *s.event_info;
    j["event_info"] = {{"type", e.type}, {"encoder_position", e.encoder_position}, {"time_us", e.time_us}, {"angle", e.angle}};
  }
  return j;
}

nlohmann::json replayJson(const ReplayResult& r) {
  auto stats = [](const ColaStreamStats& s) {
    return nlohmann::json{{"frames", s.frames},
                          {"bad_checksum", s.bad_checksum},
                          {"bad_length", s.bad_length},
                          {"unterminated", s.unterminated},
                          {"garbage_bytes", s.garbage_bytes}};
  };
  nlohmann::json j;
  j["format"] = r.format;
  j["dialect"] = colaDialectName(r.dialect);
  j["scan_frames"] = r.frames.size();
  j["undecodable_scan_frames"] = r.undecodable;
  j["to_device"] = stats(r.to_device);
  j["from_device"] = stats(r.from_device);
  j["other_telegrams"] = r.other_telegrams;
  j["warnings"] = r.warnings;
  j["frames"] = nlohmann::json::array();
  for (const ReplayFrame& f : r.frames) {
    nlohmann::json fj = scanDataJson(f.scan);
    fj["time_s"] = f.time_s;
    j["frames"].push_back(std::move(fj));
  }
  return j;
}

}  // namespace sailshape
