// `sailshape analyze`: the analysis pipeline on one cloud.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "acquisition/sensor_model.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/design_prior.hpp"
#include "analysis/pipeline/params_io.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"
#include "cli/sail_design.hpp"

namespace sailshape::cli {
namespace {

struct AnalyzeOptions {
  std::string input;
  int sections = 0;
  std::vector<double> at;
  std::string plane;
  std::string json_out, mesh_out, params_file, cloud_out, fitted_out;
  bool print_params = false, describe_params = false, no_segment = false, quiet = false, sky = false;
  int corners = -1;
  std::string scanner;  // lms111 / lms511: its beam footprint for the edges
  std::vector<double> viewpoint;  // x, y, z of the scanner, m, for a cloud without one
  std::string design;             // the sail's design: crop to its region, pick its cluster, check the match
  double margin = 0;
  bool margin_given = false;      // otherwise the design's plausible trim deviation
};

void printTable(const SailAnalysis& a) {
  const SailOutline& o = a.outline;
  const SailOutline::Uncertainty& u = o.uncertainty;
  std::printf("Sail: %zu of %zu points, %zu triangles, area %.2f ± %.2f m2\n", a.sail_points, a.points_in,
              a.mesh.triangles.size(), o.area_m2, u.area_m2);
  if (a.working_voxel_m > 0)
    std::printf("  analysed as %zu points, one per %.1f cm column of the sail (working_voxel_sigmas)\n", a.working_points, 100 * a.working_voxel_m);
  // With the design fitted in, a corner the scan did not reach is the fitted design's.
  const bool fitted = a.design_fit.has_value();
  auto corner = [fitted](const char* name, const Vec3& p, double sigma_m, bool reached) {
    std::printf("  %-5s (%8.3f, %8.3f, %8.3f) m ± %.1f cm%s\n", name, p.x(), p.y(), p.z(), 100 * sigma_m,
                fitted && !reached ? "  (not scanned: the fitted design's)" : "");
  };
  const SailOutline::Coverage& cov = o.coverage;
  corner("tack", o.tack, u.tack_m, cov.known && cov.tack);
  corner("clew", o.clew, u.clew_m, cov.known && cov.clew);
  corner("head", o.head, u.head_m, cov.known && cov.head);
  if (o.has_peak) corner("peak", o.peak, u.peak_m, cov.known && cov.peak);
  std::printf("  luff %.3f ± %.3f m, leech %.3f ± %.3f m, foot %.3f ± %.3f m", o.luff_length_m, u.luff_length_m,
              o.leech_length_m, u.leech_length_m, o.foot_length_m, u.foot_length_m);
  if (o.has_peak) std::printf(", top %.3f ± %.3f m", o.top_length_m, u.top_length_m);
  if (o.footprint_reach_m > 0)
    std::printf("\n  edges moved out by the beam's footprint, %.1f cm along luff and leech", 100 * o.footprint_reach_m);
  if (cov.known && !fitted) {
    std::printf("\n  scanned to the sail's edge along %.0f %% of the luff, %.0f %% of the leech, %.0f %% of the foot",
                100 * cov.luff, 100 * cov.leech, 100 * cov.foot);
    if (o.has_peak) std::printf(", %.0f %% of the top", 100 * cov.top);
  } else if (!fitted) {
    std::printf("\n  where the scan reached the sail's edges is not known: no scanner position (--viewpoint), and the "
                "samples' density did not tell it");
  }
  const LuffCurve& l = a.luff;
  std::printf("\n  luff curve: LUFA sag %.1f ± %.1f mm at %.0f ± %.0f %%, LUSW sag %.1f ± %.1f mm at %.0f ± %.0f %%\n\n",
              1000 * l.lufa_sag_m, 1000 * l.uncertainty.lufa_sag_m, l.lufa_position_pct, l.uncertainty.lufa_position_pct,
              1000 * l.lusw_sag_m, 1000 * l.uncertainty.lusw_sag_m, l.lusw_position_pct, l.uncertainty.lusw_position_pct);
  if (fitted) {
    const DesignFit& f = *a.design_fit;
    std::printf("  design fitted to the scan: %.0f %% of its area within %.0f mm of a sample, RMS to them %.1f mm; "
                "the scan alone: %s\n",
                100 * f.coverage, 1000 * f.support_radius_m, 1000 * f.rms_m, a.inferred_because.c_str());
  }
  std::printf("%8s %9s %14s %14s %14s %14s %13s %13s%s\n", "height", "chord m", "camber %", "draft %", "twist deg",
              "twist rel", "entry deg", "exit deg", fitted ? "  inferred" : "");
  // Measured and unmeasured sections in height order.
  const auto& measured = a.sections.sections;
  const auto& unmeasured = a.sections.unmeasured;
  for (size_t i = 0, j = 0; i < measured.size() || j < unmeasured.size();) {
    if (j < unmeasured.size() && (i == measured.size() || unmeasured[j].fraction < measured[i].fraction)) {
      std::printf("%7.0f%% not measured: %s\n", 100 * unmeasured[j].fraction, unmeasured[j].reason.c_str());
      ++j;
      continue;
    }
    const Section& s = measured[i++];
    const SectionParameters &v = s.value, &u = s.uncertainty;
    // "value ± σ" in `width` characters; a value the section could not measure is a dash (the warnings say why).
    auto cell = [](double value, double sd, int width, int digits) {
      char buf[64];
      if (std::isfinite(value))
        std::snprintf(buf, sizeof(buf), "%*.*f ±%*.*f", width - 8, digits, value, 5, digits, sd);
      else
        return std::string(width - 9, ' ') + "—" + std::string(8, ' ');  // "—" is one column, three bytes
      return std::string(buf);
    };
    std::printf("%7.0f%% %9.3f %s %s %s %s %s %s", 100 * s.fraction, v.chord_m,
                cell(v.camber_pct, u.camber_pct, 14, 2).c_str(), cell(v.draft_pct, u.draft_pct, 14, 1).c_str(),
                cell(v.twist_deg, u.twist_deg, 14, 2).c_str(), cell(v.twist_rel_deg, u.twist_rel_deg, 14, 2).c_str(),
                cell(v.entry_deg, u.entry_deg, 13, 1).c_str(), cell(v.exit_deg, u.exit_deg, 13, 1).c_str());
    if (fitted) std::printf("  %7.0f %%", s.inferred_pct);
    std::printf("\n");
  }
  if (!a.warnings.empty()) {
    std::printf("\nWarnings:\n");
    for (const auto& w : a.warnings) std::printf("  %s\n", w.c_str());
  }
}

void run(const AnalyzeOptions& o) {
  AnalysisParams params = o.params_file.empty() ? AnalysisParams{} : loadParams(o.params_file);
  if (o.sections > 0) {
    params.sections.count = o.sections;
    params.sections.fractions.clear();
  }
  if (!o.at.empty()) params.sections.fractions = o.at;
  if (!o.plane.empty()) params.sections.plane = o.plane;
  if (o.no_segment) params.segment = false;
  if (o.corners >= 0) params.outline.corners = o.corners;
  if (!o.scanner.empty()) useScannerBeam(params.outline, parseScannerModel(o.scanner));
  if (o.sky) params.outline.edges_against_sky = true;
  if (o.print_params) {
    std::cout << paramsToJson(params).dump(2) << "\n";
    return;
  }
  if (o.describe_params) {
    std::cout << describeParams(params);
    return;
  }
  if (o.input.empty()) throw InvalidInput("analyze: an INPUT cloud file is required");

  ProgressBar bar(!o.quiet);
  CloudReadResult read = readCloud(o.input);
  for (const auto& w : read.warnings) std::fprintf(stderr, "warning: %s: %s\n", o.input.c_str(), w.c_str());
  if (!o.viewpoint.empty()) read.cloud.viewpoint = Vec3(o.viewpoint[0], o.viewpoint[1], o.viewpoint[2]);
  std::optional<DesignFile> design;
  std::optional<DesignCheck> check;
  RegionBox region;
  if (!o.design.empty()) {
    design = readDesignFile(o.design, "auto", "auto", params.sections);
    const Mesh& mesh = design->design.mesh;
    region = designRegion(mesh, o.margin_given ? o.margin : plausibleTrimDeviationM(mesh));
  } else if (o.margin_given) {
    throw InvalidInput("analyze: --margin applies with --design only");
  }
  if (!o.fitted_out.empty() && !design) throw InvalidInput("analyze: --fitted applies with --design only");
  SailAnalysis a = design ? analyzeWithDesign(read.cloud, region, design->design.mesh, design->sections, params, bar.progress())
                          : analyzeSail(read.cloud, params, bar.progress());
  bar.finish();
  if (design) check = checkAgainstDesign(design->design.mesh, design->sections, a);
  if (!o.mesh_out.empty()) writeMesh(o.mesh_out, a.mesh);
  if (!o.fitted_out.empty()) {
    if (!a.design_fit) throw AnalysisError("analyze: --fitted: the scan gave the sections alone, no design was fitted");
    writeMesh(o.fitted_out, a.design_fit->fitted);
  }
  if (!o.cloud_out.empty()) writeCloud(o.cloud_out, a.sail_cloud);
  if (!o.json_out.empty()) {
    nlohmann::json doc = analysisToJson(a);
    doc["input"] = o.input;
    doc["parameters"] = paramsToJson(params);
    if (design) {
      const DistanceStats& st = check->comparison.stats;
      doc["design"] = {{"file", o.design},
                       {"region_m", formatRegionBox(region)},
                       {"deviation_mean_m", st.mean_m},
                       {"deviation_rms_m", st.rms_m},
                       {"mismatch", check->mismatch}};
      // Whether the design stood in for what the scan did not reach, and how well it fits.
      if (a.design_fit) {
        const DesignFit& f = *a.design_fit;
        doc["design"]["fit"] = {{"because", a.inferred_because}, {"coverage", f.coverage},
                                {"support_radius_m", f.support_radius_m}, {"rms_m", f.rms_m},
                                {"noise_m", f.noise_m}, {"samples", f.samples}, {"samples_used", f.samples_used},
                                {"warnings", f.warnings}};
      } else {
        doc["design"]["fit"] = nullptr;
      }
    }
    writeJsonFile(o.json_out, doc);
    if (!o.quiet) std::fprintf(stderr, "wrote %s\n", o.json_out.c_str());
  } else {
    printTable(a);
    if (design)
      std::printf("\nDesign %s: region %s m; deviation from it mean %+.1f mm, RMS %.1f mm\n", o.design.c_str(),
                  formatRegionBox(region).c_str(), 1000 * check->comparison.stats.mean_m,
                  1000 * check->comparison.stats.rms_m);
  }
}

}  // namespace

void addAnalyzeCommand(CLI::App& app) {
  auto opt = std::make_shared<AnalyzeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "analyze",
      "Measure a flying sail from a cloud: its outline and sections (camber, draft, twist)\n\n"
      "Analyse a cloud of a flying sail (alone or in a scene with mast, boom and deck, in the boat frame): "
      "segment it, clean and smooth it, build its surface, find corners and edges, and cut sections with "
      "camber, draft, twist, entry and exit angles, each with its uncertainty. A scan that carries its samples' "
      "scan angles and the scanner's position (sailshape's own) first loses its mixed pixels (a beam straddling "
      "an edge returns a range between the sail and what lies behind it); see mixed_pixels in --print-params.");
  cmd->add_option("INPUT", opt->input, "Cloud file: .ply (ascii/binary), .pcd, .xyz/.txt or .csv, metres");
  cmd->add_option("--sections", opt->sections, "Number of sections N, at t = k/(N+1) of luff and leech (default 3)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--at", opt->at, "Explicit section fractions, comma separated, e.g. 0.25,0.5,0.75")
      ->delimiter(',')
      ->excludes("--sections");
  cmd->add_option("--plane", opt->plane,
                  "Section plane: normal (holds the surface normal at maximum camber; default), perpendicular "
                  "(to the corners' plane) or horizontal (z = const through the luff point)")
      ->check(CLI::IsMember({"normal", "perpendicular", "horizontal"}));
  cmd->add_option("--json", opt->json_out, "Write the full result as JSON to this file instead of the table");
  cmd->add_option("--mesh", opt->mesh_out, "Write the reconstructed sail surface (.ply, .obj or .stl)");
  cmd->add_option("--sail-cloud", opt->cloud_out, "Write the segmented, cleaned and smoothed sail points (one per voxel at a working resolution)");
  cmd->add_option("--params", opt->params_file, "Pipeline parameters file (.json, .yaml or .yml); see --print-params");
  cmd->add_option("--corners", opt->corners, "Corners of the sail: 3, 4 (square top) or 0 for automatic")
      ->check(CLI::IsMember({0, 3, 4}));
  cmd->add_option("--scanner", opt->scanner,
                  "The scanner that measured the cloud (lms111 or lms511): a return comes off the sail only while "
                  "its whole beam footprint lies on it, so the samples stop short of every edge by the footprint's "
                  "reach (exit diameter/2 + range x divergence/2); the edges and corners are moved out by it. Needs "
                  "the scanner's position: the cloud's viewpoint (PLY/PCD header, as sailshape's scans write it). "
                  "Sets outline.beam_exit_diameter_m and beam_divergence_rad (see --print-params). In a wind tunnel "
                  "(walls behind the sail); for a scan on the water see --sky. Its range (20 or 80 m, "
                  "outline.scanner_max_range_m) tells a scan cut short by range from the sail's edge")
      ->check(CLI::IsMember({"lms111", "lms511"}, CLI::ignore_case));
  cmd->add_flag("--sky", opt->sky,
                "Nothing but open sky lies behind the sail's edges (a scan on the water): a beam straddling an edge "
                "returns from the sail alone while enough of it lies there, so the samples reach the edges and "
                "--scanner's footprint moves nothing. Sets outline.edges_against_sky");
  cmd->add_option("--viewpoint", opt->viewpoint,
                  "Where the scanner stood, X,Y,Z in metres in the cloud's frame, for a cloud that does not carry it "
                  "(a plain XYZ file; sailshape's own scans do): from it, a boundary the beams met at grazing "
                  "incidence or at the end of their range is told apart from the sail's edge, and a corner the scan "
                  "never reached is refused rather than placed where the samples stop. Overrides the file's. "
                  "Without it (and without one in the file) the position is estimated from how the samples' density "
                  "falls with range and obliquity (the warnings give it with its ±; estimate_viewpoint in "
                  "--print-params turns that off)")
      ->expected(3)
      ->delimiter(',');
  cmd->add_option("--design", opt->design,
                  "The sail's design (.dxf, .obj, .stl, .ply, as `design show` reads): the scan (a whole tunnel or "
                  "deck) is cropped to the design's box grown by --margin, segmentation takes the cluster that lies "
                  "nearest the design, and a sail that flies farther from it than any plausible trim (RMS deviation "
                  "beyond a fifth of the mean chord, area beyond ±20 %, an edge beyond ±10 %) is a warning. When the scan "
                  "alone gives no sections (it did not reach the head or a clew: out of range, at grazing angles), "
                  "or its luff or leech stops short of the design's by more than stretch and tension explain under a "
                  "foot as long as the design's (a plain cloud or a crop that missed the head), the design is fitted "
                  "onto the sail's samples (as `sailshape fit`): the corners the scan did not reach are the fitted "
                  "design's, a section the scan spans between its own edges is measured on it, the others are cut on "
                  "the fitted surface and say how much of them was inferred, their σ carrying the fit's");
  cmd->add_option("--fitted", opt->fitted_out,
                  "With --design, when the design was fitted in: write the fitted design (.ply, .obj or .stl), its "
                  "vertices and triangles in the design's order");
  auto* margin = cmd->add_option("--margin", opt->margin,
                                 "With --design: metres added to every side of its box (default: a fifth of the "
                                 "design's mean chord, as far as a plausible trim moves the sail)");
  cmd->add_flag("--no-segment", opt->no_segment, "The input is the sail alone: skip segmentation");
  auto* print = cmd->add_flag("--print-params", opt->print_params,
                              "Print every pipeline parameter with its value as JSON (a --params file) and exit");
  cmd->add_flag("--describe-params", opt->describe_params,
                "Print every pipeline parameter, one a line: its key (as --params files nest it), value, unit and "
                "what it does; and exit")
      ->excludes(print);
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress output");
  cmd->callback([opt, margin] {
    opt->margin_given = margin->count() > 0;
    run(*opt);
  });
}

}  // namespace sailshape::cli
