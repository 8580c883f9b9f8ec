#include "analysis/registration/pose_verification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/segmentation/mixed_pixels.hpp"
#include "analysis/spatial/normals.hpp"

namespace sailshape {
namespace {

// z with P(N(0,1) > z) = α, by bisection on the tail.
double upperQuantile(double alpha) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = (lo + hi) / 2;
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

}  // namespace

// One cloud as the other is scored against: its points, tangent planes, the
// nearest range its beams met in every direction (free space lies before it),
// and its samples.
struct PoseVerifier::Side {
  Cloud cloud;
  KdTree tree;
  std::vector<Vec3> normals;
  std::vector<uint32_t> samples;
  Vec3 origin = Vec3::Zero();
  bool has_viewpoint = false;
  double longest_range_m = 1;
  // Range image about the viewpoint: bins of bin_rad in azimuth and elevation,
  // each holding the nearest return's range (∞: no return there).
  double bin_rad = 0;
  int n_az = 0, n_el = 0;
  std::vector<float> nearest_range, farthest_range;

  // Mixed pixels (SPEC §3: a beam straddling an edge returns a range between
  // the surfaces) hang in the free space before the farther surface, where a
  // right pose then seems to put points: they are left out when the scan
  // angles allow finding them.
  static Cloud withoutMixedPixels(const Cloud& c, double sigma_m) {
    if (!c.hasScanAngles() || !c.viewpoint) return c;
    MixedPixelParams mp;
    mp.sensor_sigma_m = sigma_m;
    return selectPoints(c, removeMixedPixels(c, mp).kept);
  }

  Side(const Cloud& input, size_t sample_count, double sigma_m)
      : cloud(withoutMixedPixels(input, sigma_m)), tree(cloud.points), has_viewpoint(cloud.viewpoint.has_value()) {
    const Cloud& c = cloud;
    if (has_viewpoint) origin = *c.viewpoint;
    if (!has_viewpoint) {  // the fallback scores distances to the tangent planes
      NormalParams np;
      np.k_neighbours = 12;
      np.orientation = "none";
      np.robust = false;
      normals = estimateNormals(c, np).normals.normals;
    }
    const double step = static_cast<double>(c.size()) / static_cast<double>(std::min(sample_count, c.size()));
    for (double x = 0; static_cast<size_t>(x) < c.size(); x += step) samples.push_back(static_cast<uint32_t>(x));
    for (const Vec3& q : c.points) longest_range_m = std::max(longest_range_m, (q - origin).norm());
    if (has_viewpoint) buildRangeImage();
  }

  // The bin size follows the scan's own angular spacing (nearest-neighbour
  // distance over range, median over the samples), doubled so most bins hold a
  // return: finer bins would leave holes, coarser ones blur free space at edges.
  void buildRangeImage() {
    std::vector<double> spacing;
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    for (size_t i = 0; i < samples.size(); i += std::max<size_t>(1, samples.size() / 500)) {
      const Vec3& q = cloud.points[samples[i]];
      tree.nearest(q, 2, idx, d2);
      const double r = (q - origin).norm();
      if (d2.size() == 2 && r > 0) spacing.push_back(std::sqrt(d2[1]) / r);
    }
    if (spacing.empty()) return;
    std::nth_element(spacing.begin(), spacing.begin() + static_cast<long>(spacing.size() / 2), spacing.end());
    bin_rad = std::clamp(2 * spacing[spacing.size() / 2], 0.1 * kRadPerDeg, 5 * kRadPerDeg);
    n_az = static_cast<int>(std::ceil(2 * M_PI / bin_rad));
    n_el = static_cast<int>(std::ceil(M_PI / bin_rad));
    const size_t cells = static_cast<size_t>(n_az) * static_cast<size_t>(n_el);
    nearest_range.assign(cells, std::numeric_limits<float>::infinity());
    farthest_range.assign(cells, -std::numeric_limits<float>::infinity());
    for (const Vec3& q : cloud.points) {
      int a, e;
      double r;
      bin(q, a, e, r);
      const size_t cell = static_cast<size_t>(e) * static_cast<size_t>(n_az) + static_cast<size_t>(a);
      nearest_range[cell] = std::min(nearest_range[cell], static_cast<float>(r));
      farthest_range[cell] = std::max(farthest_range[cell], static_cast<float>(r));
    }
  }

  void bin(const Vec3& q, int& a, int& e, double& r) const {
    const Vec3 d = q - origin;
    r = d.norm();
    const double az = std::atan2(d.y(), d.x()), el = r > 0 ? std::asin(std::clamp(d.z() / r, -1.0, 1.0)) : 0.0;
    a = std::clamp(static_cast<int>((az + M_PI) / bin_rad), 0, n_az - 1);
    e = std::clamp(static_cast<int>((el + M_PI / 2) / bin_rad), 0, n_el - 1);
  }

  // Where q (this side's frame) lies along this unit's beam towards it: the
  // returns in its bin and the bins around span [near, far] (the nine bins, so a
  // surface's slope or an edge never reads as free space). No return in its own
  // bin: nothing was seen that way (false).
  bool rangesAround(const Vec3& q, double& range, double& near, double& far) const {
    if (nearest_range.empty()) return false;
    int a, e;
    bin(q, a, e, range);
    auto cell = [&](int aa, int ee) {
      return static_cast<size_t>(ee) * static_cast<size_t>(n_az) + static_cast<size_t>((aa + n_az) % n_az);
    };
    if (!std::isfinite(nearest_range[cell(a, e)])) return false;
    near = std::numeric_limits<double>::infinity();
    far = -near;
    for (int ee = std::max(0, e - 1); ee <= std::min(n_el - 1, e + 1); ++ee)
      for (int aa = a - 1; aa <= a + 1; ++aa) {
        if (!std::isfinite(nearest_range[cell(aa, ee)])) continue;
        near = std::min(near, static_cast<double>(nearest_range[cell(aa, ee)]));
        far = std::max(far, static_cast<double>(farthest_range[cell(aa, ee)]));
      }
    return true;
  }
};

PoseVerifier::PoseVerifier(const Cloud& reference, const Cloud& moving, const PoseVerificationParams& p) : p_(p) {
  auto bad = [](const std::string& what) { throw InvalidInput("[PoseVerifier] " + what); };
  if (!(p.sigma_m > 0)) bad("sigma_m must be > 0 (got " + std::to_string(p.sigma_m) + ")");
  if (!(p.systematic_fraction >= 0)) bad("systematic_fraction must be >= 0");
  if (!(p.free_space_outlier_rate > 0 && p.free_space_outlier_rate < 1)) bad("free_space_outlier_rate must be in (0, 1)");
  if (!(p.false_accept_probability > 0 && p.false_accept_probability < 0.5))
    bad("false_accept_probability must be in (0, 0.5)");
  if (p.samples_per_cloud < 10) bad("samples_per_cloud must be >= 10");
  if (!(p.match_radius_m > 0)) bad("match_radius_m must be > 0");
  if (!(p.coincidence_cell_m > 0)) bad("coincidence_cell_m must be > 0");
  if (reference.size() < 20 || moving.size() < 20)
    bad("both clouds need at least 20 points (reference " + std::to_string(reference.size()) + ", moving " +
        std::to_string(moving.size()) + ")");
  reference_ = std::make_unique<Side>(reference, p.samples_per_cloud, p.sigma_m);
  moving_ = std::make_unique<Side>(moving, p.samples_per_cloud, p.sigma_m);
}

PoseVerifier::~PoseVerifier() = default;

PoseEvidence PoseVerifier::evaluate(const RigidTransform& moving_to_reference, size_t samples_limit) const {
  PoseEvidence ev;
  const RigidTransform reference_to_moving = moving_to_reference.inverse();
  struct Job {
    const Side* from;
    const Side* other;
    const RigidTransform* to_other;
  };
  const Job jobs[2] = {{reference_.get(), moving_.get(), &reference_to_moving},
                       {moving_.get(), reference_.get(), &moving_to_reference}};
  const double r2 = p_.match_radius_m * p_.match_radius_m;

  for (const Job& job : jobs) {
    const size_t n = job.from->samples.size();
    const size_t stride = samples_limit == 0 || samples_limit >= n ? 1 : n / samples_limit;
    const long count = static_cast<long>((n + stride - 1) / stride);
    const double hidden = -std::log(job.other->longest_range_m);
    const double free = std::log(p_.free_space_outlier_rate) + hidden;
    std::vector<double> ell(static_cast<size_t>(count));
    std::vector<char> kind(static_cast<size_t>(count));
    std::vector<int64_t> cell(static_cast<size_t>(count), 0);
    const double cell_m = p_.coincidence_cell_m;
#pragma omp parallel if (count > 4000)
    {
      std::vector<uint32_t> idx;
      std::vector<double> d2;
#pragma omp for schedule(static)
      for (long s = 0; s < count; ++s) {
        const Vec3& own = job.from->cloud.points[job.from->samples[static_cast<size_t>(s) * stride]];
        const Vec3 q = *job.to_other * own;
        const double range_own = (own - job.from->origin).norm(), range_other = (q - job.other->origin).norm();
        const double ss = p_.systematic_fraction;
        const double sigma = std::sqrt(2 * p_.sigma_m * p_.sigma_m + ss * ss * (range_own * range_own + range_other * range_other));
        double l = hidden;
        char k = 1;
        double range, near, far;
        if (job.other->rangesAround(q, range, near, far)) {
          // The other unit saw returns between near and far that way: a point there
          // lies anywhere in that span (widened by the noise), one nearer sits in
          // the free space its beam crossed, one farther is hidden behind.
          const double margin = 3 * sigma;
          if (range < near - margin) {
            l = free;
            k = 2;
          } else if (range <= far + margin) {
            l = -std::log(far - near + 2 * margin);
            k = 0;
          }
        } else if (!job.other->has_viewpoint) {
          // No viewpoint, no beams: only the distance to the other's surface speaks.
          job.other->tree.nearest(q, 1, idx, d2);
          if (!d2.empty() && d2[0] <= r2) {
            const double d = job.other->normals[idx[0]].dot(q - job.other->cloud.points[idx[0]]) / sigma;
            const double on = -0.5 * d * d - std::log(std::sqrt(2 * M_PI) * sigma);
            if (on > hidden) {
              l = on;
              k = 0;
            }
          }
        }
        ell[static_cast<size_t>(s)] = l;
        kind[static_cast<size_t>(s)] = k;
        const auto c = [&](double x) { return static_cast<int64_t>(std::floor(x / cell_m)) & 0x1FFFFF; };
        cell[static_cast<size_t>(s)] = (c(q.x()) << 42) | (c(q.y()) << 21) | c(q.z());
      }
    }
    const double violation = std::log(p_.free_space_outlier_rate);
    struct CellTally {
      double best = 0;        // the largest log(L / span) of its coincident samples
      size_t on = 0, all = 0;
    };
    std::unordered_map<int64_t, CellTally> cells;
    for (size_t s = 0; s < ell.size(); ++s) {
      ev.consistency += ell[s];
      const double l = kind[s] == 2 ? violation : 0.0;
      ev.log_likelihood += l;
      ev.per_sample.push_back(l);
      (kind[s] == 0 ? ev.on_surface : kind[s] == 1 ? ev.hidden : ev.in_free_space)++;
      CellTally& t = cells[cell[s]];
      ++t.all;
      if (kind[s] == 0) {
        ++t.on;
        t.best = std::max(t.best, ell[s] - hidden);
      }
    }
    for (const auto& [key, t] : cells) {
      if (t.on == 0) continue;
      ev.coincidence += t.best * static_cast<double>(t.on) / static_cast<double>(t.all);
      ++ev.coincident_cells;
    }
  }
  ev.log_likelihood += ev.coincidence;
  return ev;
}

PoseComparison PoseVerifier::compare(const PoseEvidence& best, const PoseEvidence& other) const {
  if (best.per_sample.size() != other.per_sample.size())
    throw InvalidInput("[PoseVerifier::compare] the evidence holds different samples (" +
                       std::to_string(best.per_sample.size()) + " and " + std::to_string(other.per_sample.size()) + ")");
  PoseComparison c;
  const size_t n = best.per_sample.size();
  double sum = 0, sum2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = best.per_sample[i] - other.per_sample[i];
    sum += d;
    sum2 += d * d;
  }
  c.log_ratio = best.log_likelihood - other.log_likelihood;
  const double mean = n ? sum / static_cast<double>(n) : 0.0;
  const double var = n > 1 ? std::max(0.0, (sum2 - static_cast<double>(n) * mean * mean) / static_cast<double>(n - 1)) : 0.0;
  c.standard_error = std::sqrt(static_cast<double>(n) * var);
  c.needed = std::max(-std::log(p_.false_accept_probability), upperQuantile(p_.false_accept_probability) * c.standard_error);
  c.decisive = c.log_ratio > c.needed;
  return c;
}

std::string describePose(const RigidTransform& t) {
  const Eigen::AngleAxisd aa(t.linear());
  const Vec3& a = aa.axis();
  const Vec3& x = t.translation();
  return formatFixed(aa.angle() / kRadPerDeg, 2) + "° about (" + formatFixed(a.x()) + ", " + formatFixed(a.y()) + ", " +
         formatFixed(a.z()) + "), t = (" + formatFixed(x.x()) + ", " + formatFixed(x.y()) + ", " + formatFixed(x.z()) +
         ") m";
}

}  // namespace sailshape
