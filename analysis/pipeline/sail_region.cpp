#include "analysis/pipeline/sail_region.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

Eigen::AlignedBox3d boundsOf(const Mesh& design) {
  Eigen::AlignedBox3d box;
  for (const Vec3& v : design.vertices) box.extend(v);
  return box;
}

std::string mm(double m) { return std::to_string(static_cast<long>(std::lround(1000 * m))) + " mm"; }
std::string metres(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", m);
  return buf;
}
std::string percent(double ratio) { return std::to_string(static_cast<long>(std::lround(100 * ratio))) + " %"; }

}  // namespace

RegionBox designRegion(const Mesh& design, double margin_m) {
  if (design.vertices.empty()) throw InvalidInput("[designRegion] the design has no vertices");
  if (!(margin_m >= 0) || !std::isfinite(margin_m))
    throw InvalidInput("margin must be a finite number of metres >= 0 (got " + std::to_string(margin_m) + ")");
  RegionBox box = boundsOf(design);
  box.min().array() -= margin_m;
  box.max().array() += margin_m;
  return box;
}

RegionBox parseRegionBox(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(x))
      throw InvalidInput("box: \"" + item + "\" is not a finite number of metres (XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX)");
    v.push_back(x);
  }
  if (v.size() != 6)
    throw InvalidInput("box needs six numbers XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX in metres (got " + std::to_string(v.size()) + ")");
  RegionBox box;
  for (int a = 0; a < 3; ++a) {
    if (v[2 * a] > v[2 * a + 1])
      throw InvalidInput(std::string("box: ") + "xyz"[a] + "min " + metres(v[2 * a]) + " exceeds " + "xyz"[a] + "max " +
                         metres(v[2 * a + 1]) + " (XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX)");
    box.min()[a] = v[2 * a];
    box.max()[a] = v[2 * a + 1];
  }
  return box;
}

std::string formatRegionBox(const RegionBox& box) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.3f,%.3f,%.3f,%.3f,%.3f,%.3f", box.min().x(), box.max().x(), box.min().y(),
                box.max().y(), box.min().z(), box.max().z());
  return buf;
}

Cloud cropToRegion(const Cloud& cloud, const RegionBox& box) {
  std::vector<uint32_t> keep;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (box.contains(cloud.points[i])) keep.push_back(static_cast<uint32_t>(i));
  if (keep.empty())
    throw AnalysisError("none of the scan's " + std::to_string(cloud.size()) + " points lies in the sail's region (" +
                        formatRegionBox(box) + " m)");
  Cloud out = selectPoints(cloud, keep);
  out.viewpoint = cloud.viewpoint;
  out.scanner_range_m = cloud.scanner_range_m;
  out.lost_beta_rad = cloud.lost_beta_rad;
  return out;
}

std::vector<Vec3> designSurfacePoints(const Mesh& design, double spacing_m) {
  if (!(spacing_m > 0)) throw InvalidInput("[designSurfacePoints] spacing_m must be > 0 (got " + std::to_string(spacing_m) + ")");
  std::vector<Vec3> out = design.vertices;
  for (const auto& t : design.triangles) {
    const Vec3 &a = design.vertices[t[0]], &b = design.vertices[t[1]], &c = design.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = static_cast<int>(std::ceil(longest / spacing_m));
    if (n <= 1) continue;
    // Barycentric grid of n steps per edge: neighbours lie longest / n <= spacing_m apart.
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) out.push_back(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
  }
  return out;
}

void guideByDesign(AnalysisParams& params, const Mesh& design) {
  const double match_m = plausibleTrimDeviationM(design);
  params.sail_pick.method = "design";
  params.sail_pick.design_match_m = match_m;
  params.sail_pick.design_points = designSurfacePoints(design, match_m / 2);
}

SailAnalysis analyzeInRegion(const Cloud& scan, const RegionBox& region, const Mesh& design, AnalysisParams params,
                             const Progress& progress, SailAnalysis* surface_only) {
  guideByDesign(params, design);
  return analyzeSail(cropToRegion(withoutMixedPixels(scan, params), region), params, progress, surface_only);
}

std::string designMismatch(const Mesh& design, const MeshSections& design_sections, const SailAnalysis& flying,
                           const DistanceStats& deviation) {
  const double bound_m = plausibleTrimDeviationM(design);
  std::vector<std::string> off;
  if (deviation.rms_m > bound_m)
    off.push_back("RMS deviation " + mm(deviation.rms_m) + " (a plausible trim: up to " + mm(bound_m) + ")");
  const double design_area = meshArea(design);
  if (design_area > 0 && std::abs(flying.outline.area_m2 / design_area - 1) > 0.2)
    off.push_back("area " + percent(flying.outline.area_m2 / design_area) + " of the design's");
  const SailOutline &d = design_sections.outline, &f = flying.outline;
  const struct {
    const char* name;
    double design_m, flying_m, sigma_m;
  } edges[] = {{"luff", d.luff_length_m, f.luff_length_m, f.uncertainty.luff_length_m},
               {"leech", d.leech_length_m, f.leech_length_m, f.uncertainty.leech_length_m},
               {"foot", d.foot_length_m, f.foot_length_m, f.uncertainty.foot_length_m}};
  for (const auto& e : edges)
    if (edgeBeyondDesign(e.flying_m, e.design_m, e.sigma_m) != 0)
      off.push_back(std::string(e.name) + " " + percent(e.flying_m / e.design_m) + " of the design's");
  if (off.empty()) return "";
  std::string line = "the analysed surface does not fly like this sail's design: ";
  for (size_t i = 0; i < off.size(); ++i) line += (i ? ", " : "") + off[i];
  return line + "; the scan may hold another sail, or the wrong design was given";
}

int edgeBeyondDesign(double flying_m, double design_m, double sigma_m) {
  if (!(design_m > 0 && flying_m > 0) || std::abs(flying_m - design_m) <= 0.1 * design_m + 3 * sigma_m) return 0;
  return flying_m > design_m ? 1 : -1;
}

}  // namespace sailshape
