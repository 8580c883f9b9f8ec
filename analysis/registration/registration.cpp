#include "analysis/registration/registration.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/normals.hpp"

namespace sailshape {
namespace {

std::string vecText(const Vec3& v) { return "(" + formatFixed(v.x()) + ", " + formatFixed(v.y()) + ", " + formatFixed(v.z()) + ")"; }

std::string describePlanes(const std::vector<DetectedPlane>& planes) {
  if (planes.empty()) return "none";
  std::string s;
  for (size_t i = 0; i < planes.size(); ++i) {
    if (i) s += "; ";
    s += "normal " + vecText(planes[i].normal) + " with " + std::to_string(planes[i].points) + " points";
  }
  return s;
}

double angleDeg(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) / kRadPerDeg; }

// Angle between the lines of two normals, in [0°, 90°].
double lineAngleDeg(const Vec3& a, const Vec3& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))) / kRadPerDeg; }

double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

// At most `limit` of `indices`, evenly spread.
std::vector<uint32_t> thin(const std::vector<uint32_t>& indices, size_t limit) {
  if (indices.size() <= limit) return indices;
  std::vector<uint32_t> out;
  out.reserve(limit);
  const double step = static_cast<double>(indices.size()) / static_cast<double>(limit);
  for (size_t i = 0; i < limit; ++i) out.push_back(indices[static_cast<size_t>(static_cast<double>(i) * step)]);
  return out;
}

std::vector<uint32_t> allIndices(size_t n) {
  std::vector<uint32_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<uint32_t>(i);
  return v;
}

void checkParams(const Cloud& reference, const Cloud& moving, const RegistrationParams& p) {
  auto bad = [](const std::string& what) { throw InvalidInput("[registerClouds] " + what); };
  if (p.method != "planes" && p.method != "svd" && p.method != "icp")
    bad("method must be planes, svd or icp (got '" + p.method + "')");
  if (p.method == "svd" && p.pairs.size() < 3)
    bad("the svd method needs at least 3 point pairs (got " + std::to_string(p.pairs.size()) + ")");
  if (p.method == "planes" && p.pairs.size() > 1)
    bad("the planes method takes at most one point pair, for the translation (got " + std::to_string(p.pairs.size()) +
        ")");
  if (p.method == "planes" && !p.plane_hints.empty() && p.plane_hints.size() != (p.pairs.size() == 1 ? 2u : 3u))
    bad("plane hints must name " + std::string(p.pairs.size() == 1 ? "2 planes (a pair gives the translation)" : "3 planes") +
        " (got " + std::to_string(p.plane_hints.size()) + ")");
  if (!(p.crossed_radius_m > 0)) bad("crossed_radius_m must be > 0 (got " + std::to_string(p.crossed_radius_m) + ")");
  if (!(p.uncertainty_m > 0)) bad("uncertainty_m must be > 0 (got " + std::to_string(p.uncertainty_m) + ")");
  if (!(p.icp_initial_correspondence_m > 0))
    bad("icp_initial_correspondence_m must be > 0 (got " + std::to_string(p.icp_initial_correspondence_m) + ")");
  if (p.max_icp_points < 100) bad("max_icp_points must be >= 100 (got " + std::to_string(p.max_icp_points) + ")");
  if (!(p.match.verify_radius_m > 0)) bad("match.verify_radius_m must be > 0");
  if (p.verify.samples_per_cloud < 10 || p.screen_samples < 10)
    bad("verify.samples_per_cloud and screen_samples must be >= 10 (got " + std::to_string(p.verify.samples_per_cloud) +
        ", " + std::to_string(p.screen_samples) + ")");
  if (p.refined_hypotheses < 1) bad("refined_hypotheses must be >= 1");
  if (!(p.match.max_angle_mismatch_deg > 0)) bad("match.max_angle_mismatch_deg must be > 0");
  if (!(p.match.min_plane_angle_deg > 0 && p.match.min_plane_angle_deg <= 90))
    bad("match.min_plane_angle_deg must be in (0, 90] (got " + std::to_string(p.match.min_plane_angle_deg) + ")");
  if (reference.empty() || moving.empty())
    bad("both clouds need points (reference " + std::to_string(reference.size()) + ", moving " +
        std::to_string(moving.size()) + ")");
}

// The plane whose inliers come closest to `point`.
size_t planeNearest(const Cloud& cloud, const std::vector<DetectedPlane>& planes, const Vec3& point,
                    const char* which) {
  size_t best = planes.size();
  double best_d2 = 1e300;
  for (size_t i = 0; i < planes.size(); ++i)
    for (uint32_t j : planes[i].indices) {
      const double d2 = (cloud.points[j] - point).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
  if (best == planes.size() || best_d2 > 0.25 * 0.25)
    throw AnalysisError(std::string("[registerClouds] no plane of the ") + which + " cloud lies near the hint " +
                        vecText(point) + " (nearest plane point " + formatFixed(std::sqrt(best_d2)) + " m away)");
  return best;
}

struct Candidate {
  RigidTransform transform;
  size_t ref[3], mov[3];
  size_t planes_on = 0;  // moving planes lying on a matching reference plane
};

// Whether planes' normals are far enough apart to fix a rotation: a pair, or a
// triple whose normals are independent too.
struct PlaneIndependence {
  const PlaneMatchParams& m;
  bool pair(const Vec3& a, const Vec3& b) const { return lineAngleDeg(a, b) >= m.min_plane_angle_deg; }
  bool triple(const Vec3& a, const Vec3& b, const Vec3& c) const {
    return pair(a, b) && pair(a, c) && pair(b, c) && std::abs(det3(a, b, c)) >= m.min_triple_det;
  }
  // The planes s (two or three indices into `planes`).
  bool of(const std::vector<DetectedPlane>& planes, const std::vector<size_t>& s) const {
    return s.size() == 2 ? pair(planes[s[0]].normal, planes[s[1]].normal)
                         : triple(planes[s[0]].normal, planes[s[1]].normal, planes[s[2]].normal);
  }
};

// The plane sets a match may pair: the hinted ones (one reference set and its
// moving set), or every usable reference pair/triple (largest planes first) with
// no moving set (every ordered one is tried). `need`: planes per set (2 or 3).
struct PlaneSets {
  std::vector<std::vector<size_t>> reference, moving_hinted;
};

PlaneSets planeSets(const Cloud& reference, const Cloud& moving, const PlaneDetection& dr, const PlaneDetection& dm,
                    const RegistrationParams& p, const PlaneIndependence& independent, size_t need,
                    const std::string& need_text) {
  const auto& R = dr.planes;
  const auto& M = dm.planes;
  PlaneSets sets;
  if (!p.plane_hints.empty()) {
    std::vector<size_t> rs, ms;
    for (const PointPair& h : p.plane_hints) {
      rs.push_back(planeNearest(reference, R, h.reference, "reference"));
      ms.push_back(planeNearest(moving, M, h.moving, "moving"));
    }
    sets.reference.push_back(rs);
    sets.moving_hinted.push_back(ms);
  } else {
    for (size_t i = 0; i < R.size(); ++i)
      for (size_t j = i + 1; j < R.size(); ++j) {
        if (!independent.pair(R[i].normal, R[j].normal)) continue;
        if (need == 2) {
          sets.reference.push_back({i, j});
          continue;
        }
        for (size_t l = j + 1; l < R.size(); ++l)
          if (independent.triple(R[i].normal, R[j].normal, R[l].normal)) sets.reference.push_back({i, j, l});
      }
  }
  if (sets.reference.empty() || (!p.plane_hints.empty() && !independent.of(R, sets.reference[0])))
    throw AnalysisError("[registerClouds] the reference cloud's planes are parallel or their normals share one "
                        "plane (found " + describePlanes(R) + "): the plane method needs " + need_text + " at least " +
                        formatFixed(independent.m.min_plane_angle_deg, 0) +
                        "° apart; parallel planes leave the rotation about their normal and the translation along "
                        "them undetermined");
  if (!p.plane_hints.empty() && !independent.of(M, sets.moving_hinted[0]))
    throw AnalysisError("[registerClouds] the hinted planes of the moving cloud are parallel or their normals share "
                        "one plane: the plane method needs " + need_text);
  return sets;
}

// Which reference plane each moving plane lands on under a candidate pose: one
// of the same orientation holding the nearest reference point of at least a
// tenth of the moving plane's samples (up to 100 of its points).
class CandidateScorer {
 public:
  CandidateScorer(const Cloud& reference, const Cloud& moving, const std::vector<DetectedPlane>& R,
                  const std::vector<DetectedPlane>& M, const PlaneMatchParams& m)
      : moving_(moving), R_(R), M_(M), m_(m), ref_tree_(reference.points),
        r2_(m.verify_radius_m * m.verify_radius_m),
        ref_label_(reference.size(), static_cast<uint32_t>(R.size())) {
    for (size_t j = 0; j < R.size(); ++j)
      for (uint32_t i : R[j].indices) ref_label_[i] = static_cast<uint32_t>(j);
    for (const DetectedPlane& pl : M) plane_samples_.push_back(thin(pl.indices, 100));
  }

  // The reference plane each moving plane lands on under t (R.size(): none).
  std::vector<size_t> landings(const RigidTransform& t) const {
    std::vector<size_t> on(M_.size(), R_.size());
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    for (size_t k = 0; k < M_.size(); ++k) {
      const Vec3 n = t.linear() * M_[k].normal;
      std::vector<size_t> hits(R_.size(), 0);
      for (uint32_t i : plane_samples_[k]) {
        ref_tree_.nearest(t * moving_.points[i], 1, idx, d2);
        if (d2.empty() || d2[0] > r2_ || ref_label_[idx[0]] == R_.size()) continue;
        if (angleDeg(n, R_[ref_label_[idx[0]]].normal) <= 2 * m_.max_angle_mismatch_deg) ++hits[ref_label_[idx[0]]];
      }
      const size_t j = static_cast<size_t>(std::max_element(hits.begin(), hits.end()) - hits.begin());
      if (10 * hits[j] >= plane_samples_[k].size() && hits[j] > 0) on[k] = j;
    }
    return on;
  }

 private:
  const Cloud& moving_;
  const std::vector<DetectedPlane>& R_;  // reference planes
  const std::vector<DetectedPlane>& M_;  // moving planes
  const PlaneMatchParams& m_;
  const KdTree ref_tree_;
  const double r2_;
  // Which reference plane each reference point belongs to (R.size(): none).
  std::vector<uint32_t> ref_label_;
  std::vector<std::vector<uint32_t>> plane_samples_;  // per moving plane, up to 100 of its points
};

// Every distinct alignment that maps a moving plane set onto a reference set with
// the same angles between normals (and handedness), scored. any_moving_set: some
// set passed the angle test. Reports progress per reference set.
std::vector<Candidate> matchPlaneSets(const PlaneSets& sets, const std::vector<DetectedPlane>& R,
                                      const std::vector<DetectedPlane>& M, const RegistrationParams& p,
                                      const PlaneIndependence& independent, size_t need,
                                      const Progress& progress, bool& any_moving_set) {
  const bool pair_translation = p.pairs.size() == 1;
  const double tol = p.match.max_angle_mismatch_deg;
  auto sameTransform = [](const RigidTransform& a, const RigidTransform& b) {
    return rotationDifferenceDeg(a.linear(), b.linear()) < 1.0 && (a.translation() - b.translation()).norm() < 0.05;
  };
  std::vector<Candidate> candidates;
  any_moving_set = false;
  for (size_t s = 0; s < sets.reference.size(); ++s) {
    progress("plane matching", static_cast<double>(s) / static_cast<double>(sets.reference.size()));
    const std::vector<size_t>& rs = sets.reference[s];
    std::vector<std::vector<size_t>> mov_sets;
    if (!p.plane_hints.empty()) {
      mov_sets = sets.moving_hinted;
    } else {
      for (size_t a = 0; a < M.size(); ++a)
        for (size_t b = 0; b < M.size(); ++b) {
          if (b == a) continue;
          if (need == 2) {
            mov_sets.push_back({a, b});
            continue;
          }
          for (size_t c = 0; c < M.size(); ++c)
            if (c != a && c != b) mov_sets.push_back({a, b, c});
        }
    }
    for (const std::vector<size_t>& ms : mov_sets) {
      // The angles between normals are the same in every frame; so is the handedness.
      bool ok = true;
      for (size_t x = 0; x < rs.size() && ok; ++x)
        for (size_t y = x + 1; y < rs.size() && ok; ++y)
          ok = std::abs(angleDeg(R[rs[x]].normal, R[rs[y]].normal) - angleDeg(M[ms[x]].normal, M[ms[y]].normal)) <= tol;
      if (!ok || !independent.of(M, ms)) continue;
      if (need == 3 && (det3(R[rs[0]].normal, R[rs[1]].normal, R[rs[2]].normal) > 0) !=
                           (det3(M[ms[0]].normal, M[ms[1]].normal, M[ms[2]].normal) > 0))
        continue;
      any_moving_set = true;
      Candidate c;
      const Eigen::Matrix3d rot =
          rotationFromNormalPairs(R[rs[0]].normal, R[rs[1]].normal, M[ms[0]].normal, M[ms[1]].normal);
      if (need == 3 && angleDeg(rot * M[ms[2]].normal, R[rs[2]].normal) > tol) continue;
      c.transform = RigidTransform::Identity();
      c.transform.linear() = rot;
      if (pair_translation) {
        c.transform.translation() = p.pairs[0].reference - rot * p.pairs[0].moving;
      } else {
        c.transform.translation() = intersectPlanes(R[rs[0]], R[rs[1]], R[rs[2]], 0.0) -
                                    rot * intersectPlanes(M[ms[0]], M[ms[1]], M[ms[2]], 0.0);
      }
      for (size_t x = 0; x < 3; ++x) {
        c.ref[x] = x < rs.size() ? rs[x] : rs[0];
        c.mov[x] = x < ms.size() ? ms[x] : ms[0];
      }
      bool seen = false;
      for (const Candidate& other : candidates) seen = seen || sameTransform(other.transform, c.transform);
      if (seen) continue;
      // Scored later, once solved from every plane it lands (planeHypotheses).
      candidates.push_back(c);
    }
  }
  progress("plane matching", 1.0);
  return candidates;
}

// The pose that lays every landed moving plane (on[k]: its reference plane,
// R.size(): none) on its reference plane in the weighted least-squares sense:
// the rotation from all normal pairs (Kabsch, each weighted by points × extent²,
// the inverse variance of a fitted normal), the translation from all offsets
// (n_r·t = d_r − d_m, weighted by points, the inverse variance of a fitted
// offset). What the landed planes leave free (a rotation about one normal, a
// translation along the planes) stays as in `start`.
RigidTransform jointPlanePose(const RigidTransform& start, const std::vector<size_t>& on,
                              const std::vector<DetectedPlane>& R, const std::vector<DetectedPlane>& M,
                              const PlaneIndependence& independent) {
  std::vector<size_t> landed;
  for (size_t k = 0; k < M.size(); ++k)
    if (on[k] < R.size()) landed.push_back(k);
  bool turns = false;
  for (size_t a = 0; a < landed.size() && !turns; ++a)
    for (size_t b = a + 1; b < landed.size() && !turns; ++b) turns = independent.pair(M[landed[a]].normal, M[landed[b]].normal);
  RigidTransform t = start;
  auto pairWeight = [](double wr, double wm) { return wr > 0 && wm > 0 ? 1.0 / (1.0 / wr + 1.0 / wm) : 0.0; };
  if (turns) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t k : landed) {
      const DetectedPlane &r = R[on[k]], &m = M[k];
      const double w = pairWeight(static_cast<double>(r.points) * r.extent_m * r.extent_m,
                                  static_cast<double>(m.points) * m.extent_m * m.extent_m);
      h += w * m.normal * r.normal.transpose();
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
    t.linear() = svd.matrixV() * d * svd.matrixU().transpose();
  }
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  for (size_t k : landed) {
    const DetectedPlane &r = R[on[k]], &m = M[k];
    const double w = pairWeight(static_cast<double>(r.points), static_cast<double>(m.points));
    a += w * r.normal * r.normal.transpose();
    b += w * r.normal * (r.offset_m - m.offset_m);
  }
  // A vanishing pull towards the start's translation fixes the unconstrained directions.
  const double lambda = 1e-9 * std::max(a.trace(), 1.0);
  t.translation() = (a + lambda * Eigen::Matrix3d::Identity()).ldlt().solve(b + lambda * start.translation());
  return t;
}

// One pose the planes allow, with the moving planes it lands (ICP anchors).
struct Hypothesis {
  Candidate candidate;  // the plane set it came from; transform: solved from every landed plane
  std::vector<size_t> on;
  PoseEvidence screen;
  bool determined = false;  // the planes it lands fix every degree of freedom
};

// Every distinct pose the matched planes allow, each solved jointly from all the
// planes it lands; `out` gets the plane counts.
std::vector<Hypothesis> planeHypotheses(const Cloud& reference, const Cloud& moving, const RegistrationParams& p,
                                        const Progress& progress, Registration& out, PlaneDetection& dr,
                                        PlaneDetection& dm) {
  dr = detectPlanes(reference, p.planes, progress);
  dm = detectPlanes(moving, p.planes, progress);
  for (const auto& w : dr.warnings) out.warnings.push_back("reference planes: " + w);
  for (const auto& w : dm.warnings) out.warnings.push_back("moving planes: " + w);
  out.reference_planes = dr.planes.size();
  out.moving_planes = dm.planes.size();
  const bool pair_translation = p.pairs.size() == 1;
  const size_t need = pair_translation ? 2 : 3;
  const std::string need_text = pair_translation ? "two non-parallel planes (with the picked pair)"
                                                 : "three planes whose normals are independent";
  for (const auto* d : {&dr, &dm}) {
    const char* which = d == &dr ? "reference" : "moving";
    if (d->planes.size() < need)
      throw AnalysisError(std::string("[registerClouds] fewer than ") + (need == 3 ? "three" : "two") +
                          " usable planes in the " + which + " cloud (found " + std::to_string(d->planes.size()) +
                          ": " + describePlanes(d->planes) + "); the plane method needs " + need_text +
                          " — scan more of the walls/deck, add a reference object, or use --method svd");
  }
  const PlaneMatchParams& m = p.match;
  const PlaneIndependence independent{m};
  const auto& R = dr.planes;
  const auto& M = dm.planes;
  const PlaneSets sets = planeSets(reference, moving, dr, dm, p, independent, need, need_text);
  CandidateScorer scorer(reference, moving, R, M, m);
  bool any_moving_set = false;
  const std::vector<Candidate> candidates =
      matchPlaneSets(sets, R, M, p, independent, need, progress, any_moving_set);
  if (candidates.empty())
    throw AnalysisError(std::string("[registerClouds] no ") + (need == 3 ? "three" : "two") +
                        " planes of the moving cloud match the angles between the reference planes within " +
                        formatFixed(m.max_angle_mismatch_deg, 1) + "° (" +
                        (any_moving_set ? "the third normal disagreed" : "no consistent set") +
                        "; reference: " + describePlanes(R) + "; moving: " + describePlanes(M) +
                        ") — give plane hints or picked pairs");
  out.candidates = candidates.size();
  std::vector<Hypothesis> hyps;
  for (const Candidate& c : candidates) {
    Hypothesis h;
    h.candidate = c;
    // With a picked pair the translation is the pair's; the planes only turn.
    RigidTransform t = c.transform;
    for (int pass = 0; pass < 2 && !pair_translation; ++pass) t = jointPlanePose(t, scorer.landings(t), R, M, independent);
    h.candidate.transform = t;
    h.on = scorer.landings(t);
    h.candidate.planes_on = 0;
    for (size_t j : h.on) h.candidate.planes_on += j < R.size();
    bool seen = false;
    for (const Hypothesis& o : hyps)
      seen = seen || (rotationDifferenceDeg(o.candidate.transform.linear(), t.linear()) < 1.0 &&
                      (o.candidate.transform.translation() - t.translation()).norm() < m.verify_radius_m);
    if (!seen) hyps.push_back(std::move(h));
  }
  return hyps;
}

void reportPairings(const Hypothesis& h, const std::vector<DetectedPlane>& R, const std::vector<DetectedPlane>& M,
                    Registration& out) {
  out.coarse_planes_on = h.candidate.planes_on;
  out.pairings.clear();
  for (size_t k = 0; k < M.size(); ++k) {
    if (h.on[k] >= R.size()) continue;
    PlanePairing pp;
    pp.reference_plane = h.on[k];
    pp.moving_plane = k;
    pp.reference_normal = R[h.on[k]].normal;
    pp.moving_normal = M[k].normal;
    pp.reference_points = R[h.on[k]].points;
    pp.moving_points = M[k].points;
    out.pairings.push_back(pp);
  }
}

std::vector<PlaneAnchor> planeAnchors(const Cloud& moving, const Hypothesis& h, const std::vector<DetectedPlane>& R,
                                      const std::vector<DetectedPlane>& M, size_t max_points) {
  std::vector<PlaneAnchor> anchors;
  for (size_t k = 0; k < M.size(); ++k) {
    if (h.on[k] >= R.size()) continue;
    PlaneAnchor a;
    a.normal = R[h.on[k]].normal;
    a.offset_m = R[h.on[k]].offset_m;
    for (uint32_t i : thin(M[k].indices, max_points)) a.moving_points.push_back(moving.points[i]);
    anchors.push_back(std::move(a));
  }
  return anchors;
}

// How well the aligned moving cloud lies on the reference surface over their
// overlap (crossed filter at radius_m): distance of each overlapping moving
// point to the tangent plane of its nearest reference point.
struct SurfaceFit {
  double rms_m = 0;
  double inlier_fraction = 0;  // of those distances within `inlier_m`
  size_t points = 0;
};
SurfaceFit surfaceFit(const Cloud& reference, const Cloud& aligned, double radius_m, double inlier_m, int k,
                      size_t max_points) {
  SurfaceFit fit;
  const CrossedFilter cf = crossedFilter(reference, aligned, radius_m);
  if (cf.reference.size() < static_cast<size_t>(k) || cf.moving.empty()) return fit;
  const Cloud ref = selectPoints(reference, cf.reference);
  NormalParams np;
  np.k_neighbours = k;
  np.orientation = "none";
  np.robust = false;
  const Normals n = estimateNormals(ref, np).normals;
  const KdTree tree(ref.points);
  double sum2 = 0;
  size_t inliers = 0;
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  for (uint32_t i : thin(cf.moving, max_points)) {
    const Vec3& q = aligned.points[i];
    tree.nearest(q, 1, idx, d2);
    const double r = n.normals[idx[0]].dot(q - ref.points[idx[0]]);
    sum2 += r * r;
    inliers += std::abs(r) <= inlier_m;
    ++fit.points;
  }
  fit.rms_m = std::sqrt(sum2 / static_cast<double>(fit.points));
  fit.inlier_fraction = static_cast<double>(inliers) / static_cast<double>(fit.points);
  return fit;
}

// ICP from a coarse pose over the crossed overlap (SPEC §4 step 2).
struct Refinement {
  RigidTransform transform = RigidTransform::Identity();
  CrossedFilter overlap;
  bool enough_overlap = false;
  int iterations = 0;
  bool converged = true;
  std::vector<std::string> warnings;
};

Refinement refinePose(const Cloud& reference, const Cloud& moving, const RigidTransform& coarse,
                      const std::vector<PlaneAnchor>& anchors, const RegistrationParams& p, const Progress& progress) {
  Refinement r;
  r.transform = coarse;
  r.overlap = crossedFilter(reference, transformCloud(moving, coarse), p.crossed_radius_m);
  r.enough_overlap = r.overlap.moving.size() >= p.min_overlap_points && r.overlap.reference.size() >= p.min_overlap_points;
  if (!r.enough_overlap || !p.refine) return r;
  const Cloud ref_sub = selectPoints(reference, thin(r.overlap.reference, p.max_icp_points));
  const Cloud mov_sub = selectPoints(moving, thin(r.overlap.moving, p.max_icp_points));
  IcpParams ip = p.icp;
  ip.max_correspondence_m = std::min(ip.max_correspondence_m, p.crossed_radius_m);
  const IcpResult icp =
      refineIcp(ref_sub, mov_sub, coarse, ip, progress, ip.method == "point-to-plane" ? anchors : std::vector<PlaneAnchor>{});
  for (const auto& w : icp.warnings) r.warnings.push_back("refinement: " + w);
  r.iterations = icp.iterations;
  r.converged = icp.converged;
  r.transform = icp.transform;
  return r;
}

// A refined plane hypothesis and what the verifier made of it.
struct Verified {
  const Hypothesis* hypothesis = nullptr;
  Refinement refinement;
  PoseEvidence evidence;
  bool fits = false;  // on its own it would pass the fitness, inlier and convergence tests
  size_t planes_on = 0;  // moving planes it lands on reference planes
};

// A pose refined by ICP from `start` (on `quick`'s share of the points), scored
// by the verifier and tested on its own; refinement.enough_overlap false: no overlap.
Verified verifyPose(const Cloud& reference, const Cloud& moving, const RigidTransform& start,
                    const std::vector<PlaneAnchor>& anchors, const RegistrationParams& quick,
                    const PoseVerifier& verifier) {
  Verified v;
  v.refinement = refinePose(reference, moving, start, anchors, quick, {});
  if (!v.refinement.enough_overlap) return v;
  v.evidence = verifier.evaluate(v.refinement.transform);
  const SurfaceFit fit = surfaceFit(reference, transformCloud(moving, v.refinement.transform), quick.crossed_radius_m,
                                    quick.uncertainty_m, quick.icp.normal_k, quick.max_icp_points);
  v.fits = fit.points > 0 && fit.rms_m <= quick.uncertainty_m && fit.inlier_fraction >= quick.min_inlier_fraction &&
           v.refinement.converged;
  return v;
}

// The scene's own symmetries, turned onto a pose: a box room maps onto itself
// turned 90°, 180° or 270° about a line along one of its axes, so when `lead`
// is wrong the truth may be lead turned so — and a plane match may never have
// proposed it (the units saw different walls). For each axis (the reference
// planes' normals) and turn, the line's position is searched over the reference
// cloud's extent (0.2 m steps, then 0.04 m); the likeliest turned pose of each comes back.
std::vector<RigidTransform> symmetricAlternatives(const Cloud& reference, const std::vector<DetectedPlane>& R,
                                                  const PlaneIndependence& independent, const PoseVerifier& verifier,
                                                  const RigidTransform& lead, size_t samples) {
  std::vector<Vec3> axes;
  for (const DetectedPlane& pl : R) {
    bool known = false;
    for (const Vec3& a : axes) known = known || !independent.pair(a, pl.normal);
    if (!known && axes.size() < 3) axes.push_back(pl.normal);
  }
  Vec3 lo = reference.points.front(), hi = lo;
  for (const Vec3& q : reference.points) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Vec3 mid = (lo + hi) / 2;
  const double half = (hi - lo).norm() / 2;
  std::vector<RigidTransform> out;
  for (const Vec3& a : axes) {
    const Vec3 u = a.unitOrthogonal(), v = a.cross(u);
    for (int quarter = 1; quarter <= 3; ++quarter) {
      const Eigen::Matrix3d turn = Eigen::AngleAxisd(quarter * M_PI / 2, a).toRotationMatrix();
      auto posed = [&](const Vec3& c) {
        RigidTransform t = lead;
        t.linear() = turn * lead.linear();
        t.translation() = turn * lead.translation() + (c - turn * c);
        return t;
      };
      Vec3 best_c = mid;
      double best = -std::numeric_limits<double>::infinity();
      for (double step : {0.2, 0.04}) {
        const double span = step == 0.2 ? half : 0.2;
        const Vec3 centre = best_c;
        for (double i = -span; i <= span + 1e-9; i += step)
          for (double j = -span; j <= span + 1e-9; j += step) {
            const Vec3 c = centre + i * u + j * v;
            const double ll = verifier.evaluate(posed(c), samples).log_likelihood;
            if (ll > best) {
              best = ll;
              best_c = c;
            }
          }
      }
      out.push_back(posed(best_c));
    }
  }
  return out;
}

// The plane method: every hypothesis screened by its likelihood on a few
// samples, the likeliest refined by ICP and scored on all samples both ways;
// the best must beat the runner-up (a different pose) by the verifier's margin,
// else the result is ambiguous and says which poses compete and what decides.
Refinement choosePlanePose(const Cloud& reference, const Cloud& moving, const RegistrationParams& p,
                           const Progress& progress, Registration& out) {
  PlaneDetection dr, dm;
  std::vector<Hypothesis> hyps = planeHypotheses(reference, moving, p, progress, out, dr, dm);
  const PoseVerifier verifier(reference, moving, p.verify);
  // Poses closer than the crossed radius everywhere over the moving cloud are one.
  double extent = 0;
  const Vec3 centre = moving.viewpoint.value_or(Vec3::Zero());
  for (const Vec3& q : moving.points) extent = std::max(extent, (q - centre).norm());
  // A pose is determined when the planes it lands fix all six degrees of
  // freedom (normals with an independent triple; a pair with a picked pair):
  // a pose landing fewer overlaps little and so is contradicted by little,
  // which is no evidence for it. Determined poses are ranked by their
  // free-space evidence, then by planes landed.
  const PlaneIndependence independent{p.match};
  auto determined = [&](const Hypothesis& h) {
    std::vector<size_t> landed;
    for (size_t k = 0; k < h.on.size(); ++k)
      if (h.on[k] < dr.planes.size()) landed.push_back(k);
    if (p.pairs.size() == 1) return h.candidate.planes_on >= 2;
    for (size_t a = 0; a < landed.size(); ++a)
      for (size_t b = a + 1; b < landed.size(); ++b)
        for (size_t c = b + 1; c < landed.size(); ++c)
          if (independent.triple(dm.planes[landed[a]].normal, dm.planes[landed[b]].normal, dm.planes[landed[c]].normal))
            return true;
    return false;
  };
  for (Hypothesis& h : hyps) {
    h.screen = verifier.evaluate(h.candidate.transform, p.screen_samples);
    h.determined = determined(h);
  }
  auto rank = [](const Hypothesis& h) { return h.determined; };
  std::sort(hyps.begin(), hyps.end(), [&](const Hypothesis& a, const Hypothesis& b) {
    if (rank(a) != rank(b)) return rank(a);
    if (a.screen.log_likelihood != b.screen.log_likelihood) return a.screen.log_likelihood > b.screen.log_likelihood;
    if (a.candidate.planes_on != b.candidate.planes_on) return a.candidate.planes_on > b.candidate.planes_on;
    return a.screen.consistency > b.screen.consistency;
  });
  std::vector<Verified> refined;
  // Candidates are refined on a quarter of the points (the choice needs the
  // basin, not the last 0.1 mm); the winner is refined again on all of them.
  RegistrationParams quick = p;
  quick.max_icp_points = std::max<size_t>(100, p.max_icp_points / 4);
  // Refined: the screen's best and every pose the screen cannot yet reject
  // against it (with enough overlap), up to refined_hypotheses; at least two.
  size_t to_refine = 0;
  while (to_refine < hyps.size() && to_refine < p.refined_hypotheses &&
         rank(hyps[to_refine]) && (to_refine < 2 || !verifier.compare(hyps[0].screen, hyps[to_refine].screen).decisive))
    ++to_refine;
  if (to_refine == 0)
    throw AnalysisError("[registerClouds] none of the " + std::to_string(hyps.size()) +
                        " plane matches lands planes of the moving cloud that fix the pose (three with independent "
                        "normals on reference planes): the units see too few of the same planes — decide with --pairs, "
                        "--plane-hints, or a reference cube both units see");
  for (size_t i = 0; i < to_refine; ++i) {
    progress("verifying poses", static_cast<double>(i) / static_cast<double>(to_refine));
    Verified v = verifyPose(reference, moving, hyps[i].candidate.transform,
                            planeAnchors(moving, hyps[i], dr.planes, dm.planes, quick.max_anchor_points), quick, verifier);
    v.hypothesis = &hyps[i];
    if (!v.refinement.enough_overlap) continue;
    // Two hypotheses ICP brought to one pose are one pose.
    bool same = false;
    for (Verified& o : refined) {
      if (compareTransforms(o.refinement.transform, v.refinement.transform, extent, p.crossed_radius_m).moved)
        continue;
      same = true;
      if (v.evidence.log_likelihood > o.evidence.log_likelihood) o = std::move(v);
      break;
    }
    if (!same) refined.push_back(std::move(v));
  }
  // The likeliest so far, turned by the room's symmetries, competes too: the
  // truth may be one of them when no plane match proposed it.
  if (!refined.empty() && p.symmetric_alternatives) {
    const Verified* lead = &refined.front();
    for (const Verified& v : refined)
      if (v.fits && (!lead->fits || v.evidence.log_likelihood > lead->evidence.log_likelihood)) lead = &v;
    const Hypothesis* lead_h = lead->hypothesis;
    const RigidTransform lead_t = lead->refinement.transform;
    const std::vector<RigidTransform> alts = symmetricAlternatives(reference, dr.planes, independent, verifier, lead_t,
                                                                   std::min<size_t>(p.screen_samples, 300));
    std::vector<std::pair<double, RigidTransform>> ranked;
    for (const RigidTransform& t : alts) ranked.push_back({verifier.evaluate(t, p.screen_samples).log_likelihood, t});
    std::sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    for (size_t k = 0; k < ranked.size() && k < 2; ++k) {
      Verified v = verifyPose(reference, moving, ranked[k].second, {}, quick, verifier);
      v.hypothesis = lead_h;
      if (!v.refinement.enough_overlap) continue;
      bool same = false;
      for (const Verified& o : refined)
        same = same || !compareTransforms(o.refinement.transform, v.refinement.transform, extent, p.crossed_radius_m).moved;
      if (!same) refined.push_back(std::move(v));
    }
  }
  if (refined.empty())
    throw AnalysisError("[registerClouds] no overlap: none of the " + std::to_string(hyps.size()) +
                        " plane alignments leaves " + std::to_string(p.min_overlap_points) +
                        " points of each cloud within " + formatFixed(p.crossed_radius_m) +
                        " m of the other; the clouds must see some of the same surfaces");
  // Poses that fit the overlap first; among them the one the free space contradicts least.
  std::sort(refined.begin(), refined.end(), [](const Verified& a, const Verified& b) {
    return a.fits != b.fits ? a.fits : a.evidence.log_likelihood > b.evidence.log_likelihood;
  });
  const Verified& best = refined.front();
  reportPairings(*best.hypothesis, dr.planes, dm.planes, out);
  out.coarse = best.hypothesis->candidate.transform;
  out.coarse_overlap_fraction = static_cast<double>(best.evidence.on_surface) /
                                static_cast<double>(std::max<size_t>(1, best.evidence.per_sample.size()));
  out.free_space_fraction = static_cast<double>(best.evidence.in_free_space) /
                            static_cast<double>(std::max<size_t>(1, best.evidence.per_sample.size()));
  out.poses_verified = refined.size();
  // Planes landed speak too: a fitting pose that lands as many of them as the
  // likeliest leaves the choice open whatever the free space says (on the
  // tunnel fixture without occlusion the free space favours a pose 90° off).
  const CandidateScorer landing(reference, moving, dr.planes, dm.planes, p.match);
  for (Verified& v : refined)
    for (size_t j : landing.landings(v.refinement.transform)) v.planes_on += j < dr.planes.size();
  for (size_t i = 1; i < refined.size() && !out.ambiguous; ++i)
    if (refined[i].fits && refined[i].planes_on >= best.planes_on) {
      out.ambiguous = true;
      out.warnings.push_back("ambiguous: the likeliest pose, " + describePose(best.refinement.transform) + ", lands " +
                             std::to_string(best.planes_on) + " planes, and another, " +
                             describePose(refined[i].refinement.transform) + ", lands " +
                             std::to_string(refined[i].planes_on) +
                             " — decide with --pairs, --plane-hints, or a reference cube both units see");
    }
  if (!out.ambiguous && refined.size() > 1 && refined[1].fits) {
    const PoseComparison c = verifier.compare(best.evidence, refined[1].evidence);
    out.log_likelihood_ratio = c.log_ratio;
    out.log_likelihood_ratio_needed = c.needed;
    if (!c.decisive) {
      out.ambiguous = true;
      out.warnings.push_back(
          "ambiguous: " + std::to_string(refined.size()) + " poses fit; the likeliest, " +
          describePose(best.refinement.transform) + " (" + std::to_string(best.evidence.in_free_space) +
          " samples in the other unit's free space), beats " + describePose(refined[1].refinement.transform) + " (" +
          std::to_string(refined[1].evidence.in_free_space) + ") by a log-likelihood ratio of " +
          formatFixed(c.log_ratio, 1) + " where " + formatFixed(c.needed, 1) +
          " is needed — decide with --pairs, --plane-hints, or a reference cube both units see");
    }
  }
  if (!p.refine) return best.refinement;
  return refinePose(reference, moving, best.refinement.transform,
                    planeAnchors(moving, *best.hypothesis, dr.planes, dm.planes, p.max_anchor_points), p, progress);
}

}  // namespace

RigidTransform transformFromPlanes(const DetectedPlane (&reference)[3], const DetectedPlane (&moving)[3]) {
  const Eigen::Matrix3d rot =
      rotationFromNormalPairs(reference[0].normal, reference[1].normal, moving[0].normal, moving[1].normal);
  const Vec3 xr = intersectPlanes(reference[0], reference[1], reference[2]);
  const Vec3 xm = intersectPlanes(moving[0], moving[1], moving[2]);
  RigidTransform t = RigidTransform::Identity();
  t.linear() = rot;
  t.translation() = xr - rot * xm;
  return t;
}

Registration registerClouds(const Cloud& reference, const Cloud& moving, const RegistrationParams& p,
                            const Progress& progress) {
  checkParams(reference, moving, p);
  Registration out;
  out.method = p.method;
  Refinement refinement;
  if (p.method == "planes") {
    refinement = choosePlanePose(reference, moving, p, progress, out);
  } else {
    RigidTransform coarse = RigidTransform::Identity();
    if (p.method == "svd") {
      const KabschFit fit = fitKabsch(p.pairs);
      coarse = fit.transform;
      if (fit.reflection_corrected)
        out.warnings.push_back("the picked pairs fit a reflection best; the nearest rotation was used — check the pairs");
      if (fit.rms_m > p.uncertainty_m)
        out.warnings.push_back("picked pairs disagree by " + formatFixed(fit.rms_m * 1000, 1) + " mm RMS, above the " +
                               formatFixed(p.uncertainty_m * 1000, 1) + " mm uncertainty (picking error)");
    } else {
      // Plain ICP from the raw pose: wide correspondences over both whole clouds.
      IcpParams ip = p.icp;
      ip.method = "point-to-point";
      ip.max_correspondence_m = p.icp_initial_correspondence_m;
      const Cloud ref_sub = selectPoints(reference, thin(allIndices(reference.size()), p.max_icp_points));
      const Cloud mov_sub = selectPoints(moving, thin(allIndices(moving.size()), p.max_icp_points));
      const IcpResult icp = refineIcp(ref_sub, mov_sub, p.initial, ip, progress);
      for (const auto& w : icp.warnings) out.warnings.push_back("plain ICP: " + w);
      coarse = icp.transform;
    }
    out.coarse = coarse;
    refinement = refinePose(reference, moving, coarse, {}, p, progress);
  }
  // Crossed filter: only the overlap can hold right correspondences.
  const CrossedFilter& overlap = refinement.overlap;
  out.overlap_reference_points = overlap.reference.size();
  out.overlap_moving_points = overlap.moving.size();
  if (!refinement.enough_overlap)
    throw AnalysisError("[registerClouds] no overlap: after the " + p.method + " alignment only " +
                        std::to_string(overlap.moving.size()) + " moving and " +
                        std::to_string(overlap.reference.size()) + " reference points have a point of the other cloud within " +
                        formatFixed(p.crossed_radius_m) + " m (need " + std::to_string(p.min_overlap_points) +
                        "); the clouds must see some of the same surfaces");
  for (const auto& w : refinement.warnings) out.warnings.push_back(w);
  const Cloud mov_overlap = selectPoints(moving, overlap.moving);
  out.before_refinement = nearestDistanceStats(reference, transformCloud(mov_overlap, out.coarse));
  out.icp_iterations = refinement.iterations;
  out.converged = refinement.converged;
  const RigidTransform final_t = refinement.transform;
  out.transform = final_t;
  out.rotation = final_t.linear();
  out.translation = final_t.translation();
  out.after_refinement = nearestDistanceStats(reference, transformCloud(mov_overlap, final_t));
  const SurfaceFit fit = surfaceFit(reference, transformCloud(moving, final_t), p.crossed_radius_m, p.uncertainty_m,
                                    p.icp.normal_k, p.max_icp_points);
  out.fitness_rms_m = fit.rms_m;
  out.inlier_fraction = fit.inlier_fraction;
  out.below_uncertainty = fit.points > 0 && out.fitness_rms_m <= p.uncertainty_m;
  for (PlanePairing& pp : out.pairings) pp.angle_after_deg = angleDeg(out.rotation * pp.moving_normal, pp.reference_normal);
  if (!out.below_uncertainty)
    out.warnings.push_back("fitness " + formatFixed(out.fitness_rms_m * 1000, 1) + " mm RMS is above the sensor uncertainty (" +
                           formatFixed(p.uncertainty_m * 1000, 1) + " mm): the registration is not good enough");
  if (out.inlier_fraction < p.min_inlier_fraction)
    out.warnings.push_back("only " + formatFixed(100 * out.inlier_fraction, 1) + " % of the overlapping points lie within " +
                           formatFixed(p.uncertainty_m * 1000, 1) + " mm of the reference surface (need " +
                           formatFixed(100 * p.min_inlier_fraction, 0) + " %): surfaces cross rather than coincide");
  out.accepted = out.below_uncertainty && out.inlier_fraction >= p.min_inlier_fraction && out.converged && !out.ambiguous;
  return out;
}


Drift compareTransforms(const RigidTransform& stored, const RigidTransform& fresh, double radius_m,
                        double max_displacement_m) {
  if (!(radius_m >= 0) || !(max_displacement_m > 0))
    throw InvalidInput("[compareTransforms] radius_m must be >= 0 and max_displacement_m > 0 (got " +
                       std::to_string(radius_m) + ", " + std::to_string(max_displacement_m) + ")");
  Drift d;
  d.rotation_deg = rotationDifferenceDeg(stored.linear(), fresh.linear());
  d.translation_m = (fresh.translation() - stored.translation()).norm();
  // |ΔR·x + Δt| ≤ |Δt| + 2 sin(θ/2)·|x| for every x within the radius.
  d.max_displacement_m = d.translation_m + 2 * std::sin(d.rotation_deg * kRadPerDeg / 2) * radius_m;
  d.moved = d.max_displacement_m > max_displacement_m;
  return d;
}

}  // namespace sailshape
