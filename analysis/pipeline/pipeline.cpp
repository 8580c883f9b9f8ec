#include "analysis/pipeline/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <utility>

#include "analysis/core/errors.hpp"
#include "analysis/core/plausible.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

class StageTimer {
 public:
  StageTimer(SailAnalysis& a, std::string name, size_t points_in) : analysis_(a) {
    report_.name = std::move(name);
    report_.points_in = points_in;
    start_ = std::chrono::steady_clock::now();
  }
  void finish(size_t points_out, const std::vector<std::string>& warnings = {}) {
    report_.points_out = points_out;
    report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    report_.warnings = warnings;
    for (const auto& w : warnings) analysis_.warnings.push_back(report_.name + ": " + w);
    analysis_.stages.push_back(report_);
  }

 private:
  SailAnalysis& analysis_;
  StageReport report_;
  std::chrono::steady_clock::time_point start_;
};

// The working resolution's column width for the sail's points (analyzeSail's parameters; 0: none).
double workingVoxel(const Cloud& sail, const AnalysisParams& p) {
  if (!(p.working_voxel_sigmas > 0) || sail.size() < 2) return 0;
  Eigen::AlignedBox3d box;
  for (const Vec3& x : sail.points) box.extend(x);
  return std::min(p.working_voxel_sigmas * p.sensor_sigma_m, p.working_voxel_of_extent * box.diagonal().norm());
}

// The working resolution pays only where the columns hold several samples each: at
// 40,000 points on a 10 m sail 2 cm columns hold about one on average, and the mean
// of one or two samples is no better a point than the samples, only fewer of them.
// Near two a column on average, many hold one and the narrow tips are thinned
// unevenly, which pulls the corners in by centimetres; from three a column on
// average the corners stand where every point puts them.
constexpr double kMinSamplesPerColumn = 3.0;

// The readmit parameters with the pipeline's default offset: 0 means 3 sensor σ.
ReadmitParams readmitParams(const AnalysisParams& p) {
  ReadmitParams rp = p.readmit;
  if (rp.max_offset_m == 0) rp.max_offset_m = 3.0 * p.sensor_sigma_m;
  return rp;
}

// Finds round spars among the points near the sail cluster `sail` (indices into
// `cloud`); when there are any, the sail loses its points on them and gains the
// unclustered points that lie on its surface and off every spar: the strip along
// an edge whose neighbourhoods reached onto the spar. Returns the new cluster.
std::vector<uint32_t> separateSpars(const Cloud& cloud, const std::vector<Vec3>& normals, const Segmentation& seg,
                                    const std::vector<uint32_t>& sail, const AnalysisParams& p, SailAnalysis& a) {
  std::vector<char> in_sail(cloud.size(), 0);
  Eigen::AlignedBox3d box;
  for (uint32_t i : sail) {
    in_sail[i] = 1;
    box.extend(cloud.points[i]);
  }
  SparSearchParams sp = p.spars;
  sp.sensor_sigma_m = p.sensor_sigma_m;
  // A spar within reach of the sail has its whole girth inside the grown box.
  const double reach = 2 * sp.max_radius_m + 0.1;
  box.min() -= Vec3::Constant(reach);
  box.max() += Vec3::Constant(reach);
  // Spars are among the unclustered points and the narrow or small clusters; a
  // deck's or wall's thousands of points would only drown a boom's few hundred in
  // the search's random samples.
  std::vector<char> broad(cloud.size(), 0);
  for (size_t c = 0; c < seg.clusters.size() && c < a.clusters.size(); ++c) {
    const ClusterInfo::Shape shape = a.clusters[c].shape;
    if (shape == ClusterInfo::Shape::Narrow || shape == ClusterInfo::Shape::TooSmall) continue;
    for (uint32_t i : seg.clusters[c]) broad[i] = 1;
  }
  std::vector<uint32_t> near;
  for (uint32_t i = 0; i < cloud.size(); ++i)
    if (!in_sail[i] && !broad[i] && box.contains(cloud.points[i])) near.push_back(i);
  const SparSearch found = findSpars(cloud, normals, near, sp, sail);
  a.spars = found.spars;
  if (found.spars.empty()) return sail;
  const double sigma = p.sensor_sigma_m;
  // Each spar as the search's run of points could have carried on: two diameters and two
  // bands beyond each end. A point there on its surface is the spar's, though no run
  // of them reached it (the sparse mast foot below the sail's tack).
  std::vector<Spar> reach_of;
  for (const SparFit& f : found.spars) {
    Spar s = f.spar;
    const double gap = sparRunGapM(s.radius_m, sigma);
    s.base -= gap * s.axis;
    s.length_m += 2 * gap;
    reach_of.push_back(s);
  }
  // Which spar is nearest x, and how far x lies off it.
  auto nearestSpar = [&](const Vec3& x) {
    std::pair<double, size_t> best{std::numeric_limits<double>::infinity(), 0};
    for (size_t s = 0; s < reach_of.size(); ++s) best = std::min(best, std::make_pair(distanceToSpar(x, reach_of[s]), s));
    return best;
  };
  // The unit direction across spar s from its axis to x.
  auto across = [&](const Vec3& x, size_t s) {
    const Spar& spar = found.spars[s].spar;
    return acrossAxis(x - spar.base, spar.axis).normalized();
  };
  std::vector<char> loose(cloud.size(), 0);
  for (uint32_t i : seg.unassigned) loose[i] = !in_sail[i];
  // Only the sail's points and the loose ones in the box can be kept or come back.
  std::vector<std::pair<double, size_t>> to_spar(cloud.size(), {std::numeric_limits<double>::infinity(), 0});
  for (uint32_t i = 0; i < cloud.size(); ++i)
    if (in_sail[i] || (loose[i] && box.contains(cloud.points[i]))) to_spar[i] = nearestSpar(cloud.points[i]);
  // The side of each spar the sail lies on: the mean direction across it to the sail's
  // points within half a metre.
  std::vector<Vec3> sail_side(found.spars.size(), Vec3::Zero());
  for (uint32_t i : sail)
    if (to_spar[i].first > 2 * sigma && to_spar[i].first < 0.5)
      sail_side[to_spar[i].second] += across(cloud.points[i], to_spar[i].second);
  for (Vec3& v : sail_side)
    if (v.norm() > 0) v.normalize();
  // A loose point 3σ-6σ off a spar's surface is the sail's edge strip when it lies on the
  // sail's side of the spar, within 60°. On another side it is more likely one of the
  // spar's own points that noise put out so far (one in a few hundred): taken into a
  // sparse sweep's sail as a point of its surface, it can draw the tack up the mast.
  auto offSpar = [&](uint32_t i) {
    const auto [d, s] = to_spar[i];
    if (!std::isfinite(d) || d <= 3 * sigma) return false;
    return d > 6 * sigma || sail_side[s].norm() == 0 || across(cloud.points[i], s).dot(sail_side[s]) >= 0.5;
  };
  // Sail points within 2σ of a spar's surface are more likely the spar's; loose
  // points within 3σ of it stay out (the sail is at least 2 cm off a mast's aft face).
  // `sub` ascends, and `kept` indexes the sail's part of it, as readmitSurfacePoints needs.
  std::vector<uint32_t> sub, kept;
  for (uint32_t i = 0; i < cloud.size(); ++i) {
    if (in_sail[i] && to_spar[i].first > 2 * sigma) {
      kept.push_back(static_cast<uint32_t>(sub.size()));
      sub.push_back(i);
    } else if (loose[i] && offSpar(i)) {
      sub.push_back(i);
    }
  }
  if (sub.size() == kept.size() || kept.empty()) {
    std::vector<uint32_t> out;
    out.reserve(kept.size());
    for (uint32_t k : kept) out.push_back(sub[k]);
    return out;
  }
  const Cleaning back = readmitSurfacePoints(selectPoints(cloud, sub), kept, readmitParams(p));
  std::vector<uint32_t> out;
  out.reserve(back.kept.size());
  for (uint32_t k : back.kept) out.push_back(sub[k]);
  return out;
}

}  // namespace

MixedPixelParams mixedPixelParams(const AnalysisParams& p) {
  MixedPixelParams m = p.mixed;
  m.sensor_sigma_m = p.sensor_sigma_m;
  return m;
}

namespace {
// Whether the analysis looks for mixed pixels in `scan`: only a scan's own grid shows them.
bool looksForMixedPixels(const Cloud& scan, const AnalysisParams& p) {
  return p.mixed_pixels && scan.hasScanAngles() && scan.viewpoint;
}
}  // namespace

std::vector<std::string> widenCornersBesideLostLines(SailOutline& outline, const Cloud& scan) {
  std::vector<std::string> warnings;
  if (scan.lost_beta_rad.empty() || !scan.viewpoint) return warnings;
  const std::vector<ScanLine> lines = scanLines(scan);
  if (lines.size() < 2) return warnings;
  // The turntable's step: between the lines taken across the cloud, received or lost
  // (a sweep that lost every other scan leaves its received lines two steps apart).
  std::vector<double> taken;
  for (const ScanLine& l : lines) taken.push_back(l.beta_rad);
  for (double b : scan.lost_beta_rad)
    if (b > lines.front().beta_rad && b < lines.back().beta_rad) taken.push_back(b);
  std::sort(taken.begin(), taken.end());
  std::vector<double> steps;
  for (size_t i = 1; i < taken.size(); ++i) steps.push_back(taken[i] - taken[i - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  const double step = steps[steps.size() / 2];
  if (!(step > 0)) return warnings;
  std::vector<uint32_t> line_of(scan.size(), 0);
  for (uint32_t l = 0; l < lines.size(); ++l)
    for (uint32_t s : lines[l].samples) line_of[s] = l;
  // Is a line lost within half a step of β? (A lost line is stored at its middle
  // beam, a received one at its samples' mean: a fraction of a step apart.)
  auto lostNear = [&](double beta) {
    const auto it = std::lower_bound(scan.lost_beta_rad.begin(), scan.lost_beta_rad.end(), beta - 0.5 * step);
    return it != scan.lost_beta_rad.end() && *it < beta + 0.5 * step;
  };
  auto widen = [&](const char* name, const Vec3& corner, double& sigma) {
    size_t nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < scan.size(); ++i) {
      const double d = (scan.points[i] - corner).squaredNorm();
      if (d < best) best = d, nearest = i;
    }
    // Lost lines in a row beside the corner's line, on either side, each a step on:
    // the edge may lie that many spacings further out.
    const double beta = lines[line_of[nearest]].beta_rad;
    int run = 0;
    for (const int side : {-1, 1}) {
      int k = 0;
      while (k < 1000 && lostNear(beta + side * (k + 1) * step)) ++k;
      run = std::max(run, k);
    }
    if (run == 0) return;
    const double spacing = (corner - *scan.viewpoint).norm() * step;
    sigma = std::hypot(sigma, run * spacing);
    warnings.push_back(std::string(name) + ": " + (run == 1 ? "a scan line" : std::to_string(run) + " scan lines") +
                       " the sweep lost lie beside it; it may lie up to " + formatFixed(100 * run * spacing, 1) +
                       " cm further out (a line spacing each), and its uncertainty says so");
  };
  SailOutline::Uncertainty& u = outline.uncertainty;
  widen("tack", outline.tack, u.tack_m);
  widen("clew", outline.clew, u.clew_m);
  widen("head", outline.head, u.head_m);
  if (outline.has_peak) widen("peak", outline.peak, u.peak_m);
  return warnings;
}

Cloud withoutMixedPixels(const Cloud& scan, const AnalysisParams& p) {
  if (!looksForMixedPixels(scan, p)) return scan;
  return selectPoints(scan, removeMixedPixels(scan, mixedPixelParams(p)).kept);
}

namespace {

void checkAnalysisParams(const Cloud& input, const AnalysisParams& p) {
  if (input.empty()) throw InvalidInput("[analyzeSail] empty cloud");
  for (size_t i = 0; i < input.size(); ++i)
    if (!input.points[i].allFinite())
      throw InvalidInput("[analyzeSail] point " + std::to_string(i) + " has a non-finite coordinate");
  if (auto why = implausibleCoordinates(input.points, "the cloud")) throw InvalidInput("[analyzeSail] " + *why);
  if (!(p.sensor_sigma_m > 0))
    throw InvalidInput("[analyzeSail] sensor_sigma_m must be > 0 (got " + std::to_string(p.sensor_sigma_m) + ")");
  if (!(p.working_voxel_sigmas >= 0) || !std::isfinite(p.working_voxel_sigmas))
    throw InvalidInput("[analyzeSail] working_voxel_sigmas must be >= 0 and finite (0: every point; got " +
                       std::to_string(p.working_voxel_sigmas) + ")");
  if (!(p.working_column_depth_sigmas >= 0) || !std::isfinite(p.working_column_depth_sigmas))
    throw InvalidInput("[analyzeSail] working_column_depth_sigmas must be >= 0 and finite (got " +
                       std::to_string(p.working_column_depth_sigmas) + ")");
  if (!(p.working_voxel_of_extent > 0) || !std::isfinite(p.working_voxel_of_extent))
    throw InvalidInput("[analyzeSail] working_voxel_of_extent must be > 0 and finite (got " +
                       std::to_string(p.working_voxel_of_extent) + ")");
  // The outline and sections come last: a bad parameter of theirs is reported before the work, not after.
  checkOutlineParams(p.outline);
  {
    SectionParams sp = p.sections;
    sp.sensor_sigma_m = p.sensor_sigma_m;
    checkSectionParams(sp);
  }
  if (p.mixed_pixels) checkMixedPixelParams(mixedPixelParams(p));
  // Each stage needs its neighbourhood; the largest one in use bounds how few points can be a sail.
  // After the parameters: the neighbourhoods are theirs, and a bad one is the error to report.
  const std::pair<int, const char*> needs[] = {
      {p.normals.k_neighbours, "normals.k_neighbours"},
      {p.segment ? p.region_growing.k_neighbours : 0, "region_growing.k_neighbours"},
      {p.statistical_outliers ? p.statistical.k_neighbours + 1 : 0, "statistical.k_neighbours"},
      {p.radius_outliers ? p.radius.min_neighbours + 1 : 0, "radius.min_neighbours"},
      {p.smooth ? p.smoothing.k_neighbours : 0, "smoothing.k_neighbours"}};
  const auto most = std::max_element(std::begin(needs), std::end(needs),
                                     [](const auto& a, const auto& b) { return a.first < b.first; });
  if (input.size() < static_cast<size_t>(std::max(most->first, 1)))
    throw InvalidInput("[analyzeSail] the cloud has " + std::to_string(input.size()) +
                       " points: too few to be a sail's scan (the analysis needs at least " +
                       std::to_string(most->first) + ", the neighbourhood of " + most->second + ")");
}

// The segmentation stage: `cloud` becomes the sail cluster, with its fringe, less
// any spars beside it. Clusters and spars go to `a`.
void segmentSail(Cloud& cloud, const AnalysisParams& p, const Progress& progress, SailAnalysis& a) {
  StageTimer t(a, "segmentation", cloud.size());
  // Work on a voxel-grid sample when the scan is denser than the voxel.
  const double voxel = p.segmentation_voxel_sigmas * p.sensor_sigma_m;
  const bool thin = voxel > 0 && medianNeighbourDistanceBelow(cloud.points, 0.8 * voxel);
  VoxelMeans sample;
  if (thin) sample = voxelMeans(cloud, voxel);
  const Cloud& seg_cloud = thin ? sample.cloud : cloud;
  const size_t k = static_cast<size_t>(std::max(p.normals.k_neighbours, p.region_growing.k_neighbours));
  const NeighbourTable seg_table = nearestNeighbours(seg_cloud.points, k, progress);
  const NormalEstimation normals = estimateNormals(seg_cloud, seg_table, p.normals, progress);
  const Segmentation seg = growRegions(seg_cloud, normals.normals, seg_table, p.region_growing, progress);
  const SailPick pick = pickSailCluster(seg_cloud, seg, p.sail_pick);
  a.clusters = pick.candidates;
  std::vector<uint32_t> idx = addClusterFringe(seg, pick.cluster, seg_table);
  if (p.find_spars) idx = separateSpars(seg_cloud, normals.normals.normals, seg, idx, p, a);
  if (thin) {
    std::vector<char> in(sample.cloud.size(), 0);
    for (uint32_t v : idx) in[v] = 1;
    idx.clear();
    for (uint32_t i = 0; i < cloud.size(); ++i)
      if (in[sample.voxel_of[i]]) idx.push_back(i);
  }
  cloud = selectPoints(cloud, idx);
  std::vector<std::string> w = normals.warnings;
  w.insert(w.end(), seg.warnings.begin(), seg.warnings.end());
  w.insert(w.end(), pick.warnings.begin(), pick.warnings.end());
  t.finish(cloud.size(), w);
}

// What the working resolution leaves beside the working points: how many scan
// points each stands for (empty: one each), and the scan's own sail points when
// the working points are column means (empty otherwise).
struct WorkingResolution {
  std::vector<uint32_t> represents;
  std::vector<Vec3> scan_points;
};

// The working-resolution stage: `cloud` becomes its column means where the columns
// hold enough samples to pay.
WorkingResolution toWorkingResolution(Cloud& cloud, const AnalysisParams& p, SailAnalysis& a) {
  WorkingResolution w;
  const double voxel = workingVoxel(cloud, p);
  if (!(voxel > 0)) return w;
  StageTimer t(a, "working resolution", cloud.size());
  VoxelMeans merged =
      columnMeans(cloud, principalAxes(cloud.points).axes, voxel, p.working_column_depth_sigmas * p.sensor_sigma_m);
  if (static_cast<double>(merged.cloud.size()) * kMinSamplesPerColumn <= static_cast<double>(cloud.size())) {
    w.scan_points = std::move(cloud.points);
    cloud = std::move(merged.cloud);
    w.represents = std::move(merged.count);
    a.working_voxel_m = voxel;
  }
  t.finish(cloud.size());
  return w;
}

// The cleaning stages (statistical and radius outliers, then readmission): `cloud`
// keeps its sail points; a.working_points and a.sail_points are set. Returns the
// samples the filters removed and readmission left out, for the corners only: a
// lone sample near a narrow tip stands apart from the rest and off the plane of
// its neighbours 10-25 cm back, yet the corner's own surface, fitted over far more
// of the sail, can still take it (extractOutline tests each).
std::vector<Vec3> removeOutliers(Cloud& cloud, const std::vector<uint32_t>& represents, const AnalysisParams& p,
                                 const Progress& progress, SailAnalysis& a) {
  // Cleaning keeps indices into the segmented cloud, so that the points the
  // filters removed only for being sparse can come back afterwards.
  const Cloud segmented = cloud;
  std::vector<uint32_t> kept(segmented.size());
  for (uint32_t i = 0; i < kept.size(); ++i) kept[i] = i;
  auto keepOnly = [&](const std::vector<uint32_t>& local) {
    std::vector<uint32_t> next;
    next.reserve(local.size());
    for (uint32_t j : local) next.push_back(kept[j]);
    kept = std::move(next);
    cloud = selectPoints(segmented, kept);
  };
  // Both outlier tests read one neighbour table: the radius test's rows on what the
  // statistical test kept are the kept part of the same rows.
  const size_t stat_k = static_cast<size_t>(std::max(0, p.statistical.k_neighbours)) + 1;
  const size_t radius_k = static_cast<size_t>(std::max(0, p.radius.min_neighbours)) + 1;
  const size_t table_k = std::max(p.statistical_outliers ? stat_k : 0, p.radius_outliers ? radius_k : 0);
  const bool share = p.statistical_outliers && p.radius_outliers && table_k <= cloud.size() &&
                     p.statistical.k_neighbours >= 1 && p.radius.min_neighbours >= 1;
  NeighbourTable table;
  if (p.statistical_outliers) {
    StageTimer t(a, "statistical outliers", cloud.size());
    if (share)
      table = nearestNeighbours(cloud.points, table_k, progress);
    const Cleaning c = share ? removeStatisticalOutliers(cloud, table, p.statistical, progress)
                             : removeStatisticalOutliers(cloud, p.statistical, progress);
    table = share && c.kept.size() >= radius_k ? subsetTable(table, cloud.points, c.kept, radius_k) : NeighbourTable{};
    keepOnly(c.kept);
    t.finish(cloud.size(), c.warnings);
  }
  if (p.radius_outliers) {
    StageTimer t(a, "radius outliers", cloud.size());
    const Cleaning c = table.size() == cloud.size() && table.k >= radius_k
                           ? removeRadiusOutliers(cloud, table, p.radius, progress)
                           : removeRadiusOutliers(cloud, p.radius, progress);
    keepOnly(c.kept);
    t.finish(cloud.size(), c.warnings);
  }
  if ((p.statistical_outliers || p.radius_outliers) && p.readmit_surface_points && kept.size() < segmented.size()) {
    StageTimer t(a, "readmit surface points", cloud.size());
    const Cleaning c = readmitSurfacePoints(segmented, kept, readmitParams(p));
    kept = c.kept;
    cloud = selectPoints(segmented, kept);
    t.finish(cloud.size(), c.warnings);
  }
  a.working_points = cloud.size();
  a.sail_points = cloud.size();
  if (!represents.empty()) {
    a.sail_points = 0;
    for (uint32_t i : kept) a.sail_points += represents[i];
  }
  std::vector<Vec3> removed;
  std::vector<char> in(segmented.size(), 0);
  for (uint32_t i : kept) in[i] = 1;
  for (uint32_t i = 0; i < segmented.size(); ++i)
    if (!in[i]) removed.push_back(segmented.points[i]);
  return removed;
}

// The surface stage: a.mesh from `cloud`; the points it left out join `loose`.
void meshSurface(const Cloud& cloud, const AnalysisParams& p, const Progress& progress, SailAnalysis& a,
                 std::vector<Vec3>& loose) {
  StageTimer t(a, "surface", cloud.size());
  Surface s = reconstructSurface(cloud, p.surface, progress);
  a.mesh = std::move(s.mesh);
  std::vector<char> meshed(cloud.size(), 0);
  for (uint32_t i : s.vertex_source) meshed[i] = 1;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (!meshed[i]) loose.push_back(cloud.points[i]);
  t.finish(a.mesh.vertices.size(), s.warnings);
}

// Where the scanner stood: the cloud's viewpoint, else (p.estimate_viewpoint) the
// position its samples' density tells, recorded in a.viewpoint_estimate.
std::optional<Vec3> scannerPosition(const Cloud& cloud, const AnalysisParams& p, SailAnalysis& a) {
  if (cloud.viewpoint || !p.estimate_viewpoint) return cloud.viewpoint;
  StageTimer t(a, "scanner position", cloud.size());
  std::string why;
  ViewpointEstimateParams vp;
  vp.sensor_sigma_m = p.sensor_sigma_m;
  a.viewpoint_estimate = estimateViewpoint(cloud, vp, &why);
  std::vector<std::string> warnings;
  char line[400];
  if (const auto& e = a.viewpoint_estimate) {
    std::snprintf(line, sizeof line,
                  "the cloud does not say where the scanner stood: estimated from how its samples' density falls "
                  "with range at (%.2f, %.2f, %.2f) ± (%.2f, %.2f, %.2f) m%s",
                  e->position.x(), e->position.y(), e->position.z(), e->sigma_m.x(), e->sigma_m.y(), e->sigma_m.z(),
                  e->mirror_ambiguous ? ", or its mirror image through the surfaces (shadows are not looked for)" : "");
  } else {
    std::snprintf(line, sizeof line, "the cloud does not say where the scanner stood, nor can it be estimated: %s",
                  why.c_str());
  }
  warnings.emplace_back(line);
  t.finish(cloud.size(), warnings);
  return a.viewpoint_estimate ? std::optional<Vec3>(a.viewpoint_estimate->position) : std::nullopt;
}

// The outline stage: a.outline and a.luff from a.mesh, the corners read from the
// `loose` points too. `sail_scan`: the sail's own samples when the sweep lost lines.
void outlineSail(const Cloud& input, const std::optional<Vec3>& scanner, const Cloud& sail_scan,
                 const std::vector<Vec3>& scan_points, const std::vector<Vec3>& scene, const AnalysisParams& p,
                 SailAnalysis& a, std::vector<Vec3>& loose) {
  StageTimer t(a, "outline", a.mesh.vertices.size());
  // A column mean at a narrow tip lies up to half a column short of the tip's outermost
  // samples: the corners read the scan's own points, at the scan's density.
  double sample_density = 0;
  if (!scan_points.empty()) {
    loose.insert(loose.end(), scan_points.begin(), scan_points.end());
    sample_density = static_cast<double>(a.sail_points) / std::max(1e-12, meshArea(a.mesh));
  }
  // A scan that says which scanner took it tells where it ran out of range.
  OutlineParams op = p.outline;
  if (op.scanner_max_range_m == 0) op.scanner_max_range_m = input.scanner_range_m;
  if (a.viewpoint_estimate)
    op.scanner_position_sigma_m = std::max(op.scanner_position_sigma_m, a.viewpoint_estimate->sigma_m.norm());
  a.outline = extractOutline(a.mesh, op, loose, sample_density, scanner, scene);
  for (std::string& w : widenCornersBesideLostLines(a.outline, sail_scan)) a.outline.warnings.push_back(std::move(w));
  a.luff = measureLuffCurve(a.outline);
  t.finish(a.outline.boundary.size(), a.outline.warnings);
}

// The sections stage: a.sections from a.mesh and a.outline, their noise model
// from the smoothing's neighbourhoods when there was smoothing.
void measureSections(const AnalysisParams& p, SailAnalysis& a) {
  StageTimer t(a, "sections", a.mesh.vertices.size());
  a.sections = cutSections(a.mesh, a.outline, sectionParamsFor(p, a));
  t.finish(a.sections.sections.size(), a.sections.warnings);
}

}  // namespace

SectionParams sectionParamsFor(const AnalysisParams& p, const SailAnalysis& a) {
  SectionParams sp = p.sections;
  sp.sensor_sigma_m = p.sensor_sigma_m;
  if (p.smooth) {
    sp.noise_correlation_m = a.smoothing_stats.mean_radius_m;
    // A quadratic fitted to k points of noise σ over a disc is known at its centre to
    // 2σ/√k (the constant term's variance, 4σ²/k, with the curvature terms free).
    const Smoothing& sm = a.smoothing_stats;
    if (sm.k_used > 0) sp.surface_sigma_m = 2.0 * sm.measured_noise_m / std::sqrt(static_cast<double>(sm.k_used));
  }
  return sp;
}

void refuseImplausibleResults(const SailAnalysis& a) {
  const SailOutline& o = a.outline;
  const std::pair<double, const char*> lengths[] = {{o.luff_length_m, "the luff"},
                                                    {o.leech_length_m, "the leech"},
                                                    {o.foot_length_m, "the foot"},
                                                    {o.top_length_m, "the top edge"}};
  for (const auto& [value, name] : lengths)
    if (auto why = implausibleLength(value, name)) throw AnalysisError("[analyzeSail] " + *why);
  if (auto why = implausibleArea(o.area_m2, "the area")) throw AnalysisError("[analyzeSail] " + *why);
  for (const Vec3& c : {o.tack, o.clew, o.head, o.peak})
    if (!c.allFinite()) throw AnalysisError("[analyzeSail] a corner's position is not a number");
  // An end angle read from too few points is NaN, "not measured" (sections.hpp); the
  // section's chord, camber, draft and twist are always numbers, and no value is infinite.
  for (const Section& s : a.sections.sections) {
    const SectionParameters& v = s.value;
    const bool core_finite = std::isfinite(v.chord_m) && std::isfinite(v.camber_pct) && std::isfinite(v.draft_pct) &&
                             std::isfinite(v.twist_deg);
    if (!core_finite || std::isinf(v.entry_deg) || std::isinf(v.exit_deg))
      throw AnalysisError("[analyzeSail] section " + formatFixed(s.fraction, 2) + " has a value that is not a number");
  }
}

Cloud sailSamples(const Cloud& input, const AnalysisParams& p, const Progress& progress) {
  checkAnalysisParams(input, p);
  SailAnalysis a;
  Cloud cloud = input;
  if (looksForMixedPixels(cloud, p)) cloud = selectPoints(cloud, removeMixedPixels(cloud, mixedPixelParams(p)).kept);
  if (p.segment) segmentSail(cloud, p, progress, a);
  removeOutliers(cloud, {}, p, progress, a);
  return cloud;
}

SailAnalysis analyzeSail(const Cloud& input, const AnalysisParams& p, const Progress& progress,
                         SailAnalysis* surface_only) {
  checkAnalysisParams(input, p);
  SailAnalysis a;
  a.points_in = input.size();
  Cloud cloud = input;

  if (looksForMixedPixels(cloud, p)) {
    StageTimer t(a, "mixed pixels", cloud.size());
    const Cleaning c = removeMixedPixels(cloud, mixedPixelParams(p));
    cloud = selectPoints(cloud, c.kept);
    t.finish(cloud.size(), c.warnings);
  }
  const std::optional<Vec3> scanner = scannerPosition(cloud, p, a);
  // What the scanner saw, for the shadows things in the way cast on the sail; not
  // when the scanner may have stood on the surfaces' other side.
  std::vector<Vec3> scene;
  if (input.viewpoint || (a.viewpoint_estimate && !a.viewpoint_estimate->mirror_ambiguous)) scene = cloud.points;
  if (p.segment) segmentSail(cloud, p, progress, a);

  // The sail's own samples, with their scan angles, when the sweep lost lines: a
  // corner's line is the line of the sail sample nearest it (not the boom's below a tack).
  Cloud sail_scan;
  if (!input.lost_beta_rad.empty()) sail_scan = cloud;

  const WorkingResolution working = toWorkingResolution(cloud, p, a);
  // The removed samples, and later the smoothed sail points the mesh left out.
  std::vector<Vec3> loose = removeOutliers(cloud, working.represents, p, progress, a);

  if (p.smooth) {
    StageTimer t(a, "smoothing", cloud.size());
    SmoothingParams sp = p.smoothing;
    Smoothing s = smoothMls(cloud, sp, progress);
    cloud = std::move(s.cloud);
    s.cloud = Cloud{};
    a.smoothing_stats = s;
    t.finish(cloud.size(), s.warnings);
  }
  meshSurface(cloud, p, progress, a, loose);
  bool outlined = false;
  try {
    outlineSail(input, scanner, sail_scan, working.scan_points, scene, p, a, loose);
    outlined = true;
    measureSections(p, a);
    refuseImplausibleResults(a);
  } catch (const AnalysisError&) {
    if (surface_only) {
      if (!outlined || !a.sections.sections.empty()) a.outline = SailOutline{};
      a.sections = SectionAnalysis{};
      a.luff = LuffCurve{};
      a.sail_cloud = std::move(cloud);
      *surface_only = std::move(a);
    }
    throw;
  }
  progress("done", 1.0);
  a.sail_cloud = std::move(cloud);
  return a;
}

}  // namespace sailshape
