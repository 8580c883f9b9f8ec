#include "tests/support/realistic_judge.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/pipeline/pipeline.hpp"

namespace sailshape::realistic {
namespace {

using nlohmann::json;

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

Verdict verdictFor(double error, double sigma, double target) {
  if (!std::isfinite(error)) return Verdict::Wrong;
  if (error <= target) return Verdict::Within;
  if (std::isfinite(sigma) && error <= 3 * sigma + target) return Verdict::Honest;
  if (!std::isfinite(sigma) && sigma > 0) return Verdict::Honest;  // an infinite σ claims nothing
  return Verdict::Wrong;
}

namespace {

JudgedValue scalar(const std::string& name, double measured, double sigma, double truth, double target) {
  JudgedValue v;
  v.name = name;
  v.measured = measured;
  v.sigma = sigma;
  v.truth = truth;
  v.target = target;
  v.error = std::abs(measured - truth);
  v.verdict = verdictFor(v.error, sigma, target);
  return v;
}

JudgedValue corner(const std::string& name, const Vec3& measured, double sigma, const Vec3& truth, double target) {
  JudgedValue v;
  v.name = name;
  v.sigma = sigma;
  v.target = target;
  v.error = (measured - truth).norm();
  v.is_corner = true;
  v.measured_point = measured;
  v.truth_point = truth;
  v.verdict = verdictFor(v.error, sigma, target);
  return v;
}

JudgedValue refused(const std::string& name, double truth, double target, const std::string& reason) {
  JudgedValue v;
  v.name = name;
  v.truth = truth;
  v.target = target;
  v.verdict = Verdict::Refused;
  v.reason = reason;
  return v;
}

std::string at(const char* what, double f) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%s@%.2f", what, f);
  return buf;
}


VariantResult analyse(const std::string& name, const Cloud& cloud, const Truth& truth, const SailDesign& design,
                      const Targets& tg, bool segment = true) {
  VariantResult r;
  r.variant = name;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    // As `sailshape analyze FILE` runs it: default parameters, the scene segmented first.
    AnalysisParams params;
    params.segment = segment;
    const SailAnalysis a = analyzeSail(cloud, params);
    r.seconds = seconds(t0);
    r.sail_points = a.sail_points;
    judgeAnalysis(&a, "", truth, design, tg, r);
  } catch (const std::runtime_error& e) {  // AnalysisError; InvalidInput for a scan that kept no point
    if (!dynamic_cast<const AnalysisError*>(&e) && !dynamic_cast<const InvalidInput*>(&e)) throw;
    r.seconds = seconds(t0);
    r.refused = true;
    r.refusal = e.what();
    judgeAnalysis(nullptr, r.refusal, truth, design, tg, r);
  }
  return r;
}

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

json designJson(const SailDesign& d) {
  json stations = json::array();
  for (const ProfileStation& s : d.stations)
    stations.push_back({{"fraction", s.fraction}, {"camber_pct", s.camber_pct}, {"draft_pct", s.draft_pct},
                        {"twist_deg", s.twist_deg}, {"entry_factor", s.entry_factor}, {"exit_factor", s.exit_factor}});
  // The keys of a SCENE.json "sail" object (acquisition/README.md), so the design can be rebuilt by hand.
  return {{"sail_type", sailTypeName(d.type)}, {"luff_m", d.luff_m},       {"leech_m", d.leech_m},
          {"foot_m", d.foot_m},                {"head_width_m", d.head_width_m}, {"tack", vec(d.tack)},
          {"rake_deg", d.rake_deg},            {"luff_round_m", d.luff_round_m}, {"luff_sag_m", d.luff_sag_m},
          {"leech_round_m", d.leech_round_m},  {"lean_deg", d.lean_deg},       {"leeward_port", d.leeward_port},
          {"stations", stations}};
}

}  // namespace

void judgeAnalysis(const SailAnalysis* a, const std::string& refusal, const Truth& truth, const SailDesign& design,
                   const Targets& tg, VariantResult& out) {
  const SailSurface surface(design);
  const char* names[] = {"camber_pct", "draft_pct", "twist_deg", "entry_deg", "exit_deg"};
  const double targets[] = {tg.camber_pct, tg.draft_pct, tg.twist_deg, tg.end_deg, tg.end_deg};
  std::vector<double> fractions(std::begin(kSectionFractions), std::end(kSectionFractions));
  if (!a) {
    for (double f : fractions)
      for (int k = 0; k < 5; ++k) out.values.push_back(refused(at(names[k], f), 0, targets[k], refusal));
    for (const char* c : {"tack_m", "clew_m", "head_m"}) out.values.push_back(refused(c, 0, tg.corner_m, refusal));
    if (truth.has_peak) out.values.push_back(refused("peak_m", 0, tg.corner_m, refusal));
    for (const char* l : {"luff_length_m", "leech_length_m", "foot_length_m"})
      out.values.push_back(refused(l, 0, tg.length_m, refusal));
    return;
  }
  for (const Section& s : a->sections.sections) {
    const KnownSection k = surface.section(s.fraction);
    const double measured[] = {s.value.camber_pct, s.value.draft_pct, s.value.twist_deg, s.value.entry_deg, s.value.exit_deg};
    const double sigma[] = {s.uncertainty.camber_pct, s.uncertainty.draft_pct, s.uncertainty.twist_deg,
                            s.uncertainty.entry_deg, s.uncertainty.exit_deg};
    const double known[] = {k.camber_pct, k.draft_pct, k.twist_deg, k.entry_deg, k.exit_deg};
    for (int i = 0; i < 5; ++i) {
      // A value the section names as not measured is no result; any other NaN is judged (wrong).
      const auto why = s.not_measured.find(names[i]);
      if (why != s.not_measured.end())
        out.values.push_back(refused(at(names[i], s.fraction), known[i], targets[i], why->second));
      else
        out.values.push_back(scalar(at(names[i], s.fraction), measured[i], sigma[i], known[i], targets[i]));
    }
  }
  for (const UnmeasuredSection& u : a->sections.unmeasured)
    for (int i = 0; i < 5; ++i) out.values.push_back(refused(at(names[i], u.fraction), 0, targets[i], u.reason));
  const SailOutline& o = a->outline;
  const SailOutline::Uncertainty& u = o.uncertainty;
  out.values.push_back(corner("tack_m", o.tack, u.tack_m, truth.tack, tg.corner_m));
  out.values.push_back(corner("clew_m", o.clew, u.clew_m, truth.clew, tg.corner_m));
  out.values.push_back(corner("head_m", o.head, u.head_m, truth.head, tg.corner_m));
  if (o.has_peak) out.values.push_back(corner("peak_m", o.peak, u.peak_m, truth.peak, tg.corner_m));
  else if (truth.has_peak) out.values.push_back(refused("peak_m", 0, tg.corner_m, "no fourth corner found"));
  out.values.push_back(scalar("luff_length_m", o.luff_length_m, u.luff_length_m, truth.luff_m, tg.length_m));
  // Without a peak the leech runs clew → head; the truth's leech then is clew → peak → head.
  const double leech_truth = truth.has_peak && !o.has_peak ? truth.leech_m + truth.top_m : truth.leech_m;
  out.values.push_back(scalar("leech_length_m", o.leech_length_m, u.leech_length_m, leech_truth, tg.length_m));
  out.values.push_back(scalar("foot_length_m", o.foot_length_m, u.foot_length_m, truth.foot_m, tg.length_m));
  if (o.has_peak && truth.has_peak)
    out.values.push_back(scalar("top_length_m", o.top_length_m, u.top_length_m, truth.top_m, tg.length_m));
}

std::string verdictName(Verdict v) {
  switch (v) {
    case Verdict::Within: return "within";
    case Verdict::Refused: return "refused";
    case Verdict::Honest: return "honest";
    case Verdict::Wrong: return "wrong";
  }
  return "?";
}

size_t VariantResult::count(Verdict v) const {
  size_t n = 0;
  for (const JudgedValue& j : values) n += j.verdict == v;
  return n;
}

size_t ConfigRun::count(Verdict v) const {
  size_t n = 0;
  for (const VariantResult& r : variants) n += r.count(v);
  return n;
}

ConfigRun runSeed(uint64_t seed, const RunOptions& options) { return runConfig(drawConfig(seed), options); }

ConfigRun runConfig(const Config& config, const RunOptions& options) {
  ConfigRun run;
  run.config = config;
  run.truth = truthOf(config.design);
  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene = buildScene(config);
  const Scan scan = sweepScene(config, scene, options.threads);
  run.scan_seconds = seconds(t0);
  run.scan_points = scan.cloud.size();
  run.sail_hits = scan.sail_points();
  run.sail_beams = scan.sail_beams;
  const Cloud xyz = plainXyz(scan.cloud);
  if (!options.ply_dir.empty()) {
    const std::string stem = options.ply_dir + "/realistic_" + std::to_string(config.seed);
    writeCloud(stem + "_own.ply", scan.cloud, CloudFormat::PlyBinary);
    writeCloud(stem + "_xyz.ply", xyz, CloudFormat::PlyBinary);
    // The sail's own points (their beams' axes hit it): the segmentation's right answer, to tell its
    // failures from the outline's (`sailshape analyze --no-segment`).
    std::vector<uint32_t> on_sail;
    for (size_t i = 0; i < scan.object.size(); ++i)
      if (scan.object[i] == static_cast<int>(scan.sail_object)) on_sail.push_back(static_cast<uint32_t>(i));
    writeCloud(stem + "_sail.ply", selectPoints(scan.cloud, on_sail), CloudFormat::PlyBinary);
  }
  run.variants.push_back(analyse("own-scan", scan.cloud, run.truth, config.design, options.targets));
  run.variants.push_back(analyse("plain-xyz", xyz, run.truth, config.design, options.targets));
  if (options.even_control) {
    ScanSimulation sim;
    sim.points = std::max<size_t>(run.sail_hits, 20000);
    sim.noise_sigma_m = 0.004;
    sim.seed = config.seed;
    sim.viewpoint = config.unit.position;
    run.variants.push_back(analyse("even-control", sampleSail(config.design, sim), run.truth, config.design,
                                   options.targets, false));
  }
  return run;
}

std::string runToJson(const ConfigRun& run) {
  const Config& c = run.config;
  const Truth& t = run.truth;
  json truth_sections = json::array();
  for (const KnownSection& k : t.sections)
    truth_sections.push_back({{"fraction", k.fraction}, {"chord_m", k.chord_m}, {"camber_pct", k.camber_pct},
                              {"draft_pct", k.draft_pct}, {"twist_deg", k.twist_deg}, {"entry_deg", k.entry_deg},
                              {"exit_deg", k.exit_deg}, {"luff_point", vec(k.luff_point)},
                              {"leech_point", vec(k.leech_point)}});
  json variants = json::array();
  for (const VariantResult& r : run.variants) {
    json values = json::array();
    for (const JudgedValue& v : r.values) {
      json j = {{"name", v.name}, {"verdict", verdictName(v.verdict)}, {"target", v.target}};
      if (v.verdict == Verdict::Refused) j["reason"] = v.reason;
      else if (v.is_corner) j.update({{"measured", vec(v.measured_point)}, {"sigma", v.sigma}, {"truth", vec(v.truth_point)}, {"error", v.error}});
      else j.update({{"measured", v.measured}, {"sigma", v.sigma}, {"truth", v.truth}, {"error", v.error}});
      values.push_back(j);
    }
    variants.push_back({{"variant", r.variant}, {"refused", r.refused}, {"refusal", r.refusal},
                        {"seconds", r.seconds}, {"sail_points", r.sail_points}, {"values", values}});
  }
  const Boat& b = c.boat;
  const UnitSetup& u = c.unit;
  json doc = {
      {"seed", c.seed},
      {"summary", c.summary()},
      {"config",
       {{"sail", sailKindName(c.sail)},
        {"unit_place", unitPlaceName(c.place)},
        {"design", designJson(c.design)},
        {"boat",
         {{"mast_height_m", b.mast_height_m}, {"mast_radius_m", b.mast_radius_m}, {"mast_rake_rad", b.mast_rake_rad},
          {"stern_x_m", b.stern_x_m}, {"bow_x_m", b.bow_x_m}, {"half_beam_m", b.half_beam_m},
          {"boom_z_m", b.boom_z_m}, {"boom_end", vec(b.boom_end)}, {"stay_base", vec(b.stay_base)},
          {"stay_top", vec(b.stay_top)}, {"sprit_length_m", b.sprit_length_m}, {"pole", b.pole},
          {"pole_end", vec(b.pole_end)}, {"tunnel", b.tunnel}}},
        {"unit",
         {{"model", scannerModelName(u.model)}, {"position", vec(u.position)}, {"yaw_rad", u.yaw_rad},
          {"p_m", u.p_m}, {"theta_rad", u.theta_rad}, {"beta_start_deg", u.beta_start_deg},
          {"sweep_deg", u.sweep_deg}, {"line_step_deg", u.line_step_deg}, {"alpha_from_deg", u.alpha_from_deg},
          {"alpha_to_deg", u.alpha_to_deg}, {"resolution_deg", u.resolution_deg}}}}},
      {"scan",
       {{"points", run.scan_points}, {"sail_points", run.sail_hits}, {"seconds", run.scan_seconds},
        {"sail_beams",
         {{"valid", run.sail_beams[0]}, {"out_of_range", run.sail_beams[2]}, {"grazing", run.sail_beams[3]},
          {"edge_loss", run.sail_beams[4]}}}}},
      {"truth",
       {{"tack", vec(t.tack)}, {"clew", vec(t.clew)}, {"head", vec(t.head)}, {"peak", vec(t.peak)},
        {"has_peak", t.has_peak}, {"luff_m", t.luff_m}, {"leech_m", t.leech_m}, {"foot_m", t.foot_m},
        {"top_m", t.top_m}, {"sections", truth_sections}}},
      {"results", variants}};
  return doc.dump(2);
}

std::vector<std::string> wrongValues(const ConfigRun& run) {
  std::vector<std::string> out;
  for (const VariantResult& r : run.variants)
    for (const JudgedValue& v : r.values) {
      if (v.verdict != Verdict::Wrong) continue;
      char buf[400];
      const Vec3 &m = v.measured_point, &t = v.truth_point;
      char what[160];
      if (v.is_corner)
        std::snprintf(what, sizeof what, "at (%.3f, %.3f, %.3f), truth (%.3f, %.3f, %.3f)", m.x(), m.y(), m.z(), t.x(),
                      t.y(), t.z());
      else
        std::snprintf(what, sizeof what, "measured %.4g, truth %.4g", v.measured, v.truth);
      std::snprintf(buf, sizeof buf, "seed %llu (%s at %s, %s): %s %s, error %.4g, sigma %.3g",
                    static_cast<unsigned long long>(run.config.seed), sailKindName(run.config.sail).c_str(),
                    unitPlaceName(run.config.place).c_str(), r.variant.c_str(), v.name.c_str(), what, v.error, v.sigma);
      out.push_back(buf);
    }
  return out;
}

}  // namespace sailshape::realistic
