#include "acquisition/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <thread>

#include "acquisition/scan_data.hpp"
#include "acquisition/scanner_client.hpp"
#include "acquisition/turntable.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

namespace {

struct ReceivedScan {
  ScanData data;
  double host_time_s = 0;
};

struct TableSample {
  double host_time_s;
  double deg;
};

// β (degrees) at host time t from turntable samples, linear between neighbours, held outside.
double interpolateBeta(const std::vector<TableSample>& samples, double t) {
  if (t <= samples.front().host_time_s) return samples.front().deg;
  if (t >= samples.back().host_time_s) return samples.back().deg;
  const auto it = std::upper_bound(samples.begin(), samples.end(), t,
                                   [](double v, const TableSample& s) { return v < s.host_time_s; });
  const TableSample& b = *it;
  const TableSample& a = *(it - 1);
  const double f = (t - a.host_time_s) / (b.host_time_s - a.host_time_s);
  return a.deg + f * (b.deg - a.deg);
}

double encoderDeg(const ScanData& s) {
  return countsToDeg(static_cast<int32_t>(s.encoders.front().position));
}

// One scan line's points for watching the sweep: β from the scan's encoder reading when
// β comes from the encoder, else the turntable's latest reported angle, for every beam.
std::vector<Vec3> previewPoints(const UnitConfig& unit, const ScanData& s, double table_deg) {
  std::vector<Vec3> out;
  const ScanChannel* dist = s.channel("DIST1");
  if (!dist) return out;
  const bool encoder = unit.beta_source == BetaSource::Encoder && !s.encoders.empty();
  const double beta = (encoder ? encoderDeg(s) : table_deg) * kRadPerDeg;
  out.reserve(dist->values.size());
  for (size_t i = 0; i < dist->values.size(); ++i)
    if (dist->values[i] != 0) out.push_back(sweepPointPosition(unit, scanRangeMm(*dist, i) / 1000.0, scanAngleRad(*dist, i), beta));
  return out;
}

}  // namespace

std::vector<double> lostLineBetas(const std::vector<std::pair<uint16_t, double>>& counter_beta_deg) {
  std::vector<double> out;
  for (size_t k = 1; k < counter_beta_deg.size(); ++k) {
    const auto [c0, b0] = counter_beta_deg[k - 1];
    const auto [c1, b1] = counter_beta_deg[k];
    const uint16_t step = static_cast<uint16_t>(c1 - c0);  // the counter wraps at 65,536
    if (b1 == b0) continue;  // the turntable stood: the lost scans repeat a line received
    for (uint16_t j = 1; j < step; ++j) out.push_back((b0 + (b1 - b0) * j / step) * kRadPerDeg);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Vec3 sweepPointPosition(const UnitConfig& unit, double r, double alpha, double beta) {
  return unit.pose * unitPoint(r, alpha, beta, unit.p_m, unit.theta_rad);
}

namespace {

// A duration as typed: 15, 1.5, 1.25 (not 15.000000).
std::string shortNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

void validateSweepOptions(const SweepOptions& o) {
  auto need = [](double v, const char* what) {
    if (!(v > 0 && std::isfinite(v)))
      throw InvalidInput(std::string("[runSweep] ") + what + " must be > 0 (got " + formatFixed(v, 3) + ")");
  };
  need(o.home_timeout_s, "home_timeout_s");
  need(o.positioning_speed_deg_s, "positioning_speed_deg_s");
  need(o.reply_timeout_s, "reply_timeout_s");
  need(o.scan_timeout_s, "scan_timeout_s");
  need(o.ready_timeout_s, "ready_timeout_s");
}

namespace {

// Homes the turntable (when asked) and moves it to the sweep's start angle at the positioning speed.
void moveToStart(TurntableClient& table, const UnitConfig& unit, const SweepOptions& options, const Progress& progress) {
  table.setAcceleration(unit.acceleration_deg_s2);
  if (options.home) table.home(options.home_timeout_s, progress);
  table.setVelocity(options.positioning_speed_deg_s);
  table.moveAbsolute(unit.start_angle_deg);
  const double positioning_s = std::abs(unit.start_angle_deg) / options.positioning_speed_deg_s + 5.0;
  if (!table.waitIdle(positioning_s))
    throw TurntableError("[runSweep] " + unit.name + ": the turntable did not reach the start angle " +
                         std::to_string(unit.start_angle_deg) + "° within " + std::to_string(positioning_s) + " s");
}

// The unit file's scan settings in the device's units (1/100 Hz, 1/10000°).
ScannerClientParams scannerParams(const UnitConfig& unit, const SweepOptions& options) {
  ScannerClientParams sp;
  sp.host = unit.host;
  sp.port = unit.port;
  sp.dialect = unit.protocol == "cola-a" ? ColaDialect::kAscii : ColaDialect::kBinary;
  sp.reply_timeout_s = options.reply_timeout_s;
  sp.scan_timeout_s = options.scan_timeout_s;
  sp.scan_frequency = static_cast<uint32_t>(std::lround(unit.frequency_hz * 100));
  sp.angular_resolution = static_cast<uint32_t>(std::lround(unit.resolution_deg * 10000));
  sp.start_angle = static_cast<int32_t>(std::lround(unit.output_start_deg * 10000));
  sp.stop_angle = static_cast<int32_t>(std::lround(unit.output_stop_deg * 10000));
  sp.rssi = unit.rssi;
  sp.capture_path = options.capture_path;
  return sp;
}

// The scanner's start-up sequence, then the encoder block in every scan when β comes from the encoder.
ScannerStartup startScanner(ScannerClient& scanner, const UnitConfig& unit, ColaDialect dialect, Sweep& sweep) {
  const ScannerStartup startup = scanner.start();
  for (const std::string& w : startup.warnings) sweep.warnings.push_back(w);
  if (unit.beta_source == BetaSource::Encoder) {
    // The turntable's encoder is wired to the scanner: ask for the encoder block in every scan
    // (LMDscandatacfg: channel, remission, 8-bit, mm, encoder 1, no position/name/comment/time, every scan).
    ColaWriter w(dialect);
    w.u8(1).u8(0).u8(unit.rssi ? 1 : 0).u8(0).u8(0).u8(1).u8(0).u8(0).u8(0).u8(0).u8(0).u16(1);
    scanner.request("sWN", "LMDscandatacfg", w.bytes());
  }
  return startup;
}

// The move waits for the scans: a unit still spinning up streams nothing yet.
void waitForFirstScan(ScannerClient& scanner, const UnitConfig& unit, const SweepOptions& options,
                      const ScannerStartup& startup, const Progress& progress) {
  const double since = hostTimeSeconds(), deadline = since + options.ready_timeout_s;
  for (;;) {
    const double left = deadline - hostTimeSeconds();
    if (left <= 0)
      throw ScannerError("[runSweep] " + unit.name + ": the scanner streamed no scan within " +
                         shortNumber(options.ready_timeout_s) +
                         " s of its start-up (device state " + std::to_string(startup.device_state) +
                         (startup.device_state == 0 ? ", busy" : "") + ")");
    const ScanBatch first = scanner.receiveScans(1, left);
    if (!first.scans.empty()) break;
    if (first.connection_lost) throw ScannerError("[runSweep] " + unit.name + ": " + first.message);
    progress("scanner starting", std::clamp((hostTimeSeconds() - since) / options.ready_timeout_s, 0.0, 1.0));
  }
}

// What streamed while the turntable turned through the sweep.
struct Streamed {
  std::vector<ReceivedScan> scans;
  std::vector<TableSample> table_samples;  // host time and β (degrees), polled during the move
  // The scanner's clock on the host's, as the smallest receive − transmission gap over every scan received
  // (seconds): a scan that arrives late (a busy network, or a device draining its output) is still placed
  // at its own time.
  double clock_offset_s = std::numeric_limits<double>::infinity();
  // The turntable stopped answering: β is known up to its last reported angle only.
  bool table_lost = false;
};

// Commands the sweep move and keeps every scan until the turntable is idle, judged by each scan's own
// start; a turntable fault or lost link, a scanner error or a move overrunning its time end the sweep as
// partial.
// Stops the turntable (partial) and the scanner's stream either way.
Streamed streamSweep(TurntableClient& table, ScannerClient& scanner, const UnitConfig& unit,
                     const SweepOptions& options, Sweep& sweep, const Progress& progress) {
  Streamed out;
  std::vector<ReceivedScan>& scans = out.scans;
  std::vector<TableSample>& table_samples = out.table_samples;
  const double target = unit.start_angle_deg + unit.sweep_angle_deg;
  table.setVelocity(unit.speed_deg_s);
  table_samples.push_back({hostTimeSeconds(), table.sample().deg()});
  sweep.start_time_s = hostTimeSeconds();
  table.moveAbsolute(target);
  const double expected_s = std::abs(unit.sweep_angle_deg) / unit.speed_deg_s +
                            unit.speed_deg_s / unit.acceleration_deg_s2 + 2.0;
  double last_poll = 0;
  double idle_at = -1;
  for (;;) {
    const double now = hostTimeSeconds();
    if (now - last_poll > 0.015 || idle_at < 0) {
      TurntableStatus st;
      try {
        st = table.status();
      } catch (const TurntableError& e) {
        // The turntable's link is gone (a unit losing power): the scans so far are kept.
        sweep.partial = true;
        sweep.message = std::string("turntable lost: ") + e.what();
        out.table_lost = true;
        break;
      }
      const double t = hostTimeSeconds();
      table_samples.push_back({0.5 * (now + t), countsToDeg(st.counts)});
      last_poll = t;
      if (st.state == TurntableState::Error) {
        sweep.partial = true;
        sweep.message = "turntable fault " + turntableErrorWord(st.error);
        break;
      }
      if (st.state == TurntableState::Idle && idle_at < 0) idle_at = t;
      progress("sweep", std::clamp((countsToDeg(st.counts) - unit.start_angle_deg) / unit.sweep_angle_deg, 0.0, 1.0));
    }
    // One more scan after the table stopped so the last moving scan has a successor for β interpolation.
    if (idle_at > 0 && !scans.empty() &&
        scans.back().data.time_since_startup_us * 1e-6 + out.clock_offset_s > idle_at + 0.5 / unit.frequency_hz)
      break;
    if (now - sweep.start_time_s > expected_s + options.scan_timeout_s) {
      sweep.partial = true;
      sweep.message = "the turntable did not finish the sweep within " + std::to_string(expected_s) + " s";
      break;
    }
    try {
      ScanData s = scanner.nextScan();
      if (options.on_scan) options.on_scan(previewPoints(unit, s, table_samples.back().deg));
      scans.push_back({std::move(s), hostTimeSeconds()});
      out.clock_offset_s =
          std::min(out.clock_offset_s, scans.back().host_time_s - scans.back().data.time_of_transmission_us * 1e-6);
    } catch (const ScannerError& e) {
      sweep.partial = true;
      sweep.message = e.what();
      break;
    }
  }
  sweep.end_time_s = hostTimeSeconds();
  if (sweep.partial) {
    try {
      table.stop();
    } catch (const TurntableError& e) {
      sweep.warnings.push_back(std::string("the turntable may still be turning: stopping it failed: ") + e.what());
      out.table_lost = true;
    }
  }
  try {
    if (scanner.connected()) scanner.stop();
  } catch (const ScannerError& e) {
    // A scanner that hung up streams to no one: only a stop refused or unanswered on a
    // live connection leaves it streaming, and is worth a line.
    if (scanner.connected()) sweep.warnings.push_back(std::string("stop sequence: ") + e.what());
  }
  if (!out.table_lost) {
    try {
      table_samples.push_back({hostTimeSeconds(), table.sample().deg()});
    } catch (const TurntableError& e) {
      out.table_lost = true;  // the whole unit went down, its scanner first
      sweep.warnings.push_back(std::string("turntable lost: ") + e.what());
    }
  }
  return out;
}

// Scans the device counted but never delivered: gaps in the scan counter between received scans of the sweep.
size_t countMissedScans(const Streamed& streamed, double sweep_start_s) {
  const std::vector<ReceivedScan>& scans = streamed.scans;
  size_t missed = 0;
  for (size_t k = 1; k < scans.size(); ++k) {
    const uint16_t step = static_cast<uint16_t>(scans[k].data.scan_counter - scans[k - 1].data.scan_counter);
    if (step > 1 && scans[k].data.time_since_startup_us * 1e-6 + streamed.clock_offset_s >= sweep_start_s)
      missed += step - 1u;
  }
  return missed;
}

// β(u) = beta0 + rate·u + curve·u² (degrees), u in scan periods from a scan's first beam.
struct EncoderBeta {
  double beta0 = 0, rate = 0, curve = 0;
};

// The encoder is latched once per scan; between readings the turntable may accelerate, so β per beam
// follows the parabola through the previous, this and the next reading (a line at the ends).
// Scan k must carry an encoder block.
EncoderBeta encoderBeta(const std::vector<ReceivedScan>& scans, size_t k) {
  const ScanData& s = scans[k].data;
  EncoderBeta b;
  b.beta0 = encoderDeg(s);
  const auto usable = [&](size_t j) { return j < scans.size() && !scans[j].data.encoders.empty(); };
  const double h_next = usable(k + 1) ? static_cast<uint16_t>(scans[k + 1].data.scan_counter - s.scan_counter) : 0;
  const double h_prev = k > 0 && usable(k - 1) ? static_cast<uint16_t>(s.scan_counter - scans[k - 1].data.scan_counter) : 0;
  const double d_next = h_next > 0 ? encoderDeg(scans[k + 1].data) - b.beta0 : 0;
  const double d_prev = h_prev > 0 ? b.beta0 - encoderDeg(scans[k - 1].data) : 0;
  if (h_next > 0 && h_prev > 0) {
    const double s_next = d_next / h_next, s_prev = d_prev / h_prev;
    b.curve = (s_next - s_prev) / (h_next + h_prev);
    b.rate = s_next - b.curve * h_next;
  } else if (h_next > 0) {
    b.rate = d_next / h_next;
  } else if (h_prev > 0) {
    b.rate = d_prev / h_prev;
  }
  return b;
}

// Every echo of the scans taken during the move, with β per beam; returns each used scan's counter and
// β at its middle beam (degrees), where the lost lines lay. Scans taken before the move was commanded
// stand at the start angle: not part of the sweep. Timestamp mode maps the scanner's clock to the host's
// by the smallest receive − transmission gap.
std::vector<std::pair<uint16_t, double>> assemblePoints(const Streamed& streamed, const UnitConfig& unit,
                                                        Sweep& sweep) {
  const std::vector<ReceivedScan>& scans = streamed.scans;
  const double clock_offset = streamed.clock_offset_s;
  const bool encoder = unit.beta_source == BetaSource::Encoder;
  size_t used = 0;
  std::vector<std::pair<uint16_t, double>> line_beta_deg;
  for (size_t k = 0; k < scans.size(); ++k) {
    const ScanData& s = scans[k].data;
    const ScanChannel* dist = s.channel("DIST1");
    if (!dist || dist->values.empty()) {
      sweep.warnings.push_back("scan " + std::to_string(s.scan_counter) + " has no DIST1 channel: skipped");
      continue;
    }
    const ScanChannel* rssi = s.channel("RSSI1");
    const double period_s = s.scan_frequency > 0 ? 100.0 / s.scan_frequency : 1.0 / unit.frequency_hz;
    const double scan_host_start = s.time_since_startup_us * 1e-6 + clock_offset;
    if (scan_host_start < sweep.start_time_s - period_s) continue;
    // Past the lost turntable's last reported angle, β would be a guess.
    if (streamed.table_lost && !encoder && scan_host_start + period_s > streamed.table_samples.back().host_time_s)
      continue;
    EncoderBeta eb;
    if (encoder) {
      if (s.encoders.empty()) {
        // Scans streamed before the encoder block was switched on are expected; later ones are not.
        if (used > 0)
          sweep.warnings.push_back("scan " + std::to_string(s.scan_counter) +
                                   " has no encoder block although beta_source is encoder: skipped");
        continue;
      }
      eb = encoderBeta(scans, k);
    }
    ++used;
    sweep.beams += dist->values.size();
    const double first_alpha_deg = scanAngleDeg(*dist, 0);
    // β (deg) at `frac` of a mirror turn from this scan's first beam.
    auto betaAt = [&](double frac) {
      return encoder ? eb.beta0 + frac * (eb.rate + frac * eb.curve)
                     : interpolateBeta(streamed.table_samples, scan_host_start + frac * period_s);
    };
    line_beta_deg.emplace_back(s.scan_counter,
                               betaAt(0.5 * (scanAngleDeg(*dist, dist->values.size() - 1) - first_alpha_deg) / 360.0));
    for (size_t i = 0; i < dist->values.size(); ++i) {
      if (dist->values[i] == 0) continue;  // no echo
      SweepPoint p;
      p.range_m = scanRangeMm(*dist, i) / 1000.0;
      p.alpha_rad = scanAngleRad(*dist, i);
      const double frac = (scanAngleDeg(*dist, i) - first_alpha_deg) / 360.0;
      p.time_s = scan_host_start + frac * period_s;
      p.beta_rad = betaAt(frac) * kRadPerDeg;
      if (rssi && i < rssi->values.size()) p.rssi = static_cast<uint8_t>(std::min<uint16_t>(rssi->values[i], 255));
      sweep.points.push_back(p);
    }
  }
  sweep.scans = used;
  return line_beta_deg;
}

// The sweep's cloud from its points (SPEC §2 and the unit's pose), with the lost lines' β.
void buildCloud(const UnitConfig& unit, const std::vector<std::pair<uint16_t, double>>& line_beta_deg, Sweep& sweep) {
  sweep.cloud.viewpoint = unit.pose.translation();
  sweep.cloud.scanner_range_m = scannerSpec(unit.model).max_range_m;
  sweep.cloud.lost_beta_rad = lostLineBetas(line_beta_deg);
  sweep.cloud.points.reserve(sweep.points.size());
  for (const SweepPoint& p : sweep.points) {
    sweep.cloud.points.push_back(sweepPointPosition(unit, p.range_m, p.alpha_rad, p.beta_rad));
    sweep.cloud.alpha_rad.push_back(p.alpha_rad);
    sweep.cloud.beta_rad.push_back(p.beta_rad);
    sweep.cloud.intensity.push_back(p.rssi);
  }
}

}  // namespace

Sweep runSweep(const UnitConfig& unit, const SweepOptions& options, const Progress& progress) {
  validateUnit(unit);
  validateSweepOptions(options);
  Sweep sweep;
  sweep.unit = unit.name;

  TurntableLinkParams link;
  link.device = unit.serial_device;
  link.baud = unit.baud;
  TurntableClient table(link);
  moveToStart(table, unit, options, progress);

  const ScannerClientParams sp = scannerParams(unit, options);
  ScannerClient scanner(sp);
  const ScannerStartup startup = startScanner(scanner, unit, sp.dialect, sweep);
  waitForFirstScan(scanner, unit, options, startup, progress);
  if (options.wait_for_start) sweep.trigger_time_s = options.wait_for_start();

  const Streamed streamed = streamSweep(table, scanner, unit, options, sweep, progress);
  sweep.scans_missed = countMissedScans(streamed, sweep.start_time_s);
  const std::vector<std::pair<uint16_t, double>> line_beta_deg = assemblePoints(streamed, unit, sweep);
  if (sweep.scans_missed > 0)
    sweep.warnings.push_back(std::to_string(sweep.scans_missed) + " of " +
                             std::to_string(sweep.scans + sweep.scans_missed) +
                             " scans of the sweep never arrived (gaps in the scan counter): the scan lines are "
                             "that much further apart there");
  if (!sweep.points.empty()) {
    sweep.beta_start_deg = sweep.points.front().beta_rad / kRadPerDeg;
    sweep.beta_end_deg = sweep.points.back().beta_rad / kRadPerDeg;
  }
  buildCloud(unit, line_beta_deg, sweep);
  if (!sweep.partial && sweep.scans == 0) {
    sweep.partial = true;
    sweep.message = "no scan arrived while the turntable moved";
  }
  progress("sweep", 1.0);
  return sweep;
}

}  // namespace sailshape
