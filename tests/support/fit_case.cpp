#include "tests/support/fit_case.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/design/design_compare.hpp"

namespace sailshape {

SailDesign deeperAndMoreTwisted(const SailDesign& design) {
  SailDesign flying = design;
  for (ProfileStation& st : flying.stations) {
    st.camber_pct += 3.0;
    st.twist_deg += 2.0 + 10.0 * st.fraction;
  }
  return flying;
}

FitRegion fitRegion(const SailSurface& flying, const Vec3& p, const FitCaseOptions& o) {
  const double z0 = flying.tack().z(), z1 = std::max(flying.head().z(), flying.peak().z());
  const double h = (p.z() - z0) / (z1 - z0);
  if (h > o.top_h) return FitRegion::AboveTop;
  if (h >= o.hole_h_from && h <= o.hole_h_to) {
    const Vec3 luff = flying.luffPoint(h), leech = flying.leechPoint(h);
    const double u = (p - luff).dot(leech - luff) / (leech - luff).squaredNorm();
    if (u >= o.hole_u_from && u <= o.hole_u_to) return FitRegion::Hole;
  }
  return FitRegion::Scanned;
}

FitCase makeFitCase(const FitCaseOptions& o) {
  FitCase c;
  c.design = exampleDesign(o.type);
  c.flying = deeperAndMoreTwisted(c.design);
  c.design_mesh = generateSailMesh(c.design, o.rows, o.columns);
  ScanSimulation sim;
  sim.points = o.points;
  sim.noise_sigma_m = o.noise_sigma_m;
  sim.seed = o.seed;
  Cloud all;
  std::vector<char> sail;
  if (o.scene) {
    SceneCloud s = sampleSailScene(c.flying, sim);
    all = std::move(s.cloud);
    sail = std::move(s.is_sail);
  } else {
    all = sampleSail(c.flying, sim);
    sail.assign(all.size(), 1);
  }
  const SailSurface surface(c.flying);
  c.scan.viewpoint = all.viewpoint;
  for (size_t i = 0; i < all.size(); ++i) {
    if (sail[i] && fitRegion(surface, all.points[i], o) != FitRegion::Scanned) continue;
    c.scan.points.push_back(all.points[i]);
    c.is_sail.push_back(sail[i]);
  }
  return c;
}

std::array<RegionError, 3> regionErrors(const std::vector<Vec3>& vertices, const FitCase& c, const FitCaseOptions& o,
                                        const std::vector<char>* supported, const std::vector<double>* sigma) {
  const SailSurface truth(c.flying);
  // 320 × 160 cells: the truth mesh's own chord error (cell² · curvature / 8) is hundredths of a mm.
  const DesignDistance truth_mesh(generateSailMesh(c.flying, 320, 160));
  std::array<RegionError, 3> e{};
  for (size_t v = 0; v < vertices.size(); ++v) {
    const DesignDistance::Closest foot = truth_mesh.closest(vertices[v]);
    const FitRegion region = fitRegion(truth, foot.point, o);
    if (region == FitRegion::Scanned && supported && !(*supported)[v]) continue;
    RegionError& r = e[static_cast<size_t>(region)];
    const double d = std::abs(foot.distance_m);
    ++r.count;
    r.rms_m += d * d;
    r.max_m = std::max(r.max_m, d);
    if (sigma && d <= 3 * (*sigma)[v]) ++r.within_3_sigma;
  }
  for (RegionError& r : e) r.rms_m = r.count ? std::sqrt(r.rms_m / static_cast<double>(r.count)) : 0.0;
  return e;
}

}  // namespace sailshape
