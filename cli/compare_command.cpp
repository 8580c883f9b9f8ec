// `sailshape compare`: a flying shape (cloud or mesh) against its design.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/io/design_import.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/params_io.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

struct CompareOptions {
  std::string design, flying, unit = "auto", axes = "auto", json_out, params_file, distances_out, whole_sail_out;
  int sections = 3;
  bool no_segment = false, raw_distances = false, quiet = false;
};

// A .ply holds a mesh when its header declares faces.
bool plyHasFaces(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int i = 0; i < 200 && std::getline(in, line); ++i) {
    if (line.rfind("end_header", 0) == 0) break;
    if (line.rfind("element face ", 0) == 0) return std::stoll("0" + line.substr(13)) > 0;
  }
  return false;
}

// The whole sail's deviation from its design (--whole-sail): the design fitted onto the flying
// shape, each vertex's move along the design's normal (positive to leeward), split by whether
// samples held it (scanned) or the fit carried it on from around (inferred).
struct WholeSail {
  DesignFit fit;
  std::vector<double> deviation_m;  // per design vertex
  DistanceStats scanned, inferred;
  double inferred_sigma_p50_m = 0, inferred_sigma_max_m = 0;  // the inferred vertices' σ
};

WholeSail wholeSail(const Mesh& design, const std::vector<Vec3>& samples, const Vec3& leeward, const Progress& progress) {
  WholeSail w;
  w.fit = fitDesign(design, samples, {}, progress);
  w.deviation_m = vertexMoves(design, w.fit, leeward).normal_m;
  std::vector<double> scanned, inferred, sigma;
  for (size_t v = 0; v < design.vertices.size(); ++v) {
    if (w.fit.supported[v]) {
      scanned.push_back(w.deviation_m[v]);
    } else {
      inferred.push_back(w.deviation_m[v]);
      sigma.push_back(w.fit.sigma_m[v]);
    }
  }
  if (!scanned.empty()) w.scanned = distanceStats(scanned);
  if (!inferred.empty()) w.inferred = distanceStats(inferred);
  if (!sigma.empty()) {
    std::sort(sigma.begin(), sigma.end());
    w.inferred_sigma_p50_m = sigma[sigma.size() / 2];
    w.inferred_sigma_max_m = sigma.back();
  }
  return w;
}

// The fitted design as an ASCII PLY mesh whose vertices carry deviation_mm (along the design's
// normal, + leeward), sigma_mm (1σ of that) and scanned (1: samples hold it, 0: inferred).
void writeWholeSail(const std::string& path, const WholeSail& w) {
  std::ofstream out(path);
  if (!out) throw FileError(path + ": cannot write");
  const Mesh& m = w.fit.fitted;
  out << "ply\nformat ascii 1.0\ncomment sailshape compare --whole-sail: the design fitted onto the flying shape\n"
      << "element vertex " << m.vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float deviation_mm\n"
         "property float sigma_mm\nproperty uchar scanned\nelement face "
      << m.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  char line[160];
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    const Vec3& p = m.vertices[v];
    std::snprintf(line, sizeof line, "%.5f %.5f %.5f %.2f %.2f %d\n", p.x(), p.y(), p.z(), 1000 * w.deviation_m[v],
                  1000 * w.fit.sigma_m[v], w.fit.supported[v] ? 1 : 0);
    out << line;
  }
  for (const auto& t : m.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  if (!out) throw FileError(path + ": write failed");
}

nlohmann::json statsJson(const DistanceStats& s) {
  return {{"count", s.count}, {"mean_m", s.mean_m}, {"rms_m", s.rms_m}, {"max_abs_m", s.max_abs_m},
          {"p5_m", s.p5_m},   {"p50_m", s.p50_m},   {"p95_m", s.p95_m}};
}

// A section asked of both sides that one of them could not measure: it has no delta.
struct MissingSection {
  double fraction;
  std::string side;  // "design" or "flying"
  std::string reason;
};

void printTable(const CompareOptions& o, const DesignImport& design, const DesignComparison& c, const std::string& what,
                const std::vector<MissingSection>& missing, const std::string& outline_refused,
                const std::optional<WholeSail>& whole) {
  std::printf("Design %s (%s, %s, %s axes)\nFlying %s\n", o.design.c_str(), design.format.c_str(), design.unit.c_str(),
              design.axes.c_str(), o.flying.c_str());
  const DistanceStats& s = c.stats;
  std::printf("\nSigned distance of %zu %s to the design (mm, positive to leeward, towards %+.2f %+.2f %+.2f):\n",
              s.count, what.c_str(), c.leeward.x(), c.leeward.y(), c.leeward.z());
  std::printf("  mean %+.1f  rms %.1f  max |d| %.1f  p5 %+.1f  p50 %+.1f  p95 %+.1f\n", 1000 * s.mean_m, 1000 * s.rms_m,
              1000 * s.max_abs_m, 1000 * s.p5_m, 1000 * s.p50_m, 1000 * s.p95_m);
  if (whole) {
    const WholeSail& w = *whole;
    std::printf("\nThe whole sail: the design fitted onto the flying shape (%.0f %% of its area within %.0f mm of a "
                "sample), each design point's move along its normal (mm, positive to leeward):\n",
                100 * w.fit.coverage, 1000 * w.fit.support_radius_m);
    auto line = [](const char* name, const DistanceStats& s) {
      std::printf("  %-9s %6zu points: mean %+.1f  rms %.1f  p5 %+.1f  p95 %+.1f  max |d| %.1f\n", name, s.count,
                  1000 * s.mean_m, 1000 * s.rms_m, 1000 * s.p5_m, 1000 * s.p95_m, 1000 * s.max_abs_m);
    };
    line("scanned", w.scanned);
    if (w.inferred.count > 0) {
      line("inferred", w.inferred);
      std::printf("            (inferred where the scan has no samples: σ median %.1f, largest %.1f)\n",
                  1000 * w.inferred_sigma_p50_m, 1000 * w.inferred_sigma_max_m);
    }
    std::printf("  stretch where scanned: p5 %+.2f %%, p95 %+.2f %%\n", w.fit.strain_supported.p5_pct,
                w.fit.strain_supported.p95_pct);
    std::printf("  written to %s\n", o.whole_sail_out.c_str());
  }
  if (!outline_refused.empty())
    std::printf("\nOutline and sections not measured on the flying shape: %s\n", outline_refused.c_str());
  std::printf("\nSections: design / flying (flying - design)\n");
  std::printf("%6s %22s %22s %22s %22s %22s %22s\n", "height", "chord m", "camber %", "draft %", "twist deg",
              "entry deg", "exit deg");
  for (const SectionDelta& d : c.sections) {
    auto cell = [](double a, double b, double delta, int digits) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%.*f/%.*f (%+.*f)", digits, a, digits, b, digits, delta);
      std::printf(" %22s", buf);
    };
    std::printf("%5.0f%%", 100 * d.fraction);
    cell(d.design.chord_m, d.flying.chord_m, d.delta.chord_m, 3);
    cell(d.design.camber_pct, d.flying.camber_pct, d.delta.camber_pct, 2);
    cell(d.design.draft_pct, d.flying.draft_pct, d.delta.draft_pct, 1);
    cell(d.design.twist_deg, d.flying.twist_deg, d.delta.twist_deg, 1);
    cell(d.design.entry_deg, d.flying.entry_deg, d.delta.entry_deg, 1);
    cell(d.design.exit_deg, d.flying.exit_deg, d.delta.exit_deg, 1);
    std::printf("\n");
  }
  for (const MissingSection& m : missing)
    std::printf("%5.0f%% not measured on the %s: %s\n", 100 * m.fraction, m.side.c_str(), m.reason.c_str());
  if (!c.warnings.empty()) {
    std::printf("\nWarnings:\n");
    for (const auto& w : c.warnings) std::printf("  %s\n", w.c_str());
  }
}

void run(const CompareOptions& o) {
  DesignImportOptions io;
  io.unit = o.unit;
  io.axes = o.axes;
  const DesignImport design = importDesign(o.design, io);
  SectionParams sp;
  sp.count = o.sections;
  MeshSections design_sections = analyzeMeshSections(design.mesh, {}, sp);

  std::vector<Vec3> points;
  std::vector<Vec3> fit_samples;  // the flying shape's own points for --whole-sail
  SectionAnalysis flying_sections;
  std::vector<std::string> warnings;
  std::string what;
  // Why the flying shape has no outline (a patch of a sail, a scan short of a corner): its
  // distances to the design still stand, its sections are not measured.
  std::string outline_refused;
  std::string ext = std::filesystem::path(o.flying).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  const bool is_mesh = ext == ".obj" || ext == ".stl" || (ext == ".ply" && plyHasFaces(o.flying));
  ProgressBar bar(!o.quiet);
  if (is_mesh) {
    const Mesh flying = readMesh(o.flying);
    OutlineParams op;
    op.design_lengths_m = {design_sections.outline.luff_length_m, design_sections.outline.leech_length_m,
                           design_sections.outline.foot_length_m};
    try {
      const MeshSections fs = analyzeMeshSections(flying, op, sp);
      flying_sections = fs.sections;
      warnings = fs.outline.warnings;
    } catch (const AnalysisError& e) {
      outline_refused = userMessage(e.what());
    }
    points = flying.vertices;
    fit_samples = flying.vertices;
    what = "flying mesh vertices";
  } else {
    AnalysisParams params = o.params_file.empty() ? AnalysisParams{} : loadParams(o.params_file);
    params.sections.count = o.sections;
    params.sections.fractions.clear();
    if (o.no_segment) params.segment = false;
    params.outline.design_lengths_m = {design_sections.outline.luff_length_m, design_sections.outline.leech_length_m,
                                       design_sections.outline.foot_length_m};
    CloudReadResult read = readCloud(o.flying);
    for (const auto& w : read.warnings) std::fprintf(stderr, "warning: %s: %s\n", o.flying.c_str(), w.c_str());
    SailAnalysis a;
    SailAnalysis surface_only;
    try {
      a = analyzeSail(read.cloud, params, bar.progress(), &surface_only);
    } catch (const AnalysisError& e) {
      if (surface_only.sail_cloud.empty()) throw;  // no sail surface: nothing to compare
      a = std::move(surface_only);
      outline_refused = userMessage(e.what());
    }
    flying_sections = a.sections;
    warnings = a.warnings;
    if (!o.whole_sail_out.empty()) fit_samples = a.sail_cloud.points;
    if (o.raw_distances) {
      points = std::move(read.cloud.points);
      what = "flying points (as read)";
    } else {
      points = std::move(a.sail_cloud.points);
      what = "sail points (segmented, cleaned, smoothed)";
    }
  }
  if (!outline_refused.empty())
    for (double fraction : sectionFractions(sp)) flying_sections.unmeasured.push_back({fraction, "no outline on the flying shape"});
  DesignComparison c = compareWithDesign(design.mesh, design_sections.sections, points, flying_sections, bar.progress());
  std::optional<WholeSail> whole;
  if (!o.whole_sail_out.empty()) {
    whole = wholeSail(design.mesh, fit_samples, c.leeward, bar.progress());
    writeWholeSail(o.whole_sail_out, *whole);
    for (const std::string& w : whole->fit.warnings) c.warnings.push_back("whole sail: " + w);
  }
  bar.finish();
  c.warnings.insert(c.warnings.begin(), warnings.begin(), warnings.end());
  for (const std::string& w : design_sections.sections.warnings) c.warnings.push_back("design: " + w);
  std::vector<MissingSection> missing;
  for (const UnmeasuredSection& u : design_sections.sections.unmeasured) missing.push_back({u.fraction, "design", u.reason});
  for (const UnmeasuredSection& u : flying_sections.unmeasured) missing.push_back({u.fraction, "flying", u.reason});
  std::sort(missing.begin(), missing.end(), [](const auto& a, const auto& b) { return a.fraction < b.fraction; });

  if (!o.distances_out.empty()) {
    Cloud out;
    out.points = points;
    out.intensity.reserve(points.size());
    for (double d : c.distance_m) out.intensity.push_back(static_cast<float>(1000.0 * d));
    writeCloud(o.distances_out, out);
    if (!o.quiet) std::fprintf(stderr, "wrote %s (intensity = signed distance, mm)\n", o.distances_out.c_str());
  }
  if (o.json_out.empty()) {
    printTable(o, design, c, what, missing, outline_refused, whole);
    return;
  }
  nlohmann::json doc;
  doc["design"] = {{"file", o.design}, {"format", design.format}, {"unit", design.unit}, {"axes", design.axes},
                   {"notes", design.notes}};
  doc["flying"] = {{"file", o.flying}, {"kind", is_mesh ? "mesh" : "cloud"}, {"points", points.size()},
                   {"distances_of", what}};
  doc["flying"]["outline"] = outline_refused.empty() ? nlohmann::json("measured")
                                                     : nlohmann::json("not measured: " + outline_refused);
  const DistanceStats& s = c.stats;
  doc["distance"] = {{"count", s.count},       {"mean_m", s.mean_m}, {"rms_m", s.rms_m}, {"max_abs_m", s.max_abs_m},
                     {"p5_m", s.p5_m},         {"p50_m", s.p50_m},   {"p95_m", s.p95_m},
                     {"leeward", {c.leeward.x(), c.leeward.y(), c.leeward.z()}}};
  doc["sections"] = nlohmann::json::array();
  for (const SectionDelta& d : c.sections)
    doc["sections"].push_back({{"fraction", d.fraction},
                               {"design", sectionParametersToJson(d.design)},
                               {"flying", sectionParametersToJson(d.flying)},
                               {"delta", sectionParametersToJson(d.delta)}});
  doc["unmeasured_sections"] = nlohmann::json::array();
  for (const MissingSection& m : missing)
    doc["unmeasured_sections"].push_back({{"fraction", m.fraction}, {"side", m.side}, {"reason", m.reason}});
  if (whole) {
    const WholeSail& w = *whole;
    doc["whole_sail"] = {{"file", o.whole_sail_out},
                         {"coverage", w.fit.coverage},
                         {"support_radius_m", w.fit.support_radius_m},
                         {"scanned", statsJson(w.scanned)},
                         {"inferred", statsJson(w.inferred)},
                         {"inferred_sigma_p50_m", w.inferred_sigma_p50_m},
                         {"inferred_sigma_max_m", w.inferred_sigma_max_m},
                         {"strain_scanned_p5_pct", w.fit.strain_supported.p5_pct},
                         {"strain_scanned_p95_pct", w.fit.strain_supported.p95_pct}};
  } else {
    doc["whole_sail"] = nullptr;
  }
  doc["warnings"] = c.warnings;
  writeJsonFile(o.json_out, doc);
  if (!o.quiet) std::fprintf(stderr, "wrote %s\n", o.json_out.c_str());
}

}  // namespace

void addCompareCommand(CLI::App& app) {
  auto opt = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare a flying shape with its design: point distances and section deltas\n\n"
      "Compare a flying shape with its design, both in the boat frame: signed distance of every flying point to "
      "the design surface (positive to the sail's leeward side, the side its camber bulges to) with its "
      "statistics, and per-section parameter deltas (flying - design) at the same fractions.");
  cmd->add_option("--design", opt->design, "Design file: .dxf (3DFACE), .obj, .stl or .ply mesh")->required();
  cmd->add_option("--flying", opt->flying,
                  "Flying shape: a cloud (.ply without faces, .pcd, .xyz/.txt, .csv; analysed by the pipeline) or a "
                  "mesh (.obj, .stl, .ply with faces), metres, boat frame")
      ->required();
  cmd->add_option("--sections", opt->sections, "Number of sections N, at t = k/(N+1) of luff and leech")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--json", opt->json_out, "Write the statistics and section deltas as JSON to this file instead "
                                           "of the table");
  cmd->add_option("--distances", opt->distances_out,
                  "Write the flying points with their signed distance in mm as the intensity field (.ply, .pcd, "
                  ".xyz, .csv): the colour map");
  cmd->add_option("--whole-sail", opt->whole_sail_out,
                  "Fit the design onto the flying shape (as `sailshape fit`) and write the whole sail's deviation map "
                  "to this .ply: the fitted design's mesh, each vertex with deviation_mm (its move along the design's "
                  "normal, positive to leeward), sigma_mm (1σ) and scanned (1: samples hold it; 0: inferred where the "
                  "scan has none, carried on from around). The table and JSON give the statistics of the scanned "
                  "and inferred parts apart, and the stretch where scanned");
  addDesignFileOptions(cmd, opt->unit, opt->axes);
  cmd->add_option("--params", opt->params_file, "Pipeline parameters file for a flying cloud (see analyze "
                                                "--print-params)");
  cmd->add_flag("--no-segment", opt->no_segment, "The flying cloud is the sail alone: skip segmentation");
  cmd->add_flag("--raw-distances", opt->raw_distances,
                "Distances of every flying point as read, not of the analysed (segmented, cleaned, smoothed) sail "
                "points");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress output");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace sailshape::cli
