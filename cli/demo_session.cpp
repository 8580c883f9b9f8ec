#include "cli/demo_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>

#include <nlohmann/json.hpp>

#include "acquisition/emulated_turntable.hpp"
#include "acquisition/scanner_client.hpp"
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sweep.hpp"
#include "acquisition/sync.hpp"
#include "acquisition/tunnel.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "analysis/registration/boat_registration.hpp"
#include "analysis/registration/registration.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "analysis/segmentation/spars.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "reports/trim_report.hpp"

namespace sailshape::cli {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
const char* const kTest = "A2 tack ease";

// The emulator's tunnel: its scene is ray-cast from this, and the demo registers on its walls and looks for its spars.
const TunnelDescription& tunnel() {
  static const TunnelDescription t = builtInTunnel();
  return t;
}

// --- the sails: designs, and how they fly at each trim step ---------------------

SailDesign mainDesign() { return scaleDesign(exampleDesign(SailType::Main), tunnel().model_scale); }

SailDesign gennakerDesign() {
  SailDesign d = scaleDesign(exampleDesign(SailType::Gennaker), tunnel().model_scale);
  // Fractional A2 on a bowsprit: the head sits below the model's masthead and the tunnel's ceiling.
  d.luff_m = 3.06;
  d.leech_m = 2.75;
  d.foot_m = 1.7;
  d.tack = Vec3(1.5, 0.0, 0.22);
  d.stations = {{0.0, 20, 45, 32, 2.4, 1.8}, {0.5, 25, 48, 42, 2.4, 1.8}, {1.0, 17, 50, 56, 2, 2}};
  return d;
}

// The main flies a little flatter and more twisted than designed (sheet eased in the tunnel's gusts).
SailDesign mainFlying() {
  SailDesign d = mainDesign();
  d.stations = {{0.0, 8.2, 44, 9.5, 2, 2}, {0.5, 10.0, 46, 16.5, 2, 2}, {1.0, 7.0, 51, 26.5, 2, 2}};
  return d;
}

// Each step eases the gennaker's tack line by 2 cm (model scale): the luff rises and
// falls off, the head twists open, the foot flattens and the draft moves aft.
SailDesign gennakerFlying(int step) {
  SailDesign d = gennakerDesign();
  const double k = step;
  d.tack.z() += 0.02 * k;
  d.luff_sag_m += 0.01 * k;
  d.stations = {{0.0, 19.0 - 0.8 * k, 46 + 1.0 * k, 33 + 0.5 * k, 2.3, 1.8},
                {0.5, 24.0 - 0.5 * k, 49 + 1.0 * k, 44 + 1.5 * k, 2.3, 1.8},
                {1.0, 15.5 - 0.3 * k, 51 + 0.5 * k, 60 + 3.0 * k, 2, 2}};
  return d;
}

double tackEaseM(int step) { return 0.02 * step; }

json designToJson(const SailDesign& d) {
  json stations = json::array();
  for (const ProfileStation& s : d.stations)
    stations.push_back({{"fraction", s.fraction},
                        {"camber_pct", s.camber_pct},
                        {"draft_pct", s.draft_pct},
                        {"twist_deg", s.twist_deg},
                        {"entry_factor", s.entry_factor},
                        {"exit_factor", s.exit_factor}});
  return {{"sail_type", sailTypeName(d.type)}, {"luff_m", d.luff_m},     {"leech_m", d.leech_m},
          {"foot_m", d.foot_m},                {"tack", {d.tack.x(), d.tack.y(), d.tack.z()}},
          {"rake_deg", d.rake_deg},            {"luff_round_m", d.luff_round_m},
          {"luff_sag_m", d.luff_sag_m},        {"leech_round_m", d.leech_round_m},
          {"stations", stations},              {"source", "sailshape parametric generator"}};
}

Scene tunnelAtStep(int step) {
  Scene scene = builtInTunnelScene();
  for (SceneObject& o : scene.objects) {
    if (o.name == "main") o.mesh = generateSailMesh(mainFlying(), 80, 40);
    if (o.name == "gennaker") o.mesh = generateSailMesh(gennakerFlying(step), 80, 40);
  }
  return scene;
}

// --- the two units ------------------------------------------------------------------

struct RigUnit {
  UnitConfig config;               // as written to the unit file; pose = the nominal placement
  Eigen::Isometry3d true_pose;     // where the emulated unit really stands (placement error)
  std::string sail;                // the sail it scans
  std::string sail_file;           // its name in file names
  bool roi_ends_at_mast = false;   // a mainsail's region of interest ends at the mast's axis
  SailDesign design;
  Mesh design_mesh;
  MeshSections design_sections;
};

// Shaft vertical (unit X = boat +Z), the scan fan looking horizontally along `look` at β = 0.
Eigen::Isometry3d verticalShaftPose(const Vec3& position, double look_deg) {
  const Vec3 x = Vec3::UnitZ();
  const Vec3 y(std::cos(look_deg * kRadPerDeg), std::sin(look_deg * kRadPerDeg), 0.0);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = x.cross(y);
  pose.translation() = position;
  return pose;
}

// A hand-placed unit is never quite where the drawing puts it: a few centimetres and degrees.
Eigen::Isometry3d placementError(const Vec3& offset, double yaw_deg, double tilt_deg) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.linear() = (Eigen::AngleAxisd(yaw_deg * kRadPerDeg, Vec3::UnitZ()) * Eigen::AngleAxisd(tilt_deg * kRadPerDeg, Vec3::UnitX()))
                   .toRotationMatrix();
  e.translation() = offset;
  return e;
}

std::vector<RigUnit> makeRig(const DemoOptions& o, const SectionParams& sections) {
  std::vector<RigUnit> rig(2);
  // Main unit: to windward (starboard, −Y) of the boom, an LMS511.
  rig[0].config.name = "tunnel-main-lms511";
  rig[0].config.model = ScannerModel::Lms511;
  rig[0].config.pose = verticalShaftPose(Vec3(-0.5, -3.0, 1.1), 90.0);
  rig[0].config.p_m = 0.105;
  rig[0].config.theta_rad = 8.0 * kRadPerDeg;
  rig[0].true_pose = placementError(Vec3(0.03, -0.02, 0.01), 1.2, 0.4) * rig[0].config.pose;
  rig[0].sail = "Demo 36 main";
  rig[0].sail_file = "main";
  rig[0].design = mainDesign();
  rig[0].roi_ends_at_mast = true;
  // Gennaker unit: forward on the port side, looking back at the A2's leeward face, an LMS111.
  rig[1].config.name = "tunnel-gennaker-lms111";
  rig[1].config.model = ScannerModel::Lms111;
  rig[1].config.pose = verticalShaftPose(Vec3(3.7, 3.4, 1.2), -135.0);
  rig[1].config.p_m = 0.095;
  rig[1].config.theta_rad = -6.0 * kRadPerDeg;
  rig[1].true_pose = placementError(Vec3(-0.02, 0.03, -0.015), -0.8, -0.5) * rig[1].config.pose;
  rig[1].sail = "Demo 36 A2";
  rig[1].sail_file = "a2";
  rig[1].design = gennakerDesign();
  for (RigUnit& u : rig) {
    UnitConfig& c = u.config;
    c.frequency_hz = 25;
    c.resolution_deg = o.coarse ? 0.5 : c.model == ScannerModel::Lms511 ? 1.0 / 6.0 : 0.25;
    c.output_start_deg = -5;
    c.output_stop_deg = 185;
    c.start_angle_deg = -50;
    c.sweep_angle_deg = 100;
    c.speed_deg_s = c.sweep_angle_deg * c.frequency_hz / o.scan_lines;
    c.acceleration_deg_s2 = 200;
    c.beta_source = BetaSource::Encoder;
    validateUnit(c);
    u.design_mesh = generateSailMesh(u.design, 80, 40);
    u.design_sections = analyzeMeshSections(u.design_mesh, {}, sections);
  }
  return rig;
}

std::string capturePath(const std::string& dir, int step, const RigUnit& u) {
  return dir + "/step" + std::to_string(step + 1) + "-" + u.config.name + ".sscap";
}

// One emulated unit: the drive on a pty, the scanner on an ephemeral port sharing its motion.
struct EmulatedUnit {
  EmulatedTurntable table;
  ScannerEmulator scanner;
  UnitConfig connect;  // the unit file with this run's port and pty, pose identity (the unit's own frame)
  EmulatedUnit(const Scene& scene, const RigUnit& u, uint64_t seed, const EmulatedTurntableParams& tp)
      : table(tp), scanner(scene, emulatorParams(u, seed), &table.motion()), connect(u.config) {
    connect.port = scanner.port();
    connect.serial_device = table.devicePath();
    connect.pose = Eigen::Isometry3d::Identity();
  }
  static ScannerEmulatorParams emulatorParams(const RigUnit& u, uint64_t seed) {
    ScannerEmulatorParams p;
    p.port = 0;
    p.sensor.model = u.config.model;
    p.p_m = u.config.p_m;
    p.theta_rad = u.config.theta_rad;
    p.pose = u.true_pose;
    p.seed = seed;
    return p;
  }
};

// The region of interest a crew draws around each sail (study §5.4): the designed
// sail's bounding box grown by `margin_m`, less what lies within `clearance_m` above the
// deck (at `deck_z_m`) or around the spars, whose points region growing cannot always tell
// from the sail where the luff and foot touch them at model scale, and forward of
// `max_x_m` (a mainsail's box ends at the mast: beyond it lie the mast's mixed
// pixels and the headsail).
// The box is what the database stores as the scan's region (re-analyses crop to it).
RegionBox sailBox(const Mesh& design, double margin_m, double deck_z_m, double clearance_m, double max_x_m) {
  RegionBox box = designRegion(design, margin_m);
  box.min().z() = std::max(box.min().z(), deck_z_m + clearance_m);
  box.max().x() = std::min(box.max().x(), max_x_m);
  return box;
}
Cloud cropToSail(const Cloud& cloud, const RegionBox& box, double clearance_m, const std::vector<Spar>& spars) {
  auto nearSpar = [&](const Vec3& p) {
    for (const Spar& s : spars)
      if (distanceToSpar(p, s) < clearance_m) return true;
    return false;
  };
  std::vector<uint32_t> keep;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const Vec3& p = cloud.points[i];
    if (box.contains(p) && !nearSpar(p)) keep.push_back(static_cast<uint32_t>(i));
  }
  Cloud out = selectPoints(cloud, keep);
  out.viewpoint = cloud.viewpoint;
  return out;
}

// Simulated balance forces (N) for the tunnel's 6 m/s: lift and drag of each sail from
// its area, mean camber and the apparent wind angle. Labelled as simulated everywhere.
struct Forces {
  double drive_n = 0, side_n = 0, heel_moment_nm = 0;
};
Forces simulatedForces(const std::vector<std::pair<double, double>>& area_camber, double awa_deg,
                       const std::vector<double>& centre_heights_m) {
  const double q = 0.5 * 1.2 * 6.0 * 6.0;
  Forces f;
  const double b = awa_deg * kRadPerDeg;
  for (size_t i = 0; i < area_camber.size(); ++i) {
    const auto [area, camber] = area_camber[i];
    const double cl = std::min(1.7, 0.6 + 5.5 * camber);
    const double cd = 0.08 + 0.12 * cl * cl;
    const double lift = q * area * cl, drag = q * area * cd;
    const double drive = lift * std::sin(b) - drag * std::cos(b);
    const double side = lift * std::cos(b) + drag * std::sin(b);
    f.drive_n += drive;
    f.side_n += side;
    f.heel_moment_nm += side * centre_heights_m[i];
  }
  return f;
}

double meanZ(const std::vector<Vec3>& points) {
  double z = 0;
  for (const Vec3& p : points) z += p.z();
  return z / static_cast<double>(points.size());
}

double meanCamber(const SectionAnalysis& s) {
  double c = 0;
  for (const Section& x : s.sections) c += x.value.camber_pct;
  return s.sections.empty() ? 0 : c / s.sections.size() / 100.0;
}

std::string isoNow() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

void validateDemoOptions(const DemoOptions& o) {
  if (o.steps < 1 || o.steps > 10) throw InvalidInput("[runDemo] steps must be in 1..10 (got " + std::to_string(o.steps) + ")");
  if (o.sections < 1 || o.sections > 20)
    throw InvalidInput("[runDemo] sections must be in 1..20 (got " + std::to_string(o.sections) + ")");
  if (o.scan_lines < 20 || o.scan_lines > 2000)
    throw InvalidInput("[runDemo] scan_lines must be in 20..2000 (got " + std::to_string(o.scan_lines) + ")");
}

// What every trim step shares, set up once: the output folders, the rig and what the crew measured of the tunnel.
// A unit's registration into the boat frame as the steps use it.
struct StoredRegistration {
  RigidTransform transform;  // scanner to boat frame, for the cloud with the range scale taken out
  double range_scale = 1, range_scale_sigma = 0;
};

struct DemoRun {
  DemoOptions options;
  DemoLog log;
  Progress progress;
  std::string capture_dir;  // raw telegrams per step and unit
  std::string cloud_dir;    // what each sail's analysis started from (boat frame), for other tools
  SectionParams sections;
  std::vector<RigUnit> rig;
  BoatReference walls;
  std::vector<Spar> spars;  // where the crew measured them, boat frame
  std::string session;
  EmulatedTurntableParams turntable;
  // Per unit: its registration, kept until it moves.
  std::vector<std::optional<StoredRegistration>> stored;
  DemoResult result;
};

// Creates the output folders; throws InvalidInput when `dir` already holds a database.
void prepareOutput(DemoRun& run) {
  const DemoOptions& o = run.options;
  fs::create_directories(o.dir);
  run.result.database = (fs::path(o.dir) / "sailshape.db").string();
  if (fs::exists(run.result.database))
    throw InvalidInput("[runDemo] " + run.result.database + " already exists; choose another --dir or remove it");
  run.capture_dir = (fs::path(o.dir) / "captures").string();
  fs::create_directories(run.capture_dir);
  // Full scans are in the database.
  run.cloud_dir = (fs::path(o.dir) / "clouds").string();
  fs::create_directories(run.cloud_dir);
}

void writeUnitFiles(DemoRun& run) {
  for (const RigUnit& u : run.rig) {
    const std::string path = (fs::path(run.options.dir) / (u.config.name + ".json")).string();
    std::ofstream(path) << unitToJson(u.config) << "\n";
    run.result.unit_files.push_back(path);
  }
}

// What the emulator really did, to check the demo's results against: where each
// unit stood (4×4 row-major, scanner to boat frame, as the database's registrations)
// and its systematic range error as a range scale (measured / true range).
void writeEmulatorTruth(const DemoRun& run) {
  json units = json::array();
  for (const RigUnit& u : run.rig) {
    json rows = json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({u.true_pose(r, 0), u.true_pose(r, 1), u.true_pose(r, 2), u.true_pose(r, 3)});
    const double scale = 1 + EmulatedUnit::emulatorParams(u, 0).sensor.systematic_fraction;
    units.push_back({{"name", u.config.name}, {"sail", u.sail}, {"true_pose", rows}, {"range_scale", scale}});
  }
  std::ofstream(fs::path(run.options.dir) / "emulator-truth.json") << json{{"units", units}}.dump(2) << "\n";
}

void storeDesigns(Database& db, const std::vector<RigUnit>& rig) {
  for (const RigUnit& u : rig) {
    SailInfo info;
    info.name = u.sail;
    info.type = sailTypeName(u.design.type);
    info.boat = "Demo 36 (1:3.6 tunnel model)";
    info.designer = "sailshape generator";
    const json params = designToJson(u.design);
    upsertSail(db, info, &u.design_mesh, &params);
  }
}

// One unit's part of a trim step, from its sweep to what is stored.
struct UnitStep {
  DemoUnitStep row;
  BoatRegistration registration;
  StoredRegistration used;  // the unit's stored registration
  Cloud boat_cloud;
  RegionBox region;  // the sail's region in the boat frame, stored with the scan
  std::optional<SailAnalysis> analysis;  // empty when the analysis failed
  DesignComparison comparison;
  // For the simulated forces: the analysed sail's, or its design's when the analysis failed.
  double area_m2 = 0, mean_camber = 0, centre_height_m = 0;
};

// Both units sweep the step's scene on a shared trigger; throws ScannerError when a unit did not sweep.
SynchronisedSweeps sweepStep(const DemoRun& run, int step, const std::string& tag) {
  const Scene scene = tunnelAtStep(step);
  std::vector<std::unique_ptr<EmulatedUnit>> units;
  for (size_t i = 0; i < run.rig.size(); ++i)
    units.push_back(std::make_unique<EmulatedUnit>(scene, run.rig[i], run.options.seed + 1000 * step + i, run.turntable));
  std::vector<UnitConfig> connect;
  for (const auto& u : units) connect.push_back(u->connect);
  SyncOptions so;
  so.trigger_id = static_cast<uint64_t>(step + 1);
  for (const RigUnit& u : run.rig) so.capture_paths.push_back(capturePath(run.capture_dir, step, u));
  SynchronisedSweeps synced = runSynchronisedSweeps(connect, so, run.progress);
  units.clear();  // the emulators stop: the sweeps are in
  for (size_t i = 0; i < synced.errors.size(); ++i)
    if (!synced.errors[i].empty())
      throw ScannerError("[runDemo] " + tag + ": " + run.rig[i].config.name + " did not sweep: " + synced.errors[i]);
  return synced;
}

// Registers the unit's sweep on the tunnel walls and keeps the stored registration unless the unit moved.
void registerOnWalls(DemoRun& run, size_t i, const Sweep& sweep, const std::string& tag, UnitStep& out) {
  const RigUnit& u = run.rig[i];
  DemoUnitStep& row = out.row;
  run.log(tag + ": " + u.config.name + ": registering on the tunnel walls");
  BoatRegistrationParams bp;
  bp.prior_rotation = u.config.pose.linear();
  bp.prior_tolerance_deg = 15;
  out.registration = registerToBoat(sweep.cloud, run.walls, bp, run.progress);
  const BoatRegistration& reg = out.registration;
  if (!reg.accepted)
    run.result.warnings.push_back({out.row.step, u.config.name + ": wall registration not accepted (fitness " +
                                                     std::to_string(1000 * reg.fitness_rms_m) + " mm)"});
  std::optional<StoredRegistration>& stored = run.stored[i];
  const StoredRegistration fresh{reg.transform, reg.range_scale, reg.range_scale_sigma};
  if (!stored) {
    stored = fresh;
  } else {
    // With the range scale fitted alongside, an unmoved unit's registrations on the
    // walls agree to a fraction of the sensor's random error (their 10⁵ points
    // average it out; the scale no longer shifts each wall by up to 0.3 % of its
    // range): a displacement beyond one σ (SPEC §3) anywhere within 5 m is a move.
    const double tolerance_m = AnalysisParams{}.sensor_sigma_m;
    const Drift d = compareTransforms(stored->transform, reg.transform, 5.0, tolerance_m);
    row.drift_mm = 1000 * d.max_displacement_m;
    if (d.moved) {
      run.result.warnings.push_back(
          {row.step, u.config.name + ": the unit moved (" + std::to_string(row.drift_mm) + " mm); registered again"});
      stored = fresh;
    }
  }
  out.used = *stored;
  row.registration_rms_mm = 1000 * reg.fitness_rms_m;
  row.truth_error_deg = rotationDifferenceDeg(out.used.transform.linear(), u.true_pose.linear());
  row.truth_error_mm = 1000 * (out.used.transform.translation() - u.true_pose.translation()).norm();
}

// The spars where this cloud has them: the registration is good to a couple of
// centimetres, as much as the gap between the mast and the luff. A spar this unit
// cannot see is a warning of the step; the log says it the first time only, as
// the unit stands still and misses it at every step.
std::vector<Spar> findSpars(DemoRun& run, const Cloud& boat_cloud, double sensor_sigma_m, int step,
                            const std::string& tag, const std::string& unit) {
  std::vector<Spar> spars;
  for (const Spar& nominal : run.spars) {
    SparFitParams fp;
    fp.sensor_sigma_m = sensor_sigma_m;
    const SparFit f = fitSpar(boat_cloud, nominal, fp);
    if (f.found) {
      run.log(tag + ": " + unit + ": " + nominal.name + " found " +
              std::to_string(static_cast<int>(std::lround(1000 * f.offset.norm()))) + " mm from its measured place");
    } else {
      const std::string text = unit + ": " + f.message + "; its measured place is used";
      std::vector<StepWarning>& warnings = run.result.warnings;
      const bool said =
          std::any_of(warnings.begin(), warnings.end(), [&](const StepWarning& w) { return sameWarning(w.text, text); });
      if (!said) run.log(tag + ": " + text);
      warnings.push_back({step + 1, text});
    }
    spars.push_back(f.spar);
  }
  return spars;
}

// Moves the sweep into the boat frame, crops it to the sail, analyses it and compares it with its design.
void analyseUnit(DemoRun& run, size_t i, int step, const Sweep& sweep, const std::string& tag, UnitStep& out) {
  const RigUnit& u = run.rig[i];
  DemoUnitStep& row = out.row;
  run.log(tag + ": " + u.config.name + ": analysing " + u.sail);
  out.boat_cloud = toBoatFrame(sweep.cloud, out.used.transform, out.used.range_scale);
  AnalysisParams ap;
  ap.sections = run.sections;
  // The unit's beam footprint trims every edge (1.5-4 cm at these ranges); the outline allows for it.
  useScannerBeam(ap.outline, u.config.model);
  ap.outline.design_lengths_m = {u.design_sections.outline.luff_length_m, u.design_sections.outline.leech_length_m,
                                 u.design_sections.outline.foot_length_m};
  const std::vector<Spar> spars = findSpars(run, out.boat_cloud, ap.sensor_sigma_m, step, tag, u.config.name);
  const double max_x = u.roi_ends_at_mast ? spars.front().base.x() : 1e9;
  // The whole scan loses its mixed pixels before the crop cuts off the surfaces behind
  // them that tell them apart (a sail's head seen against the other sail would keep a fringe).
  out.region = sailBox(u.design_mesh, 0.1, tunnel().hull.deck_z_m, 3 * ap.sensor_sigma_m, max_x);
  const Cloud roi = cropToSail(withoutMixedPixels(out.boat_cloud, ap), out.region, 3 * ap.sensor_sigma_m, spars);
  writeCloud(run.cloud_dir + "/step" + std::to_string(step + 1) + "-" + u.sail_file + "-roi.ply", roi);
  try {
    out.analysis = analyzeSail(roi, ap, run.progress);
  } catch (const std::exception& e) {
    // The scan and its registration are still stored; the crew sees why there are no sections.
    run.result.warnings.push_back({step + 1, u.sail + ": analysis failed, scan stored without it: " + e.what()});
  }
  if (!out.analysis) {
    out.area_m2 = meshArea(u.design_mesh);
    out.mean_camber = meanCamber(u.design_sections.sections);
    out.centre_height_m = u.design_mesh.vertices.empty() ? 0 : meanZ(u.design_mesh.vertices);
    return;
  }
  const SailAnalysis& a = *out.analysis;
  row.analysed = true;
  row.sail_points = a.sail_points;
  out.comparison =
      compareWithDesign(u.design_mesh, u.design_sections.sections, a.sail_cloud.points, a.sections, run.progress);
  row.deviation_rms_mm = 1000 * out.comparison.stats.rms_m;
  out.area_m2 = meshArea(a.mesh);
  out.mean_camber = meanCamber(a.sections);
  out.centre_height_m = a.sail_cloud.points.empty() ? 0 : meanZ(a.sail_cloud.points);
}

// One unit's sweep through registration and analysis.
UnitStep processUnit(DemoRun& run, size_t i, int step, const std::string& tag, const Sweep& s, double spread_ms) {
  const RigUnit& u = run.rig[i];
  UnitStep out;
  DemoUnitStep& row = out.row;
  row.unit = u.config.name;
  row.sail = u.sail;
  row.step = step + 1;
  row.points = s.cloud.size();
  row.partial = s.partial;
  row.start_spread_ms = spread_ms;
  if (s.partial) run.result.warnings.push_back({step + 1, u.config.name + ": partial sweep (" + s.message + ")"});
  for (const std::string& w : s.warnings) run.result.warnings.push_back({step + 1, u.config.name + ": " + w});
  registerOnWalls(run, i, s, tag, out);
  analyseUnit(run, i, step, s, tag, out);
  return out;
}

// Stores each unit's scan, registration, analysis and design comparison, with the step's simulated forces.
void storeStep(DemoRun& run, Database& db, int step, const std::string& tag, const std::vector<Sweep>& sweeps,
               std::vector<UnitStep>& units) {
  std::vector<std::pair<double, double>> area_camber;
  std::vector<double> heights;
  for (const UnitStep& us : units) {
    area_camber.emplace_back(us.area_m2, us.mean_camber);
    heights.push_back(us.centre_height_m);
  }
  const double awa_deg = 110;
  const Forces forces = simulatedForces(area_camber, awa_deg, heights);
  run.log(tag + ": storing in " + run.result.database);
  for (size_t i = 0; i < run.rig.size(); ++i) {
    const RigUnit& u = run.rig[i];
    UnitStep& us = units[i];
    ImportMetadata m;
    m.campaign = "sailshape demo (emulated wind tunnel)";
    m.campaign_kind = "wind_tunnel";
    m.session = run.session;
    m.boat = "Demo 36 (1:3.6 tunnel model)";
    m.sail = u.sail;
    m.sail_type = sailTypeName(u.design.type);
    m.test = kTest;
    m.trim_step = step + 1;
    m.awa_deg = awa_deg;
    m.aws_m_s = 6.0;
    m.drive_n = forces.drive_n;
    m.side_n = forces.side_n;
    m.heel_moment_nm = forces.heel_moment_nm;
    m.controls = {{"gennaker_tack_ease_m", tackEaseM(step)}};
    m.scanner_unit = u.config.name;
    m.scanned_at = isoNow();
    m.settings = json::parse(unitToJson(u.config));
    m.settings["forces"] = "simulated by the emulator (not measured)";
    m.settings["range_scale"] = {{"scale", us.used.range_scale},
                                 {"sigma", us.used.range_scale_sigma},
                                 {"applied", "taken out of the cloud before the registration's transform"}};
    m.settings["sweep"] = {{"scans", sweeps[i].scans},
                           {"beams", sweeps[i].beams},
                           {"partial", sweeps[i].partial},
                           {"start_spread_ms", us.row.start_spread_ms}};
    m.raw_capture = capturePath(run.capture_dir, step, u);
    m.region = ScanRegion{us.region, currentDesignVersion(db, u.sail)};
    const json doc = us.analysis ? analysisToJson(*us.analysis) : json();
    const ImportResult r =
        importScan(db, m, us.analysis ? &doc : nullptr, &us.boat_cloud, {}, us.analysis ? &us.analysis->mesh : nullptr);
    addRegistration(db, r.scan_id, us.used.transform.matrix(), us.registration.fitness_rms_m, us.registration.fitness_rms_m);
    us.row.scan_id = r.scan_id;
    run.result.scans.push_back(us.row);
    if (!us.analysis) continue;
    addDesignComparison(db, r.analysis_id, u.sail, us.comparison.stats,
                        json{{"sections", sectionDeltasToJson(us.comparison.sections)}});
    for (const SectionDelta& d : us.comparison.sections)
      run.result.sections.push_back({u.sail, step + 1, d.fraction, d.flying.camber_pct, d.flying.draft_pct,
                                     d.flying.twist_deg, d.delta.camber_pct, d.delta.draft_pct, d.delta.twist_deg});
    for (const std::string& w : us.analysis->warnings) run.result.warnings.push_back({step + 1, u.sail + ": " + w});
  }
}

// One trim step: the gennaker's tack eased, both units sweep, each cloud is registered, analysed and stored.
void runStep(DemoRun& run, Database& db, int step) {
  const std::string tag = "step " + std::to_string(step + 1) + "/" + std::to_string(run.options.steps);
  run.log(tag + ": gennaker tack eased " + std::to_string(static_cast<int>(std::lround(1000 * tackEaseM(step)))) +
          " mm; synchronised sweep of both units");
  const SynchronisedSweeps synced = sweepStep(run, step, tag);
  const double spread_ms = 1000.0 * synced.start_spread_s;
  std::vector<UnitStep> units;
  for (size_t i = 0; i < run.rig.size(); ++i)
    units.push_back(processUnit(run, i, step, tag, synced.sweeps[i], spread_ms));
  storeStep(run, db, step, tag, synced.sweeps, units);
}

// One PDF trim report per sail, from the closed database.
void writeReports(DemoRun& run) {
  for (const RigUnit& u : run.rig) {
    run.log("report: " + u.sail);
    TrimReportParams rp;
    rp.db_path = run.result.database;
    rp.test = kTest;
    rp.sail = u.sail;
    rp.audience = "designer";
    rp.out_path = (fs::path(run.options.dir) / ("report-" + u.sail_file + ".pdf")).string();
    try {
      const TrimReport report = writeTrimReport(rp, run.progress);
      run.result.reports.push_back(report.out_path);
      for (const std::string& w : report.content.warnings) run.result.warnings.push_back({0, "report " + u.sail + ": " + w});
    } catch (const InvalidInput& e) {
      // A sail none of whose steps could be analysed has no sections to report.
      run.result.warnings.push_back({0, "no report for " + u.sail + ": " + e.what()});
    }
  }
}

}  // namespace

DemoResult runDemo(const DemoOptions& o, const DemoLog& log, const Progress& progress) {
  validateDemoOptions(o);
  const auto t0 = std::chrono::steady_clock::now();
  DemoRun run;
  run.options = o;
  run.log = log ? log : [](const std::string&) {};
  run.progress = progress;
  prepareOutput(run);
  run.sections.count = o.sections;
  run.rig = makeRig(o, run.sections);
  writeUnitFiles(run);
  writeEmulatorTruth(run);
  {  // the database stays open while the steps are stored; the reports read the closed file
    Database db = openSailDatabase(run.result.database);
    storeDesigns(db, run.rig);
    run.walls = tunnelWalls(tunnel());
    run.spars = tunnelSpars(tunnel());
    run.stored.resize(run.rig.size());
    run.session = "demo " + isoNow();
    run.turntable.home_speed_deg_s = 180;
    run.turntable.acceleration_deg_s2 = 400;
    for (int step = 0; step < o.steps; ++step) runStep(run, db, step);
  }
  writeReports(run);
  run.result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return std::move(run.result);
}

}  // namespace sailshape::cli
