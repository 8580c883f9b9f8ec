#pragma once
// The scanner panel's model: scanner units (from UNIT.json files, or emulated
// ones serving the real protocols on a pty and a TCP port), homing, one
// synchronised scan of every unit, and the trim-step data saved with it.
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/sweep.hpp"
#include "acquisition/unit_config.hpp"
#include "database/import.hpp"
#include "database/sqlite.hpp"

namespace sailshape {
struct Scene;
}

namespace sailshape::viewer {

// An emulated unit: the turntable drive on a pseudo-terminal and the SICK
// scanner on a loopback TCP port, ray-casting `scene` from the unit's pose.
class EmulatedUnit {
 public:
  // Throws std::runtime_error when no pty or port can be had.
  EmulatedUnit(const Scene& scene, const UnitConfig& unit);
  ~EmulatedUnit();
  EmulatedUnit(const EmulatedUnit&) = delete;
  EmulatedUnit& operator=(const EmulatedUnit&) = delete;
  // `unit` pointed at the emulator (host, port, serial device).
  const UnitConfig& unit() const { return unit_; }

 private:
  struct Hardware;
  std::unique_ptr<Hardware> hw_;
  UnitConfig unit_;
};

struct ScannerUnitSlot {
  UnitConfig config;                     // speed, acceleration, start and sweep angles edited here
  std::string origin;                    // the unit file, or "emulated (<scene>)"
  std::shared_ptr<EmulatedUnit> emulator;  // null for real hardware
};

// The trim-step data entered with a scan.
struct TrimStepForm {
  std::string campaign = "default", session = "default", boat, sail = "default", test;
  int step = 0;
  std::optional<double> awa_deg, aws_m_s, drive_n, side_n, heel_moment_nm;
  std::string controls;                  // "sheet=0.42; traveller=-0.1"
};

// "name=value" items separated by ';' or ','. Throws InvalidInput naming the bad item.
std::map<std::string, double> parseControls(const std::string& text);

struct Acquisition {
  Cloud cloud;                           // every unit's points, boat frame, metres
  std::vector<Sweep> sweeps;             // per unit (points and cloud moved into `cloud`)
  std::vector<std::string> errors;       // per unit: empty, or why its sweep failed
  double start_spread_s = 0;
  std::vector<std::string> warnings;     // partial sweeps, ...
  // One unit's sweep: the scanner it came from (the cloud's viewpoint is set too),
  // whose beam footprint the outline corrects for. Several units: none.
  std::optional<ScannerModel> model;
};

// A unit for the emulated deck scene (scene/boat frame: +X forward, +Y port, +Z up):
// shaft vertical at `position_m`, looking to port at β = 0 and sweeping 55° aft over the mainsail.
UnitConfig deckUnit(const Vec3& position_m = Vec3(1.5, -6.0, 1.2));

class ScannerSession {
 public:
  // Throws FileError / InvalidInput (acquisition/unit_config.hpp) for a bad file.
  void addUnitFile(const std::string& path);
  // Starts an emulator for `unit` in `scene`; the slot's config then points at it.
  void addEmulatedUnit(const Scene& scene, const std::string& scene_name, const UnitConfig& unit);
  void removeUnit(size_t index);
  std::vector<ScannerUnitSlot>& units() { return units_; }
  const std::vector<ScannerUnitSlot>& units() const { return units_; }

  // Homes unit `index`'s turntable. Throws InvalidInput for a bad index, TurntableError when homing fails.
  void home(size_t index, double timeout_s = 60) const;
  // Stops every unit's turntable and waits until it stands (after a cancelled scan: the drive
  // refuses to home while it still moves). Throws TurntableError naming the unit that fails.
  void stopTurntables(double timeout_s = 10) const;
  // One scan of every unit, synchronised by the UDP trigger when there are several.
  // Throws InvalidInput without units, and what runSweep throws for a single unit.
  Acquisition scan(const SweepOptions& options = {}, const Progress& progress = {}) const;

 private:
  std::vector<ScannerUnitSlot> units_;
};

// The points of the scan lines received so far, filled from the sweeping threads
// (SweepOptions::on_scan) while the UI thread watches the cloud grow.
class ArrivingPoints {
 public:
  void clear();
  void add(const std::vector<Vec3>& points);
  // Every point so far, when more arrived since `seen` (which is then moved on); else nothing.
  std::optional<std::vector<Vec3>> newerThan(uint64_t& seen) const;
  // SweepOptions that add each arriving scan line here.
  SweepOptions feeding(SweepOptions options = {});

 private:
  mutable std::mutex mutex_;
  std::vector<Vec3> points_;
  uint64_t version_ = 0;
};

// Stores the acquisition's cloud with the trim-step data (no analysis yet: the
// viewer analyses it when the scan is opened). Throws InvalidInput for an empty
// cloud or bad form values, and what importScan throws.
ImportResult saveAcquisition(Database& db, const Acquisition& acquisition, const TrimStepForm& form);

}  // namespace sailshape::viewer
