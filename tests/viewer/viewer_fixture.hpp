#pragma once
// A sailshape database with a design and flying shapes of known geometry: the
// example mainsail's design, and flying shapes whose camber and twist were
// trimmed away from it, scanned with the sensor's 4 mm range noise (SPEC §3).
#include <unistd.h>

#include <filesystem>
#include <string>

#include "analysis/design/sail_generator.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"

namespace sailshape::test {

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "sailshape-viewer-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// The design with every station's camber raised by `camber_pct` and twist by `twist_deg`.
inline SailDesign trimmed(double camber_pct, double twist_deg) {
  SailDesign d = exampleDesign(SailType::Main);
  for (auto& s : d.stations) {
    s.camber_pct += camber_pct;
    s.twist_deg += twist_deg;
  }
  return d;
}

inline constexpr double kSensorSigmaM = 0.004;  // SPEC §3 range noise

// Imports one flying scan of `shape` as trim step `step` of test "upwind".
inline ImportResult importFlying(Database& db, const SailDesign& shape, int step, double awa_deg, size_t points = 20'000) {
  ScanSimulation sim;
  sim.points = points;
  sim.noise_sigma_m = kSensorSigmaM;
  sim.seed = 7 + static_cast<uint64_t>(step);
  const Cloud cloud = sampleSail(shape, sim);
  AnalysisParams params;
  params.segment = false;  // the simulated cloud holds the sail alone
  const SailAnalysis analysis = analyzeSail(cloud, params);
  const nlohmann::json doc = analysisToJson(analysis);
  ImportMetadata meta;
  meta.campaign = "Lake trials";
  meta.sail = "main-A";
  meta.sail_type = "mainsail";
  meta.test = "upwind";
  meta.trim_step = step;
  meta.awa_deg = awa_deg;
  meta.controls = {{"sheet", 0.1 * step}};
  return importScan(db, meta, &doc, &cloud);
}

// Design "main-A" plus `steps` flying trim steps (camber +2 %, twist +3° per step).
inline void makeSailDatabase(const std::string& path, int steps = 1) {
  Database db = openSailDatabase(path);
  const Mesh design = generateSailMesh(exampleDesign(SailType::Main));
  SailInfo info;
  info.name = "main-A";
  info.type = "mainsail";
  upsertSail(db, info, &design);
  for (int k = 1; k <= steps; ++k) importFlying(db, trimmed(2.0, 3.0 * k), k, 30.0 + 2 * k);
}

}  // namespace sailshape::test
