#include "viewer/scanner_session.hpp"

#include <cmath>
#include <sstream>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sync.hpp"
#include "acquisition/turntable.hpp"
#include "analysis/core/errors.hpp"

namespace sailshape::viewer {

struct EmulatedUnit::Hardware {
  EmulatedTurntable table;
  ScannerEmulator scanner;
  Hardware(const Scene& scene, const ScannerEmulatorParams& sp, const EmulatedTurntableParams& tp)
      : table(tp), scanner(scene, sp, &table.motion()) {}
};

EmulatedUnit::EmulatedUnit(const Scene& scene, const UnitConfig& unit) : unit_(unit) {
  validateUnit(unit);
  ScannerEmulatorParams sp;
  sp.port = 0;
  sp.sensor.model = unit.model;
  sp.p_m = unit.p_m;
  sp.theta_rad = unit.theta_rad;
  sp.pose = unit.pose;
  EmulatedTurntableParams tp;
  tp.home_speed_deg_s = 180;  // the emulated drive homes in about two seconds
  tp.acceleration_deg_s2 = 720;
  hw_ = std::make_unique<Hardware>(scene, sp, tp);
  unit_.host = "127.0.0.1";
  unit_.port = hw_->scanner.port();
  unit_.serial_device = hw_->table.devicePath();
}

EmulatedUnit::~EmulatedUnit() = default;

std::map<std::string, double> parseControls(const std::string& text) {
  std::map<std::string, double> out;
  std::string item;
  std::stringstream ss(text);
  auto trim = [](std::string s) {
    const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
  };
  while (std::getline(ss, item, ';')) {
    std::stringstream inner(item);
    std::string part;
    while (std::getline(inner, part, ',')) {
      part = trim(part);
      if (part.empty()) continue;
      const auto eq = part.find('=');
      const std::string name = eq == std::string::npos ? "" : trim(part.substr(0, eq));
      const std::string value = eq == std::string::npos ? "" : trim(part.substr(eq + 1));
      size_t used = 0;
      double v = NAN;
      try {
        v = std::stod(value, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (name.empty() || used == 0 || used != value.size() || !std::isfinite(v))
        throw InvalidInput("[parseControls] \"" + part + "\" is not name=number");
      out[name] = v;
    }
  }
  return out;
}

UnitConfig deckUnit(const Vec3& position_m) {
  UnitConfig u;
  u.name = "deck-unit";
  u.model = ScannerModel::Lms511;
  // Unit X (the shaft) to boat +Z; β = 0 then looks to port (+Y).
  u.pose = makePose(position_m, 0.0, -M_PI / 2, 0.0);
  // β turns the fan from port towards aft: the mainsail (mast to clew) lies at β ≈ 10°..50°.
  u.start_angle_deg = 0;
  u.sweep_angle_deg = 55;
  u.speed_deg_s = 30;
  u.acceleration_deg_s2 = 120;
  u.frequency_hz = 50;
  u.resolution_deg = 0.5;
  u.output_start_deg = 5;
  u.output_stop_deg = 120;
  return u;
}

void ScannerSession::addUnitFile(const std::string& path) {
  ScannerUnitSlot slot;
  slot.config = readUnitFile(path);
  slot.origin = path;
  units_.push_back(std::move(slot));
}

void ScannerSession::addEmulatedUnit(const Scene& scene, const std::string& scene_name, const UnitConfig& unit) {
  ScannerUnitSlot slot;
  slot.emulator = std::make_shared<EmulatedUnit>(scene, unit);
  slot.config = slot.emulator->unit();
  slot.origin = "emulated (" + scene_name + ")";
  units_.push_back(std::move(slot));
}

void ScannerSession::removeUnit(size_t index) {
  if (index >= units_.size())
    throw InvalidInput("[ScannerSession::removeUnit] no unit " + std::to_string(index) + " (" +
                       std::to_string(units_.size()) + " units)");
  units_.erase(units_.begin() + static_cast<long>(index));
}

void ScannerSession::home(size_t index, double timeout_s) const {
  if (index >= units_.size())
    throw InvalidInput("[ScannerSession::home] no unit " + std::to_string(index) + " (" +
                       std::to_string(units_.size()) + " units)");
  TurntableLinkParams link;
  link.device = units_[index].config.serial_device;
  link.baud = units_[index].config.baud;
  TurntableClient client(link);
  client.home(timeout_s);
}

void ScannerSession::stopTurntables(double timeout_s) const {
  for (const ScannerUnitSlot& u : units_) {
    TurntableLinkParams link;
    link.device = u.config.serial_device;
    link.baud = u.config.baud;
    TurntableClient client(link);
    client.stop();
    if (!client.waitIdle(timeout_s))
      throw TurntableError("[ScannerSession::stopTurntables] " + u.config.name + ": the turntable still moves after " +
                           std::to_string(timeout_s) + " s");
  }
}

Acquisition ScannerSession::scan(const SweepOptions& options, const Progress& progress) const {
  if (units_.empty()) throw InvalidInput("[ScannerSession::scan] no scanner unit: load a unit file or add an emulated unit");
  Acquisition a;
  if (units_.size() == 1) {
    a.sweeps.push_back(runSweep(units_[0].config, options, progress));
    a.errors.push_back("");
    a.model = units_[0].config.model;
  } else {
    std::vector<UnitConfig> configs;
    for (const auto& u : units_) configs.push_back(u.config);
    SyncOptions sync;
    sync.sweep = options;
    SynchronisedSweeps s = runSynchronisedSweeps(configs, sync, progress);
    a.sweeps = std::move(s.sweeps);
    a.errors = std::move(s.errors);
    a.start_spread_s = s.start_spread_s;
  }
  for (Sweep& s : a.sweeps) {
    if (s.partial) a.warnings.push_back(s.unit + ": partial sweep (" + s.message + ")");
    for (const auto& w : s.warnings) a.warnings.push_back(s.unit + ": " + w);
    // One unit's sweep keeps where it stood and its samples' scan angles: its mixed
    // pixels are found on its grid (analysis/segmentation/mixed_pixels.hpp). Several units'
    // samples share neither.
    if (a.sweeps.size() == 1)
      a.cloud = std::move(s.cloud);
    else
      a.cloud.points.insert(a.cloud.points.end(), s.cloud.points.begin(), s.cloud.points.end());
    s.cloud = Cloud{};
    s.points.clear();
    s.points.shrink_to_fit();
  }
  return a;
}

void ArrivingPoints::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  points_.clear();
  ++version_;
}

void ArrivingPoints::add(const std::vector<Vec3>& points) {
  if (points.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  points_.insert(points_.end(), points.begin(), points.end());
  ++version_;
}

std::optional<std::vector<Vec3>> ArrivingPoints::newerThan(uint64_t& seen) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (version_ == seen) return std::nullopt;
  seen = version_;
  return points_;
}

SweepOptions ArrivingPoints::feeding(SweepOptions options) {
  options.on_scan = [this](const std::vector<Vec3>& points) { add(points); };
  return options;
}

ImportResult saveAcquisition(Database& db, const Acquisition& acquisition, const TrimStepForm& form) {
  if (acquisition.cloud.empty()) throw InvalidInput("[saveAcquisition] the scan holds no point");
  ImportMetadata meta;
  meta.campaign = form.campaign;
  meta.session = form.session;
  meta.boat = form.boat;
  meta.sail = form.sail;
  meta.test = form.test;
  meta.trim_step = form.step;
  meta.awa_deg = form.awa_deg;
  meta.aws_m_s = form.aws_m_s;
  meta.drive_n = form.drive_n;
  meta.side_n = form.side_n;
  meta.heel_moment_nm = form.heel_moment_nm;
  meta.controls = parseControls(form.controls);
  nlohmann::json settings = nlohmann::json::array();
  for (const Sweep& s : acquisition.sweeps)
    settings.push_back({{"unit", s.unit},
                        {"scans", s.scans},
                        {"beta_start_deg", s.beta_start_deg},
                        {"beta_end_deg", s.beta_end_deg},
                        {"partial", s.partial}});
  meta.settings = {{"sweeps", settings}, {"start_spread_s", acquisition.start_spread_s}};
  return importScan(db, meta, nullptr, &acquisition.cloud);
}

}  // namespace sailshape::viewer
