// `sailshape register`: bring one unit's cloud into another unit's frame or into
// the boat frame (SPEC §4 step 2, issue 5), store the 4×4 transform, reapply a
// stored one to later scans, and check a re-scan for drift.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/registration/boat_registration.hpp"
#include "analysis/registration/registration.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

struct RegisterOptions {
  std::string reference, moving, method = "planes", pairs, plane_hints, initial, boat_reference, transform;
  std::string out, apply, json_out, check;
  std::string icp = "point-to-plane";
  double crossed_radius_mm = 50, uncertainty_mm = 9, drift_radius_m = 5;
  bool no_refine = false, force = false, quiet = false;
};

nlohmann::json vec(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json statsJson(const NeighbourDistanceStats& s) {
  return {{"count", s.count},   {"mean_m", s.mean_m}, {"median_m", s.median_m}, {"p90_m", s.p90_m},
          {"max_m", s.max_m},   {"rms_m", s.rms_m},   {"bin_m", s.bin_m},       {"histogram", s.histogram}};
}

void describe(nlohmann::json& doc, const RigidTransform& t) {
  const Eigen::AngleAxisd aa(t.linear());
  doc["matrix"] = matrixJson(t.matrix());
  doc["rotation_deg"] = aa.angle() * kDegPerRad;
  doc["rotation_axis"] = vec(aa.axis());
  doc["translation_m"] = vec(t.translation());
}

void printSummary(const char* what, const RigidTransform& t) {
  const Eigen::AngleAxisd aa(t.linear());
  std::fprintf(stderr, "%s: rotation %.4f° about (%.4f, %.4f, %.4f), translation (%.4f, %.4f, %.4f) m\n", what,
               aa.angle() * kDegPerRad, aa.axis().x(), aa.axis().y(), aa.axis().z(), t.translation().x(),
               t.translation().y(), t.translation().z());
}

// `range_scale`: the source unit's, taken out before the transform (the boat
// registration fits it for the reference cloud; 1 for a moving cloud).
void writeApplied(const RegisterOptions& o, const std::string& source, const RigidTransform& t, double range_scale = 1) {
  const CloudReadResult in = readCloud(source);
  writeCloud(o.apply, toBoatFrame(in.cloud, t, range_scale));
  if (!o.quiet) std::fprintf(stderr, "wrote %s: %zu points of %s transformed\n", o.apply.c_str(), in.cloud.size(), source.c_str());
}

void validate(const RegisterOptions& o) {
  if (!o.transform.empty()) {
    if (o.moving.empty() || o.apply.empty())
      throw InvalidInput("[register] --transform reapplies a stored transform: it needs --moving and --apply");
    if (!o.reference.empty() || !o.boat_reference.empty())
      throw InvalidInput("[register] --transform reapplies a stored transform; it does not register (drop --reference "
                         "and --boat-reference)");
    return;
  }
  if (o.reference.empty()) throw InvalidInput("[register] --reference is required (or --transform to reapply one)");
  if (o.moving.empty() && o.boat_reference.empty())
    throw InvalidInput("[register] give --moving (unit to unit) or --boat-reference (reference cloud to boat frame)");
  if (!(o.crossed_radius_mm > 0) || !(o.uncertainty_mm > 0))
    throw InvalidInput("[register] --crossed-radius-mm and --uncertainty-mm must be > 0");
}

void run(const RegisterOptions& o) {
  validate(o);
  if (!o.transform.empty()) {
    const RigidTransform t = readTransform(o.transform);
    writeApplied(o, o.moving, t);
    return;
  }
  ProgressBar bar(!o.quiet);
  nlohmann::json doc;
  const Cloud reference = readCloud(o.reference).cloud;
  RigidTransform result = RigidTransform::Identity();  // what --out stores
  bool accepted = true;
  std::string why;
  double reference_range_scale = 1;  // taken out of the reference cloud by --apply (boat registration only)

  if (!o.moving.empty()) {
    const Cloud moving = readCloud(o.moving).cloud;
    RegistrationParams p;
    p.method = o.method;
    if (!o.pairs.empty()) p.pairs = readPointPairs(o.pairs);
    if (!o.plane_hints.empty()) p.plane_hints = readPointPairs(o.plane_hints);
    if (!o.initial.empty()) p.initial = readTransform(o.initial);
    p.icp.method = o.icp;
    p.refine = !o.no_refine;
    p.crossed_radius_m = o.crossed_radius_mm / 1000.0;
    p.uncertainty_m = o.uncertainty_mm / 1000.0;
    const Registration r = registerClouds(reference, moving, p, bar.progress());
    result = r.transform;
    doc["method"] = r.method;
    describe(doc, r.transform);
    doc["fitness_rms_m"] = r.fitness_rms_m;
    doc["inlier_fraction"] = r.inlier_fraction;
    doc["uncertainty_m"] = p.uncertainty_m;
    doc["below_uncertainty"] = r.below_uncertainty;
    doc["converged"] = r.converged;
    doc["ambiguous"] = r.ambiguous;
    doc["accepted"] = r.accepted;
    doc["icp_iterations"] = r.icp_iterations;
    doc["coarse_matrix"] = matrixJson(r.coarse.matrix());
    if (r.method == "planes") {
      nlohmann::json pl = {{"reference", r.reference_planes},
                           {"moving", r.moving_planes},
                           {"candidates", r.candidates},
                           {"poses_verified", r.poses_verified},
                           {"free_space_fraction", r.free_space_fraction},
                           {"log_likelihood_ratio", r.log_likelihood_ratio},
                           {"log_likelihood_ratio_needed", r.log_likelihood_ratio_needed},
                           {"moving_planes_on_reference", r.coarse_planes_on},
                           {"pairings", nlohmann::json::array()}};
      for (const PlanePairing& pp : r.pairings)
        pl["pairings"].push_back({{"reference_plane", pp.reference_plane},
                                  {"moving_plane", pp.moving_plane},
                                  {"reference_normal", vec(pp.reference_normal)},
                                  {"moving_normal", vec(pp.moving_normal)},
                                  {"reference_points", pp.reference_points},
                                  {"moving_points", pp.moving_points},
                                  {"angle_after_deg", pp.angle_after_deg}});
      doc["planes"] = pl;
    }
    doc["overlap"] = {{"reference_points", r.overlap_reference_points}, {"moving_points", r.overlap_moving_points},
                      {"crossed_radius_m", p.crossed_radius_m}};
    doc["distances_before_refinement"] = statsJson(r.before_refinement);
    doc["distances_after_refinement"] = statsJson(r.after_refinement);
    doc["warnings"] = r.warnings;
    accepted = r.accepted;
    if (!accepted)
      why = "fitness " + std::to_string(r.fitness_rms_m * 1000) + " mm, " +
            std::to_string(100 * r.inlier_fraction) + " % of the overlap within the uncertainty" +
            (r.converged ? "" : ", ICP not converged") + (r.ambiguous ? ", ambiguous plane match" : "");
    bar.finish();
    if (!o.quiet) {
      printSummary("moving → reference", r.transform);
      std::fprintf(stderr, "fitness %.2f mm RMS (%.1f %% of the overlap within %.1f mm), %s\n", r.fitness_rms_m * 1000,
                   100 * r.inlier_fraction, p.uncertainty_m * 1000, r.accepted ? "accepted" : "NOT accepted");
      std::fprintf(stderr, "overlap: median distance %.1f mm before refinement, %.1f mm after\n",
                   r.before_refinement.median_m * 1000, r.after_refinement.median_m * 1000);
      for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    }
  }

  if (!o.boat_reference.empty()) {
    const BoatReference boat = readBoatReference(o.boat_reference);
    BoatRegistrationParams bp;
    bp.uncertainty_m = o.uncertainty_mm / 1000.0;
    const BoatRegistration b = registerToBoat(reference, boat, bp, bar.progress());
    bar.finish();
    nlohmann::json bj = {{"reference", boat.name},
                         {"fitness_rms_m", b.fitness_rms_m},
                         {"below_uncertainty", b.below_uncertainty},
                         {"ambiguous", b.ambiguous},
                         {"range_scale", b.range_scale},
                         {"range_scale_sigma", b.range_scale_sigma},
                         {"accepted", b.accepted},
                         {"faces", nlohmann::json::array()},
                         {"warnings", b.warnings}};
    describe(bj, b.transform);
    for (const FaceMatch& f : b.faces)
      bj["faces"].push_back({{"face", f.face}, {"points", f.points}, {"rms_m", f.rms_m}, {"angle_deg", f.angle_deg}});
    doc["boat"] = bj;
    // moving → reference → boat, or the reference itself → boat.
    result = b.transform * result;
    if (o.moving.empty()) reference_range_scale = b.range_scale;
    if (!o.moving.empty()) describe(doc["moving_to_boat"], result);
    if (!b.accepted) {
      accepted = false;
      why += std::string(why.empty() ? "" : "; ") + "boat frame: faces " + std::to_string(b.fitness_rms_m * 1000) +
             " mm RMS off" + (b.ambiguous ? ", ambiguous (symmetric reference)" : "");
    }
    if (!o.quiet) {
      printSummary("reference → boat", b.transform);
      std::fprintf(stderr, "boat frame: %zu planes on faces of '%s', %.2f mm RMS, %s\n", b.faces.size(),
                   boat.name.c_str(), b.fitness_rms_m * 1000, b.accepted ? "accepted" : "NOT accepted");
      std::fprintf(stderr,
                   "range scale of the reference unit %.5f ± %.5f (systematic range error %+.3f %%), taken out before "
                   "the transform by --apply%s\n",
                   b.range_scale, b.range_scale_sigma, 100 * (b.range_scale - 1),
                   o.moving.empty() ? "" : " on the reference only (the moving unit's is not measured here)");
      for (const auto& w : b.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    }
  }

  if (!o.check.empty()) {
    const RigidTransform stored = readTransform(o.check);
    const Drift d = compareTransforms(stored, result, o.drift_radius_m, o.uncertainty_mm / 1000.0);
    doc["drift"] = {{"stored", o.check},
                    {"rotation_deg", d.rotation_deg},
                    {"translation_m", d.translation_m},
                    {"max_displacement_m", d.max_displacement_m},
                    {"radius_m", o.drift_radius_m},
                    {"moved", d.moved}};
    std::fprintf(stderr, "drift against %s: %.4f°, %.2f mm (up to %.2f mm within %.1f m): %s\n", o.check.c_str(),
                 d.rotation_deg, d.translation_m * 1000, d.max_displacement_m * 1000, o.drift_radius_m,
                 d.moved ? "the units MOVED — register again" : "unchanged");
  }

  doc["accepted"] = accepted;
  if (!o.json_out.empty()) {
    writeJsonFile(o.json_out, doc);
    if (!o.quiet) std::fprintf(stderr, "wrote %s\n", o.json_out.c_str());
  }
  if (!accepted && !o.force)
    throw AnalysisError("[register] registration not accepted (" + why +
                        "); no transform written — see the warnings, or --force to write it anyway");
  std::fputs(formatTransform(result).c_str(), stdout);
  if (!o.out.empty()) {
    writeTransform(o.out, result);
    if (!o.quiet) std::fprintf(stderr, "wrote %s\n", o.out.c_str());
  }
  if (!o.apply.empty()) writeApplied(o, o.moving.empty() ? o.reference : o.moving, result, reference_range_scale);
}

}  // namespace

void addRegisterCommand(CLI::App& app) {
  auto opt = std::make_shared<RegisterOptions>();
  CLI::App* cmd = app.add_subcommand(
      "register",
      "Register one unit's cloud into another unit's frame, or a cloud into the boat frame\n\n"
      "Register one unit's cloud into another unit's frame (--reference, --moving) and/or the reference cloud into "
      "the boat frame (--boat-reference). Prints the 4x4 transform (four lines of four numbers: x_ref = T x_moving) "
      "on stdout; fails without writing it when the fit is not below the sensor uncertainty.");
  cmd->add_option("--reference", opt->reference, "Cloud whose frame is the target (.ply, .pcd, .xyz, .csv)");
  cmd->add_option("--moving", opt->moving, "Cloud to bring into the reference frame");
  cmd->add_option("--method", opt->method,
                  "planes: three planes found in both clouds (walls, deck, a reference cube) give the rotation and "
                  "translation; svd: Kabsch from --pairs; icp: plain ICP from the raw pose (or --initial). All refine "
                  "with ICP on the overlap")
      ->check(CLI::IsMember({"planes", "svd", "icp"}))
      ->capture_default_str();
  cmd->add_option("--pairs", opt->pairs,
                  "Picked point pairs, one a line 'xm ym zm xr yr zr' (moving point, same point in the reference), "
                  "metres: svd needs 3 or more; planes takes 1 for the translation (then 2 planes suffice)");
  cmd->add_option("--plane-hints", opt->plane_hints,
                  "planes: one point on each plane to use, in both clouds, same format as --pairs (3 lines, or 2 "
                  "with --pairs); without it the planes are matched automatically");
  cmd->add_option("--initial", opt->initial, "icp: start from this stored 4x4 transform instead of the raw pose");
  cmd->add_option("--icp", opt->icp, "Refinement: point-to-plane or point-to-point")
      ->check(CLI::IsMember({"point-to-plane", "point-to-point"}))
      ->capture_default_str();
  cmd->add_flag("--no-refine", opt->no_refine, "Skip the ICP refinement (coarse alignment only)");
  cmd->add_option("--crossed-radius-mm", opt->crossed_radius_mm,
                  "Crossed filter: keep points with a point of the other cloud within this radius, mm")
      ->capture_default_str();
  cmd->add_option("--uncertainty-mm", opt->uncertainty_mm,
                  "Accept when the fit is below this, mm (σ + systematic error: 9 at model scale, 14 full scale)")
      ->capture_default_str();
  cmd->add_option("--boat-reference", opt->boat_reference,
                  "JSON file of faces known in boat coordinates (a cube on the deck, tunnel walls; see "
                  "analysis/registration/boat_registration.hpp): registers the reference cloud to the boat frame, fitting the "
                  "unit's range scale (its systematic range error) with the pose where faces of known separation fix it "
                  "(floor and ceiling, two side walls); --apply takes the scale out; with --moving the stored transform "
                  "maps the moving cloud into the boat frame");
  cmd->add_option("--out", opt->out, "Write the 4x4 transform here (four lines of four numbers)");
  cmd->add_option("--apply", opt->apply, "Write the moving cloud (or the reference, without --moving) transformed");
  cmd->add_option("--json", opt->json_out,
                  "Write the diagnostics: transform, fitness, planes matched, overlap, distance distributions before "
                  "and after refinement, drift, warnings");
  cmd->add_option("--transform", opt->transform,
                  "Reapply a stored transform to a later scan of the same session: with --moving and --apply, no "
                  "registration");
  cmd->add_option("--check", opt->check,
                  "Drift check: compare the new transform with this stored one (re-scan of the reference object)");
  cmd->add_option("--drift-radius-m", opt->drift_radius_m,
                  "Drift check: report the largest displacement of a point within this distance of the origin, m")
      ->capture_default_str();
  cmd->add_flag("--force", opt->force, "Write the transform even when the registration is not accepted");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress output or summary");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace sailshape::cli
