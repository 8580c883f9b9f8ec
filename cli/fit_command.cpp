// `sailshape fit`: the design deformed onto a flying scan (issue 37): the whole flying sail,
// where the scanner could not see it too, each design vertex where it flies.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/io/design_import.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/pipeline/params_io.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

struct FitOptions {
  std::string design, flying, out, json_out, unit = "auto", axes = "auto", params_file;
  bool no_segment = false, no_rigid = false, quiet = false;
  double noise_mm = 4.0, bending_m = DesignFitParams{}.bending_length_m, max_strain_pct = 5.0;
  int iterations = DesignFitParams{}.outer_iterations;
};

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

nlohmann::json strainJson(const StrainStats& s) {
  return {{"edges", s.edges},     {"mean_pct", s.mean_pct}, {"rms_pct", s.rms_pct}, {"p5_pct", s.p5_pct},
          {"p95_pct", s.p95_pct}, {"min_pct", s.min_pct},   {"max_pct", s.max_pct}};
}

nlohmann::json fitJson(const FitOptions& o, const DesignImport& design, const DesignFit& f, size_t flying_points,
                       size_t sail_points) {
  nlohmann::json doc;
  doc["design"] = {{"file", o.design}, {"format", design.format}, {"unit", design.unit}, {"axes", design.axes},
                   {"vertices", f.fitted.vertices.size()}, {"triangles", f.fitted.triangles.size()}};
  doc["flying"] = {{"file", o.flying}, {"points", flying_points}, {"sail_points", sail_points},
                   {"segmented", !o.no_segment}};
  doc["fitted"] = o.out;
  doc["rigid"] = {{"design_to_boat", matrixJson(f.rigid)}, {"rms_m", f.rigid_rms_m}};
  doc["coverage"] = f.coverage;
  doc["support_radius_m"] = f.support_radius_m;
  doc["rms_m"] = f.rms_m;
  doc["noise_m"] = f.noise_m;
  doc["samples_used"] = f.samples_used;
  doc["iterations"] = f.iterations;
  doc["strain"] = strainJson(f.strain);
  doc["strain_supported"] = strainJson(f.strain_supported);
  doc["max_plausible_strain_pct"] = o.max_strain_pct;
  // Per vertex, in the design's order: arrays side by side (a 20,000-vertex design is a few MB).
  nlohmann::json disp = nlohmann::json::array(), support = nlohmann::json::array(), sigma = nlohmann::json::array(),
                 supported = nlohmann::json::array();
  for (size_t v = 0; v < f.fitted.vertices.size(); ++v) {
    const Vec3& d = f.displacement_m[v];
    disp.push_back({d.x(), d.y(), d.z()});
    support.push_back(f.support_distance_m[v]);
    sigma.push_back(f.sigma_m[v]);
    supported.push_back(static_cast<bool>(f.supported[v]));
  }
  doc["vertices"] = {{"displacement_m", disp}, {"support_distance_m", support}, {"supported", supported},
                     {"sigma_m", sigma}};
  doc["edges"] = {{"vertices", f.edges}, {"strain_pct", f.edge_strain_pct}};
  doc["warnings"] = f.warnings;
  return doc;
}

void run(const FitOptions& o) {
  const std::string ext = lowerExtension(o.out);
  if (ext != ".ply" && ext != ".obj")
    throw InvalidInput("--out " + o.out + ": the fitted mesh is written as .ply or .obj (got '" + ext + "')");
  DesignImportOptions io;
  io.unit = o.unit;
  io.axes = o.axes;
  const DesignImport design = importDesign(o.design, io);
  CloudReadResult read = readCloud(o.flying);
  for (const auto& w : read.warnings) std::fprintf(stderr, "warning: %s: %s\n", o.flying.c_str(), w.c_str());
  if (read.cloud.empty()) throw InvalidInput(o.flying + " holds no points");
  AnalysisParams params = o.params_file.empty() ? AnalysisParams{} : loadParams(o.params_file);
  params.sensor_sigma_m = o.noise_mm / 1000.0;
  if (o.no_segment) params.segment = false;
  ProgressBar bar(!o.quiet);
  const Cloud sail = sailSamples(read.cloud, params, bar.progress());
  DesignFitParams fp;
  fp.sensor_sigma_m = params.sensor_sigma_m;
  fp.rigid = !o.no_rigid;
  fp.bending_length_m = o.bending_m;
  fp.outer_iterations = o.iterations;
  fp.max_plausible_strain_pct = o.max_strain_pct;
  const DesignFit fit = fitDesign(design.mesh, sail.points, fp, bar.progress());
  bar.finish();
  writeMesh(o.out, fit.fitted);
  if (!o.json_out.empty()) writeJsonFile(o.json_out, fitJson(o, design, fit, read.cloud.size(), sail.size()));
  if (o.quiet) return;
  std::printf("Fitted %s (%zu vertices) to %zu sail points of %s\n", o.design.c_str(), fit.fitted.vertices.size(),
              sail.size(), o.flying.c_str());
  std::printf("  coverage %.1f %% of the area within %.0f mm of a sample; RMS to the samples %.1f mm (noise %.1f mm)\n",
              100 * fit.coverage, 1000 * fit.support_radius_m, 1000 * fit.rms_m, 1000 * fit.noise_m);
  std::printf("  strain %%: mean %+.2f, p5 %+.2f, p95 %+.2f, max %+.2f\n", fit.strain.mean_pct, fit.strain.p5_pct,
              fit.strain.p95_pct, fit.strain.max_pct);
  for (const auto& w : fit.warnings) std::printf("  warning: %s\n", w.c_str());
  std::fprintf(stderr, "wrote %s%s%s\n", o.out.c_str(), o.json_out.empty() ? "" : " and ", o.json_out.c_str());
}

}  // namespace

void addFitCommand(CLI::App& app) {
  auto opt = std::make_shared<FitOptions>();
  CLI::App* cmd = app.add_subcommand(
      "fit",
      "Deform the design onto a flying scan: the whole sail, where the scanner missed it too\n\n"
      "Deform the design mesh onto a flying scan, keeping the design's vertices in their order and its "
      "triangles: each design point mapped to where it flies. A scene cloud is segmented to the sail first, as "
      "analyze does. The design is first aligned rigidly to the samples (point-to-plane ICP from where it stands; "
      "kept where it stands if that would move it more than 15 cm), then deformed like sailcloth: through the "
      "samples within their noise, and where the scan has no samples (a head out of range, a patch blinded by "
      "the sun) continued smoothly from around with the design's own bending. The JSON gives, per vertex, the "
      "displacement from the design, the distance to the nearest sample and σ (small where scanned, growing "
      "with the distance from the samples), the coverage, the RMS to the samples, the per-edge strain (%) with "
      "its statistics, and warnings where the fit stretched an edge beyond a plausible strain.");
  cmd->add_option("--design", opt->design, "Design file: .dxf (3DFACE), .obj, .stl or .ply mesh")->required();
  cmd->add_option("--flying", opt->flying,
                  "Flying scan: a cloud (.ply, .pcd, .xyz/.txt, .csv), metres, boat frame; a scene is segmented "
                  "to the sail unless --no-segment")
      ->required();
  cmd->add_option("--out", opt->out, "Write the fitted mesh here (.ply or .obj): the design's vertices, moved")
      ->required();
  cmd->add_option("--json", opt->json_out,
                  "Write coverage, RMS, strain statistics, warnings and the per-vertex displacement, support "
                  "distance and σ as JSON to this file");
  addDesignFileOptions(cmd, opt->unit, opt->axes);
  cmd->add_option("--noise-mm", opt->noise_mm, "The scanner's range noise σ in mm (SPEC: 4 mm; up to 3.5× that in "
                                               "direct sunlight)")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  cmd->add_option("--bending-length", opt->bending_m,
                  "Metres: shape features of the flying sail shorter than this are smoothed, longer ones follow the "
                  "samples")
      ->check(CLI::Range(0.01, 5.0))
      ->capture_default_str();
  cmd->add_option("--iterations", opt->iterations, "Outer iterations (correspondences found again each time)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--max-strain-pct", opt->max_strain_pct,
                  "Warn where an edge stretched more than this (%): sailcloth stretches a few % at most")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  cmd->add_option("--params", opt->params_file, "Pipeline parameters file for the segmentation (see analyze "
                                                "--print-params)");
  cmd->add_flag("--no-segment", opt->no_segment, "The flying cloud is the sail alone: skip segmentation");
  cmd->add_flag("--no-rigid", opt->no_rigid, "Skip the rigid alignment: the design stands where it is");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress output and no summary");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace sailshape::cli
