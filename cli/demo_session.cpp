#include "cli/demo_session.hpp"

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
#include "acquisition/scanner_emulator.hpp"
#include "acquisition/scanner_client.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sweep.hpp"
#include "acquisition/sync.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/units.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/registration/boat_registration.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/registration/registration.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/segmentation/spars.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "reports/trim_report.hpp"

namespace sailshape::cli {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
constexpr double kModelScale = 1.0 / 3.6;  // the built-in tunnel's yacht model
const char* const kTest = "A2 tack ease";

// --- the sails: designs, and how they fly at each trim step ---------------------

SailDesign mainDesign() { return scaleDesign(exampleDesign(SailType::Main), kModelScale); }

SailDesign gennakerDesign() {
  SailDesign d = scaleDesign(exampleDesign(SailType::Gennaker), kModelScale);
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

// The built-in tunnel's chamber (acquisition/scene.cpp) as faces known in the boat frame.
BoatReference tunnelWalls() {
  const Vec3 lo(-8.0, -7.0, -0.6), hi(8.0, 7.0, 3.2);
  BoatReference ref;
  ref.name = "wind tunnel chamber";
  ref.faces = {{"floor", Vec3::UnitZ(), lo.z()},          {"ceiling", -Vec3::UnitZ(), -hi.z()},
               {"starboard wall", Vec3::UnitY(), lo.y()}, {"port wall", -Vec3::UnitY(), -hi.y()},
               {"aft wall", Vec3::UnitX(), lo.x()},       {"forward wall", -Vec3::UnitX(), -hi.x()}};
  return ref;
}

// The built-in tunnel model's mast and boom (acquisition/scene.cpp builtInTunnelScene),
// in the boat frame as the crew measures them once per boat.
std::vector<Spar> tunnelSpars() {
  Spar mast{"mast", Vec3(0.035, 0, 0), Vec3::UnitZ(), 3.05, 0.025};
  Spar boom{"boom", Vec3(0.0, 0, 0.26), -Vec3::UnitX(), 1.05, 0.015};
  return {mast, boom};
}
constexpr double kDeckZ = 0.0;

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
// sail's bounding box grown by `margin_m`, less the deck and a clearance of
// `clearance_m` around the spars, whose points region growing cannot always tell
// from the sail where the luff and foot touch them at model scale, and forward of
// `max_x_m` (a mainsail's box ends at the mast: beyond it lie the mast's mixed
// pixels and the headsail).
Cloud cropToSail(const Cloud& cloud, const Mesh& design, double margin_m, double clearance_m, double max_x_m,
                 const std::vector<Spar>& spars) {
  Eigen::AlignedBox3d box;
  for (const Vec3& v : design.vertices) box.extend(v);
  box.min().array() -= margin_m;
  box.max().array() += margin_m;
  auto nearSpar = [&](const Vec3& p) {
    for (const Spar& s : spars)
      if (distanceToSpar(p, s) < clearance_m) return true;
    return false;
  };
  std::vector<uint32_t> keep;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const Vec3& p = cloud.points[i];
    if (box.contains(p) && p.x() < max_x_m && p.z() > kDeckZ + clearance_m && !nearSpar(p))
      keep.push_back(static_cast<uint32_t>(i));
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

}  // namespace

DemoResult runDemo(const DemoOptions& o, const DemoLog& log_fn, const Progress& progress) {
  if (o.steps < 1 || o.steps > 10) throw InvalidInput("[runDemo] steps must be in 1..10 (got " + std::to_string(o.steps) + ")");
  if (o.sections < 1 || o.sections > 20)
    throw InvalidInput("[runDemo] sections must be in 1..20 (got " + std::to_string(o.sections) + ")");
  if (o.scan_lines < 20 || o.scan_lines > 2000)
    throw InvalidInput("[runDemo] scan_lines must be in 20..2000 (got " + std::to_string(o.scan_lines) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  auto log = [&](const std::string& m) {
    if (log_fn) log_fn(m);
  };

  DemoResult result;
  fs::create_directories(o.dir);
  result.database = (fs::path(o.dir) / "sailshape.db").string();
  if (fs::exists(result.database))
    throw InvalidInput("[runDemo] " + result.database + " already exists; choose another --dir or remove it");
  const std::string capture_dir = (fs::path(o.dir) / "captures").string();
  fs::create_directories(capture_dir);
  // What each sail's analysis started from (boat frame), for other tools; full scans are in the database.
  const std::string cloud_dir = (fs::path(o.dir) / "clouds").string();
  fs::create_directories(cloud_dir);

  SectionParams sp;
  sp.count = o.sections;
  std::vector<RigUnit> rig = makeRig(o, sp);
  for (const RigUnit& u : rig) {
    const std::string path = (fs::path(o.dir) / (u.config.name + ".json")).string();
    std::ofstream(path) << unitToJson(u.config) << "\n";
    result.unit_files.push_back(path);
  }
  {  // What the emulator really did, to check the demo's results against: where each
     // unit stood (4×4 row-major, scanner to boat frame, as the database's registrations).
    json units = json::array();
    for (const RigUnit& u : rig) {
      json rows = json::array();
      for (int r = 0; r < 4; ++r) rows.push_back({u.true_pose(r, 0), u.true_pose(r, 1), u.true_pose(r, 2), u.true_pose(r, 3)});
      units.push_back({{"name", u.config.name}, {"sail", u.sail}, {"true_pose", rows}});
    }
    std::ofstream(fs::path(o.dir) / "emulator-truth.json") << json{{"units", units}}.dump(2) << "\n";
  }

  {  // the database stays open while the steps are stored; the report reads the closed file
    Database db = openSailDatabase(result.database);
    for (const RigUnit& u : rig) {
      SailInfo info;
      info.name = u.sail;
      info.type = sailTypeName(u.design.type);
      info.boat = "Demo 36 (1:3.6 tunnel model)";
      info.designer = "sailshape generator";
      const json params = designToJson(u.design);
      upsertSail(db, info, &u.design_mesh, &params);
    }

    const BoatReference walls = tunnelWalls();
    std::vector<std::optional<RigidTransform>> stored(rig.size());
    const std::string session = "demo " + isoNow();
    EmulatedTurntableParams tp;
    tp.home_speed_deg_s = 180;
    tp.acceleration_deg_s2 = 400;

    for (int step = 0; step < o.steps; ++step) {
      const std::string tag = "step " + std::to_string(step + 1) + "/" + std::to_string(o.steps);
      log(tag + ": gennaker tack eased " + std::to_string(static_cast<int>(std::lround(1000 * tackEaseM(step)))) +
          " mm; synchronised sweep of both units");
      const Scene scene = tunnelAtStep(step);
      std::vector<std::unique_ptr<EmulatedUnit>> units;
      for (size_t i = 0; i < rig.size(); ++i)
        units.push_back(std::make_unique<EmulatedUnit>(scene, rig[i], o.seed + 1000 * step + i, tp));
      std::vector<UnitConfig> connect;
      for (const auto& u : units) connect.push_back(u->connect);
      SyncOptions so;
      so.trigger_id = static_cast<uint64_t>(step + 1);
      for (const RigUnit& u : rig) so.capture_paths.push_back(capturePath(capture_dir, step, u));
      SynchronisedSweeps synced = runSynchronisedSweeps(connect, so, progress);
      units.clear();  // the emulators stop: the sweeps are in
      for (size_t i = 0; i < synced.errors.size(); ++i)
        if (!synced.errors[i].empty())
          throw ScannerError("[runDemo] " + tag + ": " + rig[i].config.name + " did not sweep: " + synced.errors[i]);
      std::vector<Sweep>& sweeps = synced.sweeps;
      const double spread_ms = 1000.0 * synced.start_spread_s;

      std::vector<std::pair<double, double>> area_camber;
      std::vector<double> heights;
      std::vector<std::optional<SailAnalysis>> analyses(rig.size());
      std::vector<DemoUnitStep> rows(rig.size());
      std::vector<RigidTransform> used(rig.size());
      std::vector<Cloud> boat_clouds(rig.size());
      std::vector<DesignComparison> comparisons(rig.size());
      std::vector<BoatRegistration> registrations(rig.size());
      for (size_t i = 0; i < rig.size(); ++i) {
        const RigUnit& u = rig[i];
        const Sweep& s = sweeps[i];
        DemoUnitStep& row = rows[i];
        row.unit = u.config.name;
        row.sail = u.sail;
        row.step = step + 1;
        row.points = s.cloud.size();
        row.partial = s.partial;
        row.start_spread_ms = spread_ms;
        if (s.partial) result.warnings.push_back(tag + " " + u.config.name + ": partial sweep (" + s.message + ")");
        for (const std::string& w : s.warnings) result.warnings.push_back(tag + " " + u.config.name + ": " + w);

        log(tag + ": " + u.config.name + ": registering on the tunnel walls");
        BoatRegistrationParams bp;
        bp.prior_rotation = u.config.pose.linear();
        bp.prior_tolerance_deg = 15;
        registrations[i] = registerToBoat(s.cloud, walls, bp, progress);
        const BoatRegistration& reg = registrations[i];
        if (!reg.accepted)
          result.warnings.push_back(tag + " " + u.config.name + ": wall registration not accepted (fitness " +
                                    std::to_string(1000 * reg.fitness_rms_m) + " mm)");
        if (!stored[i]) {
          stored[i] = reg.transform;
        } else {
          // Registrations of an unmoved unit differ by the sensor's σ-level fitness plus the
          // range's systematic error (SPEC §3: up to 0.3 % of range) on whichever walls carry
          // them: two fits leaning on different walls differ by up to that over the farthest.
          double farthest_m = 0;
          for (const ReferenceFace& f : walls.faces)
            farthest_m = std::max(farthest_m, std::abs(f.normal.dot(u.config.pose.translation()) - f.offset_m));
          const double tolerance_m = 0.009 + 0.003 * farthest_m;
          const Drift d = compareTransforms(*stored[i], reg.transform, 5.0, tolerance_m);
          row.drift_mm = 1000 * d.max_displacement_m;
          if (d.moved) {
            result.warnings.push_back(tag + " " + u.config.name + ": the unit moved (" + std::to_string(row.drift_mm) +
                                      " mm); registered again");
            stored[i] = reg.transform;
          }
        }
        used[i] = *stored[i];
        row.registration_rms_mm = 1000 * reg.fitness_rms_m;
        row.truth_error_deg = rotationDifferenceDeg(used[i].linear(), u.true_pose.linear());
        row.truth_error_mm = 1000 * (used[i].translation() - u.true_pose.translation()).norm();

        log(tag + ": " + u.config.name + ": analysing " + u.sail);
        boat_clouds[i] = transformCloud(s.cloud, used[i]);
        AnalysisParams ap;
        ap.sections = sp;
        // The unit's beam: its footprint trims every edge by 1.5-4 cm here, which put the
        // main's narrow head 11 cm and the A2's 22 cm low.
        useScannerBeam(ap.outline, u.config.model);
        ap.outline.design_lengths_m = {u.design_sections.outline.luff_length_m, u.design_sections.outline.leech_length_m,
                                       u.design_sections.outline.foot_length_m};
        // The spars where this cloud has them: the registration is good to a couple of
        // centimetres, as much as the gap between the mast and the luff.
        std::vector<Spar> spars;
        for (const Spar& nominal : tunnelSpars()) {
          SparFitParams fp;
          fp.sensor_sigma_m = ap.sensor_sigma_m;
          const SparFit f = fitSpar(boat_clouds[i], nominal, fp);
          if (f.found)
            log(tag + ": " + u.config.name + ": " + nominal.name + " found " +
                std::to_string(static_cast<int>(std::lround(1000 * f.offset.norm()))) + " mm from its measured place");
          else
            log(tag + ": " + u.config.name + ": " + f.message + "; its measured place is used");
          spars.push_back(f.spar);
        }
        const double max_x = u.roi_ends_at_mast ? spars.front().base.x() : 1e9;
        // The whole scan loses its mixed pixels before the crop cuts off the surfaces
        // behind them (the main's head, seen against the A2, grew a fringe that put it 23 cm high).
        const Cloud roi =
            cropToSail(withoutMixedPixels(boat_clouds[i], ap), u.design_mesh, 0.1, 3 * ap.sensor_sigma_m, max_x, spars);
        writeCloud(cloud_dir + "/step" + std::to_string(step + 1) + "-" + u.sail_file + "-roi.ply", roi);
        try {
          analyses[i] = analyzeSail(roi, ap, progress);
        } catch (const std::exception& e) {
          // The scan and its registration are still stored; the crew sees why there are no sections.
          result.warnings.push_back(tag + " " + u.sail + ": analysis failed, scan stored without it: " + e.what());
        }
        if (!analyses[i]) {
          area_camber.emplace_back(meshArea(u.design_mesh), meanCamber(u.design_sections.sections));
          heights.push_back(u.design_mesh.vertices.empty() ? 0 : meanZ(u.design_mesh.vertices));
          continue;
        }
        const SailAnalysis& a = *analyses[i];
        row.analysed = true;
        row.sail_points = a.sail_points;
        comparisons[i] = compareWithDesign(u.design_mesh, u.design_sections.sections, a.sail_cloud.points, a.sections, progress);
        row.deviation_rms_mm = 1000 * comparisons[i].stats.rms_m;
        area_camber.emplace_back(meshArea(a.mesh), meanCamber(a.sections));
        heights.push_back(a.sail_cloud.points.empty() ? 0 : meanZ(a.sail_cloud.points));
      }

      const double awa_deg = 110;
      const Forces forces = simulatedForces(area_camber, awa_deg, heights);
      log(tag + ": storing in " + result.database);
      for (size_t i = 0; i < rig.size(); ++i) {
        const RigUnit& u = rig[i];
        ImportMetadata m;
        m.campaign = "sailshape demo (emulated wind tunnel)";
        m.campaign_kind = "wind_tunnel";
        m.session = session;
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
        m.settings["sweep"] = {{"scans", sweeps[i].scans},
                               {"beams", sweeps[i].beams},
                               {"partial", sweeps[i].partial},
                               {"start_spread_ms", rows[i].start_spread_ms}};
        m.raw_capture = capturePath(capture_dir, step, u);
        const json doc = analyses[i] ? analysisToJson(*analyses[i]) : json();
        const ImportResult r = importScan(db, m, analyses[i] ? &doc : nullptr, &boat_clouds[i]);
        addRegistration(db, r.scan_id, used[i].matrix(), registrations[i].fitness_rms_m, registrations[i].fitness_rms_m);
        rows[i].scan_id = r.scan_id;
        result.scans.push_back(rows[i]);
        if (!analyses[i]) continue;
        json details = json::array();
        for (const SectionDelta& d : comparisons[i].sections)
          details.push_back({{"fraction", d.fraction},
                             {"design", sectionParametersToJson(d.design)},
                             {"flying", sectionParametersToJson(d.flying)},
                             {"delta", sectionParametersToJson(d.delta)}});
        addDesignComparison(db, r.analysis_id, u.sail, comparisons[i].stats, json{{"sections", details}});
        for (const SectionDelta& d : comparisons[i].sections)
          result.sections.push_back({u.sail, step + 1, d.fraction, d.flying.camber_pct, d.flying.draft_pct,
                                     d.flying.twist_deg, d.delta.camber_pct, d.delta.draft_pct, d.delta.twist_deg});
        for (const std::string& w : analyses[i]->warnings) result.warnings.push_back(tag + " " + u.sail + ": " + w);
      }
    }
  }

  for (const RigUnit& u : rig) {
    log("report: " + u.sail);
    TrimReportParams rp;
    rp.db_path = result.database;
    rp.test = kTest;
    rp.sail = u.sail;
    rp.audience = "designer";
    rp.out_path = (fs::path(o.dir) / ("report-" + u.sail_file + ".pdf")).string();
    try {
      const TrimReport report = writeTrimReport(rp, progress);
      result.reports.push_back(report.out_path);
      for (const std::string& w : report.content.warnings) result.warnings.push_back("report " + u.sail + ": " + w);
    } catch (const InvalidInput& e) {
      // A sail none of whose steps could be analysed has no sections to report.
      result.warnings.push_back("no report for " + u.sail + ": " + e.what());
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace sailshape::cli
