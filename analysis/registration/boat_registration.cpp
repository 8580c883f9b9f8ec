#include "analysis/registration/boat_registration.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/io/text_scan.hpp"

namespace sailshape {
namespace {

double angleDeg(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) / kRadPerDeg; }
double lineAngleDeg(const Vec3& a, const Vec3& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))) / kRadPerDeg; }
double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

// A reference face as a plane for intersectPlanes (only normal and offset are used).
DetectedPlane asPlane(const ReferenceFace& f) {
  DetectedPlane p;
  p.normal = f.normal;
  p.offset_m = f.offset_m;
  return p;
}

Vec3 jsonVec(const nlohmann::json& j, const std::string& source, const std::string& field) {
  if (!j.is_array() || j.size() != 3)
    throw detail::fileError(source, field + " must be an array of three numbers");
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    if (!j[static_cast<size_t>(i)].is_number()) throw detail::fileError(source, field + " must be an array of three numbers");
    v(i) = j[static_cast<size_t>(i)].get<double>();
  }
  if (!v.allFinite()) throw detail::fileError(source, field + " has a non-finite value");
  return v;
}

// Which face each detected plane lies on under `t` (faces.size() when none).
std::vector<size_t> facesOf(const std::vector<DetectedPlane>& planes, const BoatReference& ref,
                            const RigidTransform& t, double angle_tol_deg, double max_distance_m) {
  std::vector<size_t> face(planes.size(), ref.faces.size());
  for (size_t k = 0; k < planes.size(); ++k) {
    const Vec3 n = t.linear() * planes[k].normal, c = t * planes[k].centroid;
    double best = max_distance_m;
    for (size_t f = 0; f < ref.faces.size(); ++f) {
      if (angleDeg(n, ref.faces[f].normal) > angle_tol_deg) continue;
      const double d = std::abs(ref.faces[f].normal.dot(c) - ref.faces[f].offset_m);
      if (d <= best) {
        best = d;
        face[k] = f;
      }
    }
  }
  return face;
}

// Whether normal equations over (rotation, translation, scale) fix all six degrees of
// freedom of the pose: the pose block's smallest eigenvalue not vanishing beside its largest.
bool fixesThePose(const Eigen::Matrix<double, 7, 7>& ata) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(ata.topLeftCorner<6, 6>());
  return es.eigenvalues()(0) >= 1e-9 * es.eigenvalues()(5);
}

}  // namespace

std::vector<ReferenceFace> cubeFaces(const std::string& name, const Vec3& centre, double size_m, double yaw_deg) {
  if (!(size_m > 0) || !centre.allFinite() || !std::isfinite(yaw_deg))
    throw InvalidInput("[cubeFaces] size_m must be > 0 and centre, yaw finite (got size " + std::to_string(size_m) + ")");
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(yaw_deg * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  const std::pair<const char*, Vec3> sides[] = {
      {"+x", Vec3::UnitX()}, {"-x", -Vec3::UnitX()}, {"+y", Vec3::UnitY()}, {"-y", -Vec3::UnitY()}, {"top", Vec3::UnitZ()}};
  std::vector<ReferenceFace> faces;
  for (const auto& [label, local] : sides) {
    const Vec3 n = rz * local;
    faces.push_back({name + " " + label, n, n.dot(centre + 0.5 * size_m * n)});
  }
  return faces;
}

BoatReference parseBoatReference(const std::string& text, const std::string& source) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw detail::fileError(source, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object()) throw detail::fileError(source, "a boat reference must be a JSON object");
  BoatReference ref;
  ref.name = doc.value("name", std::string("reference"));
  if (doc.contains("faces")) {
    if (!doc["faces"].is_array()) throw detail::fileError(source, "\"faces\" must be an array");
    for (size_t i = 0; i < doc["faces"].size(); ++i) {
      const auto& f = doc["faces"][i];
      const std::string where = "faces[" + std::to_string(i) + "]";
      if (!f.is_object() || !f.contains("normal") || !f.contains("point"))
        throw detail::fileError(source, where + " needs \"normal\" and \"point\"");
      const Vec3 n = jsonVec(f["normal"], source, where + ".normal");
      if (n.norm() < 1e-9) throw detail::fileError(source, where + ".normal is zero");
      const Vec3 p = jsonVec(f["point"], source, where + ".point");
      const std::string name = f.contains("name") && f["name"].is_string() ? f["name"].get<std::string>() : where;
      ref.faces.push_back({name, n.normalized(), n.normalized().dot(p)});
    }
  }
  if (doc.contains("cube")) {
    const auto& c = doc["cube"];
    if (!c.is_object() || !c.contains("centre") || !c.contains("size_m") || !c["size_m"].is_number())
      throw detail::fileError(source, "\"cube\" needs \"centre\" and a numeric \"size_m\"");
    const double size = c["size_m"].get<double>();
    if (!(size > 0)) throw detail::fileError(source, "cube.size_m must be > 0 (got " + std::to_string(size) + ")");
    const double yaw = c.contains("yaw_deg") && c["yaw_deg"].is_number() ? c["yaw_deg"].get<double>() : 0.0;
    const std::string name = c.contains("name") && c["name"].is_string() ? c["name"].get<std::string>() : "cube";
    for (ReferenceFace& f : cubeFaces(name, jsonVec(c["centre"], source, "cube.centre"), size, yaw))
      ref.faces.push_back(std::move(f));
  }
  if (ref.faces.size() < 3)
    throw detail::fileError(source, "a boat reference needs at least three faces (found " +
                                        std::to_string(ref.faces.size()) + ")");
  return ref;
}

BoatReference readBoatReference(const std::string& path) {
  return parseBoatReference(detail::readWholeFile(path), path);
}

BoatRegistration registerToBoat(const Cloud& cloud, const BoatReference& ref, const BoatRegistrationParams& p,
                                const Progress& progress) {
  auto bad = [](const std::string& what) { throw InvalidInput("[registerToBoat] " + what); };
  if (!(p.max_angle_mismatch_deg > 0)) bad("max_angle_mismatch_deg must be > 0");
  if (!(p.max_face_distance_m > 0)) bad("max_face_distance_m must be > 0");
  if (!(p.uncertainty_m > 0)) bad("uncertainty_m must be > 0");
  if (p.refine_iterations < 0) bad("refine_iterations must be >= 0");
  if (!(p.range_scale_prior_sigma >= 0)) bad("range_scale_prior_sigma must be >= 0");
  const auto& F = ref.faces;
  auto usable = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    return lineAngleDeg(a, b) >= p.min_plane_angle_deg && lineAngleDeg(a, c) >= p.min_plane_angle_deg &&
           lineAngleDeg(b, c) >= p.min_plane_angle_deg && std::abs(det3(a, b, c)) >= p.min_triple_det;
  };
  std::vector<std::array<size_t, 3>> face_sets;
  for (size_t a = 0; a < F.size(); ++a)
    for (size_t b = a + 1; b < F.size(); ++b)
      for (size_t c = b + 1; c < F.size(); ++c)
        if (usable(F[a].normal, F[b].normal, F[c].normal)) face_sets.push_back({a, b, c});
  if (face_sets.empty())
    bad("reference '" + ref.name + "' has no three faces whose normals are independent (" +
        std::to_string(F.size()) + " faces): parallel faces cannot fix a frame");

  const PlaneDetection det = detectPlanes(cloud, p.planes, progress);
  BoatRegistration out;
  for (const auto& w : det.warnings) out.warnings.push_back("planes: " + w);
  const auto& D = det.planes;
  out.planes = D.size();
  if (D.size() < 3)
    throw AnalysisError("[registerToBoat] fewer than three usable planes in the cloud (found " +
                        std::to_string(D.size()) + "); the faces of '" + ref.name + "' must be scanned");

  struct Candidate {
    RigidTransform t;
    size_t score;
  };
  std::vector<Candidate> candidates;
  const double tol = p.max_angle_mismatch_deg;
  bool any_consistent = false;
  for (const auto& fs : face_sets) {
    for (size_t a = 0; a < D.size(); ++a)
      for (size_t b = 0; b < D.size(); ++b)
        for (size_t c = 0; c < D.size(); ++c) {
          if (a == b || a == c || b == c) continue;
          const size_t ds[3] = {a, b, c};
          bool ok = true;
          for (int x = 0; x < 3 && ok; ++x)
            for (int y = x + 1; y < 3 && ok; ++y)
              ok = std::abs(angleDeg(F[fs[x]].normal, F[fs[y]].normal) - angleDeg(D[ds[x]].normal, D[ds[y]].normal)) <= tol;
          if (!ok || !usable(D[a].normal, D[b].normal, D[c].normal)) continue;
          if ((det3(F[fs[0]].normal, F[fs[1]].normal, F[fs[2]].normal) > 0) !=
              (det3(D[a].normal, D[b].normal, D[c].normal) > 0))
            continue;
          const Eigen::Matrix3d rot =
              rotationFromNormalPairs(F[fs[0]].normal, F[fs[1]].normal, D[a].normal, D[b].normal);
          if (angleDeg(rot * D[c].normal, F[fs[2]].normal) > tol) continue;
          any_consistent = true;
          if (rotationDifferenceDeg(rot, p.prior_rotation) > p.prior_tolerance_deg) continue;
          RigidTransform t = RigidTransform::Identity();
          t.linear() = rot;
          t.translation() = intersectPlanes(asPlane(F[fs[0]]), asPlane(F[fs[1]]), asPlane(F[fs[2]]), 0.0) -
                            rot * intersectPlanes(D[a], D[b], D[c]);
          bool seen = false;
          for (const Candidate& o : candidates)
            seen = seen || (rotationDifferenceDeg(o.t.linear(), rot) < 1.0 && (o.t.translation() - t.translation()).norm() < 0.05);
          if (seen) continue;
          size_t score = 0;
          const std::vector<size_t> on = facesOf(D, ref, t, 2 * tol, p.max_face_distance_m);
          for (size_t k = 0; k < D.size(); ++k)
            if (on[k] < F.size()) score += D[k].points;
          candidates.push_back({t, score});
        }
  }
  if (candidates.empty())
    throw AnalysisError(std::string("[registerToBoat] no three planes of the cloud match the faces of '") + ref.name +
                        "' within " + formatFixed(tol, 1) + "°" +
                        (any_consistent ? " and the prior orientation" : "") + " (" + std::to_string(D.size()) +
                        " planes found)");
  std::sort(candidates.begin(), candidates.end(), [](const auto& x, const auto& y) {
    return x.score > y.score;
  });
  // Among equally good matches (a symmetric object), the one nearest the prior.
  size_t chosen = 0;
  for (size_t i = 1; i < candidates.size() && candidates[i].score >= 0.95 * candidates[0].score; ++i) {
    out.ambiguous = true;
    if (rotationDifferenceDeg(candidates[i].t.linear(), p.prior_rotation) <
        rotationDifferenceDeg(candidates[chosen].t.linear(), p.prior_rotation))
      chosen = i;
  }
  if (out.ambiguous)
    out.warnings.push_back("ambiguous: " + ref.name +
                           " looks the same after another rotation; chose the match nearest the prior orientation — "
                           "narrow prior_tolerance_deg or add a face that breaks the symmetry");
  RigidTransform t = candidates[chosen].t;

  // Fit every matched plane's points onto its face (linearised, few iterations),
  // with the unit's range scale k: a point p (unit frame, viewpoint v) truly lies
  // at t·(v + c(p − v)), c = 1/k. Unknowns: a small turn ω and shift τ (applied
  // after t) and δc; a point's residual r = n·x − d moves by (x × n)·ω + n·τ +
  // n·R(p − v)·δc. The prior on c − 1 is weighted by the residual variance, so
  // that it enters the normal equations on the points' scale.
  const bool fit_scale = p.range_scale_prior_sigma > 0;
  const Vec3 v = cloud.viewpoint.value_or(Vec3::Zero());
  double c = 1;
  progress("boat frame", 0.5);
  for (int it = 0; it <= p.refine_iterations; ++it) {
    const std::vector<size_t> on = facesOf(D, ref, t, 2 * tol, p.max_face_distance_m);
    Eigen::Matrix<double, 7, 7> ata = Eigen::Matrix<double, 7, 7>::Zero();
    Eigen::Matrix<double, 7, 1> atb = Eigen::Matrix<double, 7, 1>::Zero();
    out.faces.clear();
    // Each face's share of the normal equations, for the scale's σ by the jackknife
    // over faces (a face's points move together when it is fitted a little off as a
    // whole: an edge's mixed pixels, the beam's footprint).
    std::vector<Eigen::Matrix<double, 7, 7>> face_ata;
    std::vector<Eigen::Matrix<double, 7, 1>> face_atb;
    double total2 = 0;
    size_t total = 0;
    for (size_t j = 0; j < D.size(); ++j) {
      if (on[j] == F.size()) continue;
      const ReferenceFace& f = F[on[j]];
      FaceMatch fm{f.name, j, D[j].points, 0, angleDeg(t.linear() * D[j].normal, f.normal)};
      double sum2 = 0;
      Eigen::Matrix<double, 7, 7> fa = Eigen::Matrix<double, 7, 7>::Zero();
      Eigen::Matrix<double, 7, 1> fb = Eigen::Matrix<double, 7, 1>::Zero();
      for (uint32_t i : D[j].indices) {
        const Vec3& q = cloud.points[i];
        const Vec3 x = t * (v + c * (q - v));
        const double r = f.normal.dot(x) - f.offset_m;
        // The derivatives at the point's place on its plane, not at its noisy
        // sample: where the faces leave the scale to trade with the translation,
        // derivatives holding the sample's own noise would fit the scale to it
        // (the residual regressed on itself pulls c towards 0).
        const Vec3 q_plane = q - (D[j].normal.dot(q) - D[j].offset_m) * D[j].normal;
        const Vec3 x_plane = t * (v + c * (q_plane - v));
        Eigen::Matrix<double, 7, 1> a;
        a << x_plane.cross(f.normal), f.normal, f.normal.dot(t.linear() * (q_plane - v));
        fa += a * a.transpose();
        fb -= a * r;
        sum2 += r * r;
      }
      ata += fa;
      atb += fb;
      face_ata.push_back(fa);
      face_atb.push_back(fb);
      fm.rms_m = std::sqrt(sum2 / static_cast<double>(D[j].indices.size()));
      total2 += sum2;
      total += D[j].indices.size();
      out.faces.push_back(fm);
    }
    out.fitness_rms_m = total ? std::sqrt(total2 / static_cast<double>(total)) : 0.0;
    const double variance = total > 7 ? total2 / static_cast<double>(total - 7) : 0.0;
    const bool constrained = total > 0 && fixesThePose(ata);
    if (!constrained) {
      out.warnings.push_back("the matched faces do not fix all six degrees of freedom; the transform comes from the "
                             "plane intersection alone");
      break;
    }
    if (fit_scale) {
      const double w = std::max(variance, 1e-12) / (p.range_scale_prior_sigma * p.range_scale_prior_sigma);
      ata(6, 6) += w;
      atb(6) -= w * (c - 1);
    } else {  // δc = 0
      ata.row(6).setZero();
      ata.col(6).setZero();
      ata(6, 6) = 1;
      atb(6) = 0;
    }
    if (it == p.refine_iterations) {
      out.accepted = true;  // provisional: constrained
      // σ of k = 1/c (σ_k = σ_c / c²): the points' scatter taken as independent, and
      // the jackknife over faces (the scale fitted with each face left out, in one
      // step from here): a face's points move together, so the points alone were
      // overconfident (σ 2.6e-6 on the demo's main, 3σ off the emulator's scale), and
      // a face's pull on the scale depends on where it stands, not only on its offset.
      // A face without which the pose is no longer fixed says nothing here.
      if (fit_scale) {
        const double points_var = variance * ata.inverse()(6, 6);
        std::vector<double> left_out;
        for (size_t f = 0; f < face_ata.size(); ++f) {
          const Eigen::Matrix<double, 7, 7> a = ata - face_ata[f];
          if (!fixesThePose(a)) continue;
          left_out.push_back(a.ldlt().solve(atb - face_atb[f])(6));
        }
        double jack_var = 0;
        if (left_out.size() >= 2) {
          const double m = static_cast<double>(left_out.size());
          double mean = 0;
          for (double x : left_out) mean += x / m;
          for (double x : left_out) jack_var += (x - mean) * (x - mean);
          jack_var *= (m - 1) / m;
        }
        out.range_scale_sigma = std::sqrt(points_var + jack_var) / (c * c);
      }
      break;
    }
    const Eigen::Matrix<double, 7, 1> x = ata.ldlt().solve(atb);
    RigidTransform step = RigidTransform::Identity();
    const Vec3 w = x.head<3>();
    if (w.norm() > 0) step.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    step.translation() = x.segment<3>(3);
    t = step * t;
    c += x(6);
  }
  out.range_scale = 1 / c;
  progress("boat frame", 1.0);
  out.transform = t;
  out.below_uncertainty = out.fitness_rms_m <= p.uncertainty_m;
  if (!out.below_uncertainty)
    out.warnings.push_back("planes lie " + formatFixed(out.fitness_rms_m * 1000, 1) + " mm RMS off their faces, above the " +
                           formatFixed(p.uncertainty_m * 1000, 1) + " mm uncertainty");
  out.accepted = out.accepted && out.below_uncertainty && !out.ambiguous;
  return out;
}

Cloud toBoatFrame(const Cloud& cloud, const RigidTransform& transform, double range_scale) {
  return transformCloud(removeRangeScale(cloud, range_scale), transform);
}

}  // namespace sailshape
