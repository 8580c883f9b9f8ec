// `sailshape scanner calibrate`: the unit's p and θ by least squares from sweeps of known shapes.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "acquisition/calibration.hpp"
#include "acquisition/sweep_io.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"

namespace sailshape::cli {
namespace {

struct CalibrateOptions {
  std::vector<std::string> planes;
  std::vector<std::string> cylinders;
  std::vector<double> radii;
  std::string unit;
  double p0 = 0.05, theta0_deg = 0;
  bool p0_set = false, theta0_set = false;
  std::string json;
  std::string write_unit;
  std::vector<std::string> spans;
};

// "FILE" or "FILE@xmin,xmax,ymin,ymax,zmin,zmax": samples kept inside the box (unit frame, metres, under the
// initial p and θ).
CalibrationTarget loadTarget(const std::string& spec, double p0, double theta0) {
  CalibrationTarget t;
  const auto at = spec.find('@');
  const std::string file = spec.substr(0, at);
  t.name = file;
  std::vector<SweepPoint> samples = readSweepSamples(file);
  if (at == std::string::npos) {
    t.samples = std::move(samples);
    return t;
  }
  std::vector<double> box;
  std::stringstream ss(spec.substr(at + 1));
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      box.push_back(std::stod(item));
    } catch (const std::exception&) {
      box.clear();
      break;
    }
  }
  if (box.size() != 6 || box[0] >= box[1] || box[2] >= box[3] || box[4] >= box[5])
    throw InvalidInput("[scanner calibrate] '" + spec + "': the crop box must be @xmin,xmax,ymin,ymax,zmin,zmax with min < max");
  for (const SweepPoint& s : samples) {
    const Vec3 x = unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p0, theta0);
    if (x.x() >= box[0] && x.x() <= box[1] && x.y() >= box[2] && x.y() <= box[3] && x.z() >= box[4] && x.z() <= box[5])
      t.samples.push_back(s);
  }
  return t;
}

// "A[@box]:B[@box]=DISTANCE": two parallel faces a known distance apart, their points in the unit frame under p, θ.
KnownSpan loadSpan(const std::string& spec, double p, double theta) {
  const auto eq = spec.rfind('=');
  const auto comma = spec.find(':');
  double distance = 0;
  try {
    if (eq != std::string::npos) distance = std::stod(spec.substr(eq + 1));
  } catch (const std::exception&) {
    distance = 0;
  }
  if (eq == std::string::npos || comma == std::string::npos || comma > eq || !(distance > 0))
    throw InvalidInput("[scanner calibrate] '" + spec + "': a span is FACE_A:FACE_B=DISTANCE_M (each face a samples file, "
                       "optionally @box) with a distance > 0");
  KnownSpan span;
  span.name = spec;
  span.distance_m = distance;
  for (int side = 0; side < 2; ++side) {
    const std::string face = side == 0 ? spec.substr(0, comma) : spec.substr(comma + 1, eq - comma - 1);
    for (const SweepPoint& s : loadTarget(face, p, theta).samples)
      (side == 0 ? span.face_a : span.face_b).push_back(unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta));
  }
  return span;
}

void run(const CalibrateOptions& o) {
  if (o.planes.empty() && o.cylinders.empty() && o.spans.empty())
    throw InvalidInput("[scanner calibrate] give at least one --plane, --cylinder or --span");
  if (o.radii.size() != o.cylinders.size())
    throw InvalidInput("[scanner calibrate] every --cylinder needs its --radius (got " + std::to_string(o.cylinders.size()) +
                       " cylinders and " + std::to_string(o.radii.size()) + " radii)");
  UnitConfig unit;
  CalibrationParams params;
  if (!o.unit.empty()) {
    unit = readUnitFile(o.unit);
    if (unit.p_m > 0) params.initial_p_m = unit.p_m;
    params.initial_theta_rad = unit.theta_rad;
  }
  if (o.p0_set) params.initial_p_m = o.p0;
  if (o.theta0_set) params.initial_theta_rad = o.theta0_deg * kRadPerDeg;
  std::vector<CalibrationTarget> targets;
  for (const std::string& p : o.planes) targets.push_back(loadTarget(p, params.initial_p_m, params.initial_theta_rad));
  for (size_t i = 0; i < o.cylinders.size(); ++i) {
    CalibrationTarget t = loadTarget(o.cylinders[i], params.initial_p_m, params.initial_theta_rad);
    t.kind = CalibrationTarget::Kind::Cylinder;
    t.radius_m = o.radii[i];
    targets.push_back(std::move(t));
  }
  CalibrationResult r;
  r.p_m = params.initial_p_m;
  r.theta_rad = params.initial_theta_rad;
  if (!targets.empty()) r = calibrateUnit(targets, params);
  nlohmann::json scale_doc;
  if (!o.spans.empty()) {
    std::vector<KnownSpan> spans;
    for (const std::string& sp : o.spans) spans.push_back(loadSpan(sp, r.p_m, r.theta_rad));
    const RangeScaleFit k = fitRangeScale(spans);
    std::printf("range scale %.5f ± %.5f (systematic range error %+.3f %%), residual %.2f mm over %zu spans\n",
                k.scale, k.scale_stderr, 100 * (k.scale - 1), 1000 * k.residual_rms_m, spans.size());
    for (size_t i = 0; i < spans.size(); ++i)
      std::printf("  %-40s measured %.4f m, true %.4f m, corrected %.4f m\n", spans[i].name.c_str(), k.measured_m[i],
                  spans[i].distance_m, k.measured_m[i] / k.scale);
    scale_doc = {{"range_scale", k.scale}, {"range_scale_stderr", k.scale_stderr}, {"residual_rms_m", k.residual_rms_m},
                 {"measured_m", k.measured_m}};
    if (k.residual_rms_m > 2 * params.sensor_sigma_m)
      r.warnings.push_back("the spans disagree by " + std::to_string(1000 * k.residual_rms_m) +
                           " mm RMS after the scale, beyond the sensor's noise: a face or a distance is wrong");
  }
  if (targets.empty()) {
    for (const std::string& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (!o.json.empty()) writeJsonFile(o.json, scale_doc);
    return;
  }
  std::printf("p = %.2f mm ± %.2f mm, theta = %.3f deg ± %.3f deg (%s after %d iterations)\n", r.p_m * 1000,
              r.p_stderr_m * 1000, r.theta_rad / kRadPerDeg, r.theta_stderr_rad / kRadPerDeg,
              r.converged ? "converged" : "NOT converged", r.iterations);
  std::printf("%-40s %8s %8s %10s %10s\n", "target", "points", "dropped", "rms mm", "max mm");
  for (const CalibrationTargetResult& t : r.targets)
    std::printf("%-40s %8zu %8zu %10.2f %10.2f\n", t.name.c_str(), t.points, t.outliers, t.rms_m * 1000,
                t.max_abs_m * 1000);
  for (const std::string& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!o.json.empty()) {
    nlohmann::json doc{{"p_m", r.p_m},
                       {"theta_deg", r.theta_rad / kRadPerDeg},
                       {"p_stderr_m", r.p_stderr_m},
                       {"theta_stderr_deg", r.theta_stderr_rad / kRadPerDeg},
                       {"rms_m", r.rms_m},
                       {"converged", r.converged},
                       {"iterations", r.iterations},
                       {"warnings", r.warnings},
                       {"plausible", r.plausible},
                       {"targets", nlohmann::json::array()}};
    for (const CalibrationTargetResult& t : r.targets)
      doc["targets"].push_back({{"name", t.name}, {"points", t.points}, {"dropped", t.outliers}, {"rms_m", t.rms_m},
                                {"max_abs_m", t.max_abs_m}});
    if (!scale_doc.is_null()) doc["range_scale"] = scale_doc;
    writeJsonFile(o.json, doc);
  }
  if (!r.plausible)
    throw AnalysisError("[scanner calibrate] the fit is implausible: a target's residual is far above the sensor's noise "
                        "(see the table); no unit file written");
  if (!o.write_unit.empty()) {
    if (std::filesystem::exists(o.write_unit))
      throw FileError("[scanner calibrate] " + o.write_unit + " exists already; not overwritten");
    unit.p_m = r.p_m;
    unit.theta_rad = r.theta_rad;
    writeJsonFile(o.write_unit, nlohmann::json::parse(unitToJson(unit)));
    std::fprintf(stderr, "wrote %s\n", o.write_unit.c_str());
  }
}

}  // namespace

void addScannerCommand(CLI::App& app) {
  CLI::App* scanner = app.add_subcommand(
      "scanner", "Scanner unit maintenance: calibrate a unit's p and θ from sweeps of known shapes\n\n"
                 "Its command calibrate fits p and θ (SPEC §2) by least squares to sweeps of planes, and of "
                 "cylinders of known radius.");
  scanner->require_subcommand(1);
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = scanner->add_subcommand(
      "calibrate",
      "Estimate a unit's geometric constants p and θ from sweeps of known shapes\n\n"
      "Estimate the unit's geometric constants p and θ (SPEC §2) by least squares from sweeps of known shapes: "
      "planes of unknown position (a tunnel wall, the floor) and optionally cylinders of known radius. Two planes "
      "at an angle, seen over a wide β range, determine θ best; standard errors and a warning show a weak set-up.");
  cmd->add_option("--plane", o->planes,
                  "Samples of a plane: NAME.samples.csv as `sailshape scan` writes it, optionally "
                  "@xmin,xmax,ymin,ymax,zmin,zmax to keep only samples in that box (unit frame, metres, under the "
                  "initial p and θ); repeat for several planes");
  cmd->add_option("--cylinder", o->cylinders, "Samples of a cylinder (same form as --plane); repeat as needed");
  cmd->add_option("--radius", o->radii, "Radius in metres of each --cylinder, in the same order");
  cmd->add_option("--unit", o->unit, "Unit file: its p and θ are the starting guess and --write-unit starts from it")
      ->check(CLI::ExistingFile);
  cmd->add_option("--p0", o->p0, "Starting p in metres (> 0; default 0.05 or the unit's)")
      ->check(CLI::PositiveNumber)
      ->each([o](const std::string&) { o->p0_set = true; });
  cmd->add_option("--theta0", o->theta0_deg, "Starting θ in degrees (default 0 or the unit's)")
      ->each([o](const std::string&) { o->theta0_set = true; });
  cmd->add_option("--span", o->spans,
                  "Two parallel faces a known distance apart, FACE_A:FACE_B=METRES (each face a samples file, "
                  "optionally @box): the tunnel's width or height, opposite faces of a reference cube. Fits the range "
                  "scale (systematic range error, SPEC §3) and reports it with its residual; repeat for several spans");
  cmd->add_option("--json", o->json, "Write the result (p_m, theta_deg, standard errors, per-target residuals) as JSON");
  cmd->add_option("--write-unit", o->write_unit,
                  "Write the unit file (from --unit, or defaults) with the calibrated p and θ to this new path");
  cmd->callback([o] { run(*o); });
}

}  // namespace sailshape::cli
