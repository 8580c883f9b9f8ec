#pragma once
// A sweep (issue 4): home the turntable, move to the start angle, stream scans
// while the turntable rotates through the sweep angle at the set speed, stop.
// Every point keeps r, α, β, RSSI and time; its 3D position follows SPEC §2
// with the unit's p and θ, then the unit's pose. A connection lost mid-sweep
// keeps the scans received so far and flags the sweep as partial.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "acquisition/unit_config.hpp"
#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

// Every duration and speed must be > 0: runSweep throws InvalidInput otherwise.
struct SweepOptions {
  bool home = true;                  // seek the home sensor first
  double home_timeout_s = 60;
  double positioning_speed_deg_s = 45;  // to the start angle
  double reply_timeout_s = 5;        // scanner replies
  double scan_timeout_s = 2;         // longest gap between streamed scans
  // Longest wait, after the scanner's start-up, for its first streamed scan: a unit still starting (the
  // recorded ones answered "busy" then) streams nothing, and a sweep moved meanwhile would lose its start.
  double ready_timeout_s = 15;
  std::string capture_path;          // raw telegrams with time stamps (empty: none); must not exist
  // Called once the unit stands at its start angle with scans streaming, just before the sweep move;
  // returns the trigger's time (host seconds) to record, e.g. by waiting for a UDP trigger.
  std::function<double()> wait_for_start;
  // Called with each scan line's points as it arrives, to watch the cloud grow. A preview:
  // β is the scan's encoder reading or the turntable's latest reported angle, held for the
  // whole line (the sweep's cloud interpolates β per beam). Several units' sweeps call it
  // from their own threads at once.
  std::function<void(const std::vector<Vec3>& points)> on_scan;
};

// One sample; the sweep keeps every valid return.
struct SweepPoint {
  double range_m = 0;
  double alpha_rad = 0;  // scanner mirror angle
  double beta_rad = 0;   // turntable angle at the beam's firing time
  uint8_t rssi = 0;
  double time_s = 0;     // host steady clock
};

struct Sweep {
  std::string unit;
  std::vector<SweepPoint> points;
  Cloud cloud;                  // points by SPEC §2 with p, θ, then the pose; alpha/beta/intensity filled
  size_t scans = 0;             // LMDscandata frames used
  size_t beams = 0;             // beams in those frames (valid or not)
  size_t scans_missed = 0;      // scans the device counted between those frames but never delivered
  bool partial = false;         // the sweep ended early (connection lost, scanner timeout); points kept
  std::string message;          // why it ended early
  double trigger_time_s = 0;    // what wait_for_start returned (0 without one)
  double start_time_s = 0;      // host time the sweep move was commanded
  double end_time_s = 0;
  double beta_start_deg = 0, beta_end_deg = 0;  // turntable angles actually covered
  std::vector<std::string> warnings;
};

// Throws InvalidInput naming the first duration or speed that is not > 0.
void validateSweepOptions(const SweepOptions& options);

// Runs the sweep on the unit's scanner (TCP) and turntable (serial). Throws TurntableError or
// ScannerError when the set-up fails (no home, refused login, no scanner); faults after streaming
// started end the sweep early with `partial` set instead.
Sweep runSweep(const UnitConfig& unit, const SweepOptions& options = {}, const Progress& progress = {});

// The β (rad) of the scans lost between those received, from each received scan's
// counter and β at its middle beam (degrees), in the order received: the turntable
// turns evenly across a short gap, so the lost lines lie evenly between the scans
// around it. Ascending (Cloud::lost_beta_rad).
std::vector<double> lostLineBetas(const std::vector<std::pair<uint16_t, double>>& counter_beta_deg);

// The 3D point of one sample by SPEC §2 and the unit's pose.
Vec3 sweepPointPosition(const UnitConfig& unit, double range_m, double alpha_rad, double beta_rad);

}  // namespace sailshape
