#include "analysis/registration/icp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/normals.hpp"

namespace sailshape {
namespace {

constexpr uint32_t kNone = 0xffffffffu;

void checkParams(const Cloud& reference, const Cloud& moving, const IcpParams& p) {
  auto bad = [](const std::string& what) { throw InvalidInput("[refineIcp] " + what); };
  if (p.method != "point-to-plane" && p.method != "point-to-point")
    bad("method must be point-to-plane or point-to-point (got '" + p.method + "')");
  if (p.max_iterations < 1) bad("max_iterations must be >= 1 (got " + std::to_string(p.max_iterations) + ")");
  if (!(p.max_correspondence_m > 0))
    bad("max_correspondence_m must be > 0 (got " + std::to_string(p.max_correspondence_m) + ")");
  if (p.normal_k < 3) bad("normal_k must be >= 3 (got " + std::to_string(p.normal_k) + ")");
  if (p.min_correspondences < 6) bad("min_correspondences must be >= 6 (got " + std::to_string(p.min_correspondences) + ")");
  const size_t need = std::max<size_t>(static_cast<size_t>(p.normal_k), p.min_correspondences);
  if (reference.size() < need || moving.size() < need)
    bad("clouds have " + std::to_string(reference.size()) + " (reference) and " + std::to_string(moving.size()) +
        " (moving) points; at least " + std::to_string(need) + " each are needed");
}

Normals normalsOf(const Cloud& cloud, int k) {
  NormalParams np;
  np.k_neighbours = k;
  np.orientation = "none";  // point-to-plane and the angle test use lines
  np.robust = false;
  return estimateNormals(cloud, np).normals;
}

}  // namespace

CrossedFilter crossedFilter(const Cloud& reference, const Cloud& moving, double radius_m) {
  if (!(radius_m > 0)) throw InvalidInput("[crossedFilter] radius_m must be > 0 (got " + std::to_string(radius_m) + ")");
  CrossedFilter result;
  if (reference.empty() || moving.empty()) return result;
  auto keep = [radius_m](const Cloud& from, const Cloud& other, std::vector<uint32_t>& out) {
    const KdTree tree(other.points);
    const long n = static_cast<long>(from.size());
    std::vector<char> flag(from.size(), 0);
    const double r2 = radius_m * radius_m;
#pragma omp parallel
    {
      std::vector<uint32_t> idx;
      std::vector<double> d2;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        tree.nearest(from.points[static_cast<size_t>(i)], 1, idx, d2);
        flag[static_cast<size_t>(i)] = !d2.empty() && d2[0] <= r2;
      }
    }
    for (size_t i = 0; i < flag.size(); ++i)
      if (flag[i]) out.push_back(static_cast<uint32_t>(i));
  };
  keep(reference, moving, result.reference);
  keep(moving, reference, result.moving);
  return result;
}

NeighbourDistanceStats nearestDistanceStats(const Cloud& reference, const Cloud& moving, double bin_m, size_t bins) {
  if (reference.empty() || moving.empty())
    throw InvalidInput("[nearestDistanceStats] both clouds need points (reference " + std::to_string(reference.size()) +
                       ", moving " + std::to_string(moving.size()) + ")");
  if (!(bin_m > 0) || bins < 1)
    throw InvalidInput("[nearestDistanceStats] bin_m must be > 0 and bins >= 1 (got " + std::to_string(bin_m) + ", " +
                       std::to_string(bins) + ")");
  const KdTree tree(reference.points);
  std::vector<double> d(moving.size());
  const long n = static_cast<long>(moving.size());
#pragma omp parallel
  {
    std::vector<uint32_t> idx;
    std::vector<double> d2;
#pragma omp for schedule(static)
    for (long i = 0; i < n; ++i) {
      tree.nearest(moving.points[static_cast<size_t>(i)], 1, idx, d2);
      d[static_cast<size_t>(i)] = std::sqrt(d2[0]);
    }
  }
  NeighbourDistanceStats s;
  s.count = d.size();
  s.bin_m = bin_m;
  s.histogram.assign(bins, 0);
  double sum = 0, sum2 = 0;
  for (double v : d) {
    sum += v;
    sum2 += v * v;
    s.max_m = std::max(s.max_m, v);
    ++s.histogram[std::min(bins - 1, static_cast<size_t>(v / bin_m))];
  }
  s.mean_m = sum / static_cast<double>(d.size());
  s.rms_m = std::sqrt(sum2 / static_cast<double>(d.size()));
  auto quantile = [&](double q) {
    const size_t at = std::min(d.size() - 1, static_cast<size_t>(q * static_cast<double>(d.size() - 1) + 0.5));
    std::nth_element(d.begin(), d.begin() + static_cast<long>(at), d.end());
    return d[at];
  };
  s.median_m = quantile(0.5);
  s.p90_m = quantile(0.9);
  return s;
}

IcpResult refineIcp(const Cloud& reference, const Cloud& moving, const RigidTransform& initial, const IcpParams& p,
                    const Progress& progress, const std::vector<PlaneAnchor>& anchors) {
  checkParams(reference, moving, p);
  if (!anchors.empty() && p.method != "point-to-plane")
    throw InvalidInput("[refineIcp] plane anchors need the point-to-plane method (got '" + p.method + "')");
  const bool to_plane = p.method == "point-to-plane";
  const KdTree tree(reference.points);
  Normals ref_n, mov_n;
  if (to_plane) {
    ref_n = normalsOf(reference, p.normal_k);
    mov_n = normalsOf(moving, p.normal_k);
  }
  const double cos_normal = std::cos(p.max_normal_angle_deg * kRadPerDeg);
  const double max2 = p.max_correspondence_m * p.max_correspondence_m;
  const long n = static_cast<long>(moving.size());
  std::vector<uint32_t> match(moving.size());
  std::vector<double> match_d2(moving.size());

  IcpResult result;
  result.transform = initial;
  for (int it = 0; it < p.max_iterations; ++it) {
    progress("icp", static_cast<double>(it) / p.max_iterations);
    const RigidTransform t = result.transform;
#pragma omp parallel
    {
      std::vector<uint32_t> idx;
      std::vector<double> d2;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        const size_t ui = static_cast<size_t>(i);
        tree.nearest(t * moving.points[ui], 1, idx, d2);
        match[ui] = kNone;
        if (d2.empty() || d2[0] > max2) continue;
        if (to_plane && (ref_n.curvature[idx[0]] > p.max_curvature ||
                         std::abs(ref_n.normals[idx[0]].dot(t.linear() * mov_n.normals[ui])) < cos_normal))
          continue;
        match[ui] = idx[0];
        match_d2[ui] = d2[0];
      }
    }
    size_t count = 0;
    for (uint32_t m : match) count += m != kNone;
    result.correspondences = count;
    if (count < p.min_correspondences) {
      result.warnings.push_back("ICP stopped at iteration " + std::to_string(it + 1) + ": only " +
                                std::to_string(count) + " correspondences within " +
                                std::to_string(p.max_correspondence_m) + " m (need " +
                                std::to_string(p.min_correspondences) + ")");
      return result;
    }
    RigidTransform step = RigidTransform::Identity();
    if (to_plane) {
      // Linearised point-to-plane: residual n·(q − r) + (q × n)·ω + n·τ, solved for (ω, τ).
      // Tukey's biweight on a robust scale (1.4826·MAD): pairs between two
      // different surfaces that happen to lie close (a jib leech beside the main)
      // get no weight once the real overlap fits better than they do.
      std::vector<double> res;
      res.reserve(count);
      for (size_t i = 0; i < moving.size(); ++i)
        if (match[i] != kNone)
          res.push_back(std::abs(ref_n.normals[match[i]].dot(t * moving.points[i] - reference.points[match[i]])));
      for (const PlaneAnchor& anchor : anchors)
        for (const Vec3& x : anchor.moving_points) res.push_back(std::abs(anchor.normal.dot(t * x) - anchor.offset_m));
      std::vector<double> sorted = res;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
      const double scale = std::max(1.4826 * sorted[sorted.size() / 2], p.min_robust_scale_m);
      const double c = 4.685 * scale;
      Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
      double sum2 = 0;
      for (size_t i = 0; i < moving.size(); ++i) {
        if (match[i] == kNone) continue;
        const Vec3 q = t * moving.points[i];
        const Vec3& nr = ref_n.normals[match[i]];
        const double r = nr.dot(q - reference.points[match[i]]);
        sum2 += r * r;
        if (std::abs(r) >= c) continue;
        const double u = r / c, w = (1 - u * u) * (1 - u * u);
        Eigen::Matrix<double, 6, 1> a;
        a << q.cross(nr), nr;
        ata += w * a * a.transpose();
        atb -= w * a * r;
      }
      for (const PlaneAnchor& anchor : anchors)
        for (const Vec3& x : anchor.moving_points) {
          const Vec3 q = t * x;
          const double r = anchor.normal.dot(q) - anchor.offset_m;
          if (std::abs(r) >= c) continue;
          const double u = r / c, w = (1 - u * u) * (1 - u * u);
          Eigen::Matrix<double, 6, 1> a;
          a << q.cross(anchor.normal), anchor.normal;
          ata += w * a * a.transpose();
          atb -= w * a * r;
        }
      result.rms_m = std::sqrt(sum2 / static_cast<double>(count));
      // Scale-free conditioning test: a single plane (or a cylinder) leaves
      // directions free, and ICP would slide along them at random.
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(ata);
      if (es.eigenvalues()(0) < 1e-9 * es.eigenvalues()(5)) {
        result.warnings.push_back(
            "ICP stopped: the overlapping points do not constrain all six degrees of freedom (one plane, or "
            "parallel planes, only)");
        return result;
      }
      const Eigen::Matrix<double, 6, 1> x = ata.ldlt().solve(atb);
      const Vec3 w = x.head<3>();
      if (w.norm() > 0) step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      step.translation() = x.tail<3>();
    } else {
      std::vector<PointPair> pairs;
      pairs.reserve(count);
      double sum2 = 0;
      for (size_t i = 0; i < moving.size(); ++i) {
        if (match[i] == kNone) continue;
        pairs.push_back({t * moving.points[i], reference.points[match[i]]});
        sum2 += match_d2[i];
      }
      result.rms_m = std::sqrt(sum2 / static_cast<double>(count));
      try {
        step = fitKabsch(pairs).transform;
      } catch (const InvalidInput& e) {
        result.warnings.push_back(std::string("ICP stopped: ") + e.what());
        return result;
      }
    }
    result.transform = step * result.transform;
    result.iterations = it + 1;
    const double rot_deg = Eigen::AngleAxisd(step.linear()).angle() * kDegPerRad;
    if (rot_deg < p.min_step_rotation_deg && step.translation().norm() < p.min_step_translation_m) {
      result.converged = true;
      break;
    }
  }
  progress("icp", 1.0);
  if (!result.converged)
    result.warnings.push_back("ICP did not converge in " + std::to_string(p.max_iterations) + " iterations");
  return result;
}

}  // namespace sailshape
