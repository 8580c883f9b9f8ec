#include "analysis/fit/design_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "analysis/core/errors.hpp"
#include "analysis/core/plausible.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/fit/fit_internal.hpp"
#include "analysis/registration/icp.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape {

using namespace fit_detail;

namespace {

void checkInput(const Mesh& design, const std::vector<Vec3>& samples, const DesignFitParams& p) {
  if (design.triangles.empty()) throw InvalidInput("[fitDesign] the design has no triangles");
  for (const auto& t : design.triangles)
    for (uint32_t v : t)
      if (v >= design.vertices.size())
        throw InvalidInput("[fitDesign] the design has a triangle with vertex index " + std::to_string(v) + " of " +
                           std::to_string(design.vertices.size()) + " vertices");
  for (size_t i = 0; i < design.vertices.size(); ++i)
    if (!design.vertices[i].allFinite())
      throw InvalidInput("[fitDesign] design vertex " + std::to_string(i) + " has a non-finite coordinate");
  if (samples.empty()) throw InvalidInput("[fitDesign] the flying cloud has no points");
  for (size_t i = 0; i < samples.size(); ++i)
    if (!samples[i].allFinite())
      throw InvalidInput("[fitDesign] flying point " + std::to_string(i) + " has a non-finite coordinate");
  if (auto why = implausibleCoordinates(samples, "the flying cloud")) throw InvalidInput("[fitDesign] " + *why);
  if (auto why = implausibleCoordinates(design.vertices, "the design")) throw InvalidInput("[fitDesign] " + *why);
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v))
      throw InvalidInput(std::string("[fitDesign] ") + name + " must be > 0 (got " + std::to_string(v) + ")");
  };
  positive(p.sensor_sigma_m, "sensor_sigma_m");
  positive(p.bending_length_m, "bending_length_m");
  positive(p.membrane_length_m, "membrane_length_m");
  positive(p.rigid_max_correspondence_m, "rigid_max_correspondence_m");
  positive(p.rigid_max_move_m, "rigid_max_move_m");
  positive(p.max_plausible_strain_pct, "max_plausible_strain_pct");
  positive(p.max_median_distance_of_extent, "max_median_distance_of_extent");
  if (!(p.initial_stiffness >= 1)) throw InvalidInput("[fitDesign] initial_stiffness must be >= 1");
  if (!(p.support_radius_m >= 0)) throw InvalidInput("[fitDesign] support_radius_m must be >= 0 (0: automatic)");
  if (!(p.camber_change_prior >= 0)) throw InvalidInput("[fitDesign] camber_change_prior must be >= 0");
  if (p.outer_iterations < 1 || p.outer_iterations > 100)
    throw InvalidInput("[fitDesign] outer_iterations must be in [1, 100] (got " + std::to_string(p.outer_iterations) +
                       ")");
}

// At most `limit` of the samples, evenly strided (the rigid stage needs no more).
std::vector<Vec3> strided(const std::vector<Vec3>& points, size_t limit) {
  if (points.size() <= limit) return points;
  std::vector<Vec3> out;
  const double step = static_cast<double>(points.size()) / static_cast<double>(limit);
  for (size_t k = 0; k < limit; ++k) out.push_back(points[static_cast<size_t>(static_cast<double>(k) * step)]);
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double diagonal(const std::vector<Vec3>& pts) {
  Vec3 lo = pts.front(), hi = pts.front();
  for (const Vec3& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// Refuses samples that lie nowhere near the design: another sail, or another frame or unit.
void checkNearDesign(const Mesh& design, const std::vector<Vec3>& sub, const DesignFitParams& p) {
  const DesignDistance dd(design);
  std::vector<double> d(sub.size());
  for (size_t i = 0; i < sub.size(); ++i) d[i] = std::abs(dd.signedDistance(sub[i]));
  const double med = median(d), extent = diagonal(design.vertices);
  if (med > p.max_median_distance_of_extent * extent)
    throw InvalidInput("[fitDesign] the flying cloud lies " + formatFixed(med, 2) +
                       " m from the design (median distance; the design is " + formatFixed(extent, 2) +
                       " m across): not this sail, or not in the boat frame");
}

// The rigid stage: point-to-plane ICP of the samples onto the design's surface, from the
// identity; returns design → samples' frame.
RigidTransform alignRigidly(const Mesh& design, const std::vector<Vec3>& sub, const DesignFitParams& p,
                            const Progress& progress, DesignFit& out) {
  Cloud reference = sampleMesh(design, 10'000, 1);
  Cloud moving;
  moving.points = strided(sub, 3000);
  IcpParams ip;
  ip.max_correspondence_m = p.rigid_max_correspondence_m;
  ip.min_robust_scale_m = p.sensor_sigma_m;
  // A design's own surface is smooth but curved over the neighbourhood of its samples.
  ip.max_curvature = 0.05;
  ip.max_normal_angle_deg = 45;
  ip.max_iterations = 30;
  // A step under a tenth of a millimetre and 0.005° (0.9 mm over 10 m) is the pairs' noise
  // moving the pose, not a better pose: the ICP has converged.
  ip.min_step_translation_m = 1e-4;
  ip.min_step_rotation_deg = 0.005;
  const IcpResult icp = refineIcp(reference, moving, RigidTransform::Identity(), ip, progress);
  out.rigid_rms_m = icp.rms_m;
  for (const std::string& w : icp.warnings) out.warnings.push_back("rigid alignment: " + w);
  const RigidTransform t = icp.transform.inverse();
  double moved = 0;
  for (const Vec3& v : design.vertices) moved = std::max(moved, (t * v - v).norm());
  if (moved > p.rigid_max_move_m) {
    out.warnings.push_back("rigid alignment would move the design by up to " + formatFixed(moved, 2) +
                           " m: kept where it stands (a changed shape slides along itself; a misplaced design "
                           "needs moving before the fit)");
    out.rigid_rms_m = 0;
    return RigidTransform::Identity();
  }
  return t;
}

StrainStats strainStats(const std::vector<double>& strain, const std::vector<char>* keep) {
  std::vector<double> v;
  for (size_t e = 0; e < strain.size(); ++e)
    if (!keep || (*keep)[e]) v.push_back(strain[e]);
  StrainStats s;
  s.edges = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0, sum2 = 0;
  for (double x : v) {
    sum += x;
    sum2 += x * x;
  }
  auto pct = [&v](double q) { return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5)]; };
  s.mean_pct = sum / static_cast<double>(v.size());
  s.rms_pct = std::sqrt(sum2 / static_cast<double>(v.size()));
  s.p5_pct = pct(0.05);
  s.p95_pct = pct(0.95);
  s.min_pct = v.front();
  s.max_pct = v.back();
  return s;
}

}  // namespace

namespace {

// Median distance between a sample and its nearest other sample, from up to 2000 of them.
double medianSampleSpacing(const KdTree& tree, const std::vector<Vec3>& samples) {
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  std::vector<double> d;
  for (const Vec3& p : strided(samples, 2000)) {
    tree.nearest(p, 2, idx, d2);
    if (d2.size() == 2) d.push_back(std::sqrt(d2[1]));
  }
  return median(d);
}

std::vector<double> nearestSampleDistances(const KdTree& tree, const std::vector<Vec3>& x) {
  std::vector<double> d(x.size());
#pragma omp parallel
  {
    std::vector<uint32_t> idx;
    std::vector<double> d2;
#pragma omp for schedule(static)
    for (size_t v = 0; v < x.size(); ++v) {
      tree.nearest(x[v], 1, idx, d2);
      d[v] = std::sqrt(d2.front());
    }
  }
  return d;
}

// Samples that count in this iteration: within `gate` of their foot and off the surface
// along its normal (a sample beyond the mesh's edge has its foot on the boundary and lies
// off it sideways: it says nothing about where the surface stands).
std::vector<char> gateSamples(const std::vector<Vec3>& samples, const std::vector<Foot>& feet, double gate,
                              double sigma) {
  std::vector<char> use(samples.size(), 0);
  for (size_t s = 0; s < samples.size(); ++s) {
    const Foot& f = feet[s];
    if (f.triangle < 0 || f.distance_m > gate) continue;
    const double along = std::abs(f.normal.dot(samples[s] - f.point));
    use[s] = f.distance_m <= 3 * sigma || along >= 0.7 * f.distance_m;
  }
  return use;
}

double robustScale(const std::vector<Foot>& feet, const std::vector<char>* use) {
  std::vector<double> d;
  for (size_t s = 0; s < feet.size(); ++s)
    if (feet[s].triangle >= 0 && (!use || (*use)[s])) d.push_back(feet[s].distance_m);
  return 1.4826 * median(d);
}

// Per-vertex σ. A supported vertex's position is, through the data term, a weighted mean of
// the samples on its triangles (their barycentric weights summing to n_eff): σ = noise/√n_eff,
// never more than the noise itself. Beyond the samples the fit continues the supported
// surface, and what no sample says there is how the surface turns and bends: its slope
// relative to the design's may change by as much as it changed where the samples are (g,
// the RMS angle between the fitted and the design's normals over the supported vertices),
// which moves a surface continued over a distance d by g·d; and its curvature may be off by
// Δκ (the prior), which deflects it by ½·Δκ·d². The three add in quadrature.
std::vector<double> vertexSigmas(const Mesh& m, const Mesh& design, const std::vector<Foot>& feet,
                                 const std::vector<char>& use, const std::vector<char>& supported,
                                 const std::vector<double>& support_distance, double noise, double dkappa,
                                 std::vector<double>& slope_sigma, double& turn) {
  std::vector<double> n_eff(m.vertices.size(), 0.0);
  for (size_t s = 0; s < feet.size(); ++s)
    if (use[s])
      for (int k = 0; k < 3; ++k) n_eff[m.triangles[static_cast<size_t>(feet[s].triangle)][k]] += feet[s].bary[k];
  const std::vector<Vec3> fitted_normal = vertexNormals(m), design_normal = vertexNormals(design);
  double turn2 = 0;
  size_t turned = 0;
  for (size_t v = 0; v < m.vertices.size(); ++v)
    if (supported[v]) {
      // Unsigned: a mesh's normals may face either way.
      const double c = std::min(1.0, std::abs(fitted_normal[v].dot(design_normal[v])));
      turn2 += std::pow(std::acos(c), 2);
      ++turned;
    }
  const double g = turned ? std::sqrt(turn2 / static_cast<double>(turned)) : 0.0;
  turn = g;
  std::vector<double> sigma(m.vertices.size());
  slope_sigma.assign(m.vertices.size(), 0.0);
  for (size_t v = 0; v < sigma.size(); ++v) {
    const double d = supported[v] ? 0.0 : support_distance[v];
    const double turned_by = g * d;
    const double continued = 0.5 * dkappa * d * d;
    sigma[v] = std::sqrt(noise * noise / std::max(1.0, n_eff[v]) + turned_by * turned_by + continued * continued);
    // The slope's σ is the two terms' rate along d: the turn g and the curvature's Δκ·d.
    slope_sigma[v] = supported[v] ? 0.0 : std::hypot(g, dkappa * d);
  }
  return sigma;
}

void strainAndWarnings(const Mesh& design, const Topology& top, const DesignFitParams& p, DesignFit& out) {
  const std::vector<Vec3>& x = out.fitted.vertices;
  out.edges = top.edges;
  out.edge_strain_pct.resize(top.edges.size());
  std::vector<char> both_supported(top.edges.size());
  size_t over = 0, over_unsupported = 0;
  size_t worst = 0;
  for (size_t e = 0; e < top.edges.size(); ++e) {
    const uint32_t i = top.edges[e][0], j = top.edges[e][1];
    const double l0 = (design.vertices[i] - design.vertices[j]).norm();
    out.edge_strain_pct[e] = l0 > 0 ? 100.0 * ((x[i] - x[j]).norm() / l0 - 1.0) : 0.0;
    both_supported[e] = out.supported[i] && out.supported[j];
    if (out.edge_strain_pct[e] > p.max_plausible_strain_pct) {
      ++over;
      if (!both_supported[e]) ++over_unsupported;
    }
    if (out.edge_strain_pct[e] > out.edge_strain_pct[worst]) worst = e;
  }
  out.strain = strainStats(out.edge_strain_pct, nullptr);
  out.strain_supported = strainStats(out.edge_strain_pct, &both_supported);
  if (over > 0) {
    const Vec3 at = 0.5 * (x[top.edges[worst][0]] + x[top.edges[worst][1]]);
    out.warnings.push_back(
        std::to_string(over) + " of " + std::to_string(top.edges.size()) + " edges stretched beyond " +
        formatFixed(p.max_plausible_strain_pct, 1) + " % (" + std::to_string(over_unsupported) +
        " where the scan has no samples); the largest, " + formatFixed(out.edge_strain_pct[worst], 1) + " % at (" +
        formatFixed(at.x(), 2) + ", " + formatFixed(at.y(), 2) + ", " + formatFixed(at.z(), 2) +
        ") m, is more than sailcloth stretches: the design may not be this sail, or the scan holds something else");
  }
}

}  // namespace

DesignFit fitDesign(const Mesh& design, const std::vector<Vec3>& samples, const DesignFitParams& p,
                    const Progress& progress) {
  checkInput(design, samples, p);
  DesignFit out;
  out.samples = samples.size();
  const std::vector<Vec3> sub = strided(samples, 20'000);
  checkNearDesign(design, strided(sub, 2000), p);
  progress("rigid alignment", 0.0);
  Mesh aligned = design;
  if (p.rigid) {
    const RigidTransform t = alignRigidly(design, sub, p, {}, out);
    for (Vec3& v : aligned.vertices) v = t * v;
    out.rigid = t.matrix();
  }
  const Topology top = meshTopology(aligned);
  const RegulariserPtr reg = buildRegulariser(aligned, top, p.membrane_length_m, p.bending_length_m);
  const KdTree sample_tree(samples);

  out.support_radius_m = p.support_radius_m > 0 ? p.support_radius_m : 3.0 * medianSampleSpacing(sample_tree, samples);
  const std::vector<double> area = vertexAreas(aligned);
  const double total_area = std::accumulate(area.begin(), area.end(), 0.0);
  // Each sample stands for the supported area over the number of samples (m²).
  double supported_area = 0;
  {
    const std::vector<double> d0 = nearestSampleDistances(sample_tree, aligned.vertices);
    for (size_t v = 0; v < d0.size(); ++v)
      if (d0[v] <= out.support_radius_m) supported_area += area[v];
  }
  const double sample_area = std::max(supported_area, 0.05 * total_area) / static_cast<double>(samples.size());

  std::vector<Vec3> x = aligned.vertices;
  const int iterations = p.outer_iterations;
  const double ramp = std::max(1.0, iterations / 2.0 - 1.0);
  std::vector<Foot> feet;
  std::vector<char> use;
  const StepSolverPtr solver = makeStepSolver();
  // The stiff first iterations only bring the surface near the samples, smoothly: a quarter of
  // the samples (still several per vertex on a scan denser than the design) does that as well.
  const std::vector<Vec3> coarse = strided(samples, std::max<size_t>(samples.size() / 4, 1));
  const double coarse_area = sample_area * static_cast<double>(samples.size()) / static_cast<double>(coarse.size());
  for (int it = 0; it < iterations; ++it) {
    const double stiffness = std::pow(p.initial_stiffness, std::max(0.0, 1.0 - it / ramp));
    const bool stiff = stiffness > 2 && coarse.size() >= aligned.vertices.size();
    const std::vector<Vec3>& pts = stiff ? coarse : samples;
    feet = findFeet(aligned, x, top, pts);
    const double gate = std::max(3.0 * p.sensor_sigma_m, 3.0 * robustScale(feet, nullptr));
    use = gateSamples(pts, feet, gate, p.sensor_sigma_m);
    x = deformStep(*reg, aligned, top, x, pts, feet, use, stiff ? coarse_area : sample_area, stiffness, *solver);
    progress("fitting the design", static_cast<double>(it + 1) / iterations);
  }
  out.iterations = iterations;
  out.fitted = Mesh{x, design.triangles};

  // The result's own residuals, with the gate of the noise it leaves.
  feet = findFeet(aligned, x, top, samples);
  use = gateSamples(samples, feet, std::max(3.0 * p.sensor_sigma_m, 3.0 * robustScale(feet, nullptr)),
                    p.sensor_sigma_m);
  double sum2 = 0;
  for (size_t s = 0; s < samples.size(); ++s)
    if (use[s]) {
      sum2 += feet[s].distance_m * feet[s].distance_m;
      ++out.samples_used;
    }
  out.rms_m = out.samples_used ? std::sqrt(sum2 / static_cast<double>(out.samples_used)) : 0.0;
  out.noise_m = robustScale(feet, &use);

  out.support_distance_m = nearestSampleDistances(sample_tree, x);
  out.supported.resize(x.size());
  double covered = 0;
  for (size_t v = 0; v < x.size(); ++v) {
    out.supported[v] = out.support_distance_m[v] <= out.support_radius_m;
    if (out.supported[v]) covered += area[v];
  }
  out.coverage = total_area > 0 ? covered / total_area : 0.0;
  out.displacement_m.resize(x.size());
  for (size_t v = 0; v < x.size(); ++v) out.displacement_m[v] = x[v] - design.vertices[v];
  const double mean_chord = total_area / std::max(1e-9, diagonal(design.vertices));
  out.sigma_m = vertexSigmas(out.fitted, aligned, feet, use, out.supported, out.support_distance_m,
                             std::max(out.noise_m, 1e-6), 8.0 * p.camber_change_prior / mean_chord,
                             out.slope_sigma_rad, out.turn_rad);
  // Far from the samples σ grows as g·d and ½·Δκ·d² without bound; the flying sail strays from its
  // design by no more than a plausible trim (plausibleTrimDeviationM, taken as 2σ), so a vertex lies
  // no farther from it than from the design plus that. A design without height has no such bound.
  double trim_sigma = HUGE_VAL;
  try {
    trim_sigma = 0.5 * plausibleTrimDeviationM(design);
  } catch (const InvalidInput&) {
  }
  for (size_t v = 0; v < out.sigma_m.size(); ++v)
    out.sigma_m[v] = std::min(out.sigma_m[v], (out.fitted.vertices[v] - aligned.vertices[v]).norm() + trim_sigma);
  strainAndWarnings(design, top, p, out);
  if (out.samples_used < samples.size() / 2)
    out.warnings.push_back("only " + std::to_string(out.samples_used) + " of " + std::to_string(samples.size()) +
                           " flying points lie on the fitted surface within the noise: the rest are not this sail");
  progress("fitting the design", 1.0);
  return out;
}

VertexMoves vertexMoves(const Mesh& design, const DesignFit& fit, const Vec3& leeward) {
  if (fit.displacement_m.size() != design.vertices.size())
    throw InvalidInput("[vertexMoves] a fit of " + std::to_string(fit.displacement_m.size()) + " vertices for a design of " +
                       std::to_string(design.vertices.size()));
  const std::vector<Vec3> normals = vertexNormals(design);
  VertexMoves m;
  m.normal_m.resize(normals.size());
  m.along_m.resize(normals.size());
  for (size_t v = 0; v < normals.size(); ++v) {
    const Vec3 n = normals[v].dot(leeward) < 0 ? Vec3(-normals[v]) : normals[v];
    const Vec3& d = fit.displacement_m[v];
    m.normal_m[v] = d.dot(n);
    m.along_m[v] = (d - m.normal_m[v] * n).norm();
  }
  return m;
}

std::vector<double> vertexStretchPct(const DesignFit& fit) {
  std::vector<double> stretch(fit.fitted.vertices.size(), 0.0);
  std::vector<int> edges_at(stretch.size(), 0);
  for (size_t e = 0; e < fit.edges.size() && e < fit.edge_strain_pct.size(); ++e)
    for (uint32_t v : fit.edges[e]) {
      stretch[v] += fit.edge_strain_pct[e];
      ++edges_at[v];
    }
  for (size_t v = 0; v < stretch.size(); ++v)
    if (edges_at[v] > 0) stretch[v] /= edges_at[v];
  return stretch;
}

}  // namespace sailshape
