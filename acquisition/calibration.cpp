#include "acquisition/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {

namespace {

// Nuisance state of one target. Planes: normal n, offset d (n·x = d). Cylinders: axis point c and unit
// direction n (c kept as the point of the axis nearest the centroid).
struct Shape {
  Vec3 n = Vec3::UnitZ();
  double d = 0;
  Vec3 c = Vec3::Zero();
};

Vec3 offsetDerivativeP(double beta, double theta) { return {0, std::cos(beta + theta), std::sin(beta + theta)}; }
Vec3 offsetDerivativeTheta(double beta, double theta, double p) {
  return {0, -p * std::sin(beta + theta), p * std::cos(beta + theta)};
}

std::vector<Vec3> pointsOf(const CalibrationTarget& t, double p, double theta) {
  std::vector<Vec3> out;
  out.reserve(t.samples.size());
  for (const SweepPoint& s : t.samples) out.push_back(unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta));
  return out;
}

// Initial shape by principal axes: plane normal = least variance; cylinder axis = most variance.
Shape initialShape(const CalibrationTarget& t, const std::vector<Vec3>& pts) {
  const PrincipalAxes pa = principalAxes(pts);
  const Vec3& mean = pa.mean;
  Shape s;
  if (t.kind == CalibrationTarget::Kind::Plane) {
    s.n = pa.axes.col(0);
    s.d = s.n.dot(mean);
  } else {
    s.n = pa.axes.col(2);
    // The scanner sees the near side: the axis lies behind the centroid, away from the origin (the centroid
    // of a half cylinder's surface lies 2/π of the radius from its axis).
    Vec3 away = mean - s.n * s.n.dot(mean);
    if (away.norm() < 1e-9) away = s.n.unitOrthogonal();
    s.c = mean + t.radius_m * 0.7 * away.normalized();
    s.c -= s.n * s.n.dot(s.c - mean);
  }
  return s;
}

double residual(const CalibrationTarget& t, const Shape& s, const Vec3& x, Vec3* gradient) {
  if (t.kind == CalibrationTarget::Kind::Plane) {
    if (gradient) *gradient = s.n;
    return s.n.dot(x) - s.d;
  }
  const Vec3 v = x - s.c;
  const Vec3 radial = v - s.n * s.n.dot(v);
  const double dist = radial.norm();
  if (gradient) *gradient = dist > 1e-12 ? Vec3(radial / dist) : Vec3::Zero();
  return dist - t.radius_m;
}

// Two unit vectors spanning the plane perpendicular to n.
void tangents(const Vec3& n, Vec3& t1, Vec3& t2) {
  t1 = n.unitOrthogonal();
  t2 = n.cross(t1);
}

void validateTargets(const std::vector<CalibrationTarget>& targets, const CalibrationParams& params) {
  if (targets.empty()) throw InvalidInput("[calibrateUnit] no target given");
  if (!(params.sensor_sigma_m > 0) || !(params.max_rms_sigmas > 0))
    throw InvalidInput("[calibrateUnit] sensor_sigma_m and max_rms_sigmas must be > 0 (got " +
                       std::to_string(params.sensor_sigma_m) + ", " + std::to_string(params.max_rms_sigmas) + ")");
  if (!(params.initial_p_m > 0))
    throw InvalidInput("[calibrateUnit] initial_p_m must be > 0 (got " + std::to_string(params.initial_p_m) +
                       "): at p = 0 the angle θ has no effect");
  for (size_t k = 0; k < targets.size(); ++k) {
    if (targets[k].samples.size() < 10)
      throw InvalidInput("[calibrateUnit] target " + std::to_string(k) + " (" + targets[k].name + ") has " +
                         std::to_string(targets[k].samples.size()) + " samples; at least 10 are needed");
    if (targets[k].kind == CalibrationTarget::Kind::Cylinder && !(targets[k].radius_m > 0))
      throw InvalidInput("[calibrateUnit] cylinder target " + std::to_string(k) + " needs a radius > 0 (got " +
                         std::to_string(targets[k].radius_m) + ")");
  }
}

// The least-squares state. Parameters: p, θ, then per target 3 (plane: two normal tilts and the offset)
// or 4 (cylinder: two axis tilts and two axis shifts).
struct Fit {
  explicit Fit(const std::vector<CalibrationTarget>& t) : targets(t) {}
  const std::vector<CalibrationTarget>& targets;
  std::vector<size_t> first;              // each target's first parameter
  size_t np = 2;                          // parameters in all
  std::vector<std::vector<char>> inlier;  // per target and sample: counted in the cost
  double p = 0, theta = 0;
  std::vector<Shape> shapes;
  Eigen::MatrixXd JtJ;  // normal equations at the last linearisation
  Eigen::VectorXd Jtr;
};

Fit initialFit(const std::vector<CalibrationTarget>& targets, const CalibrationParams& params) {
  const size_t nt = targets.size();
  Fit f(targets);
  f.first.resize(nt);
  for (size_t k = 0; k < nt; ++k) {
    f.first[k] = f.np;
    f.np += targets[k].kind == CalibrationTarget::Kind::Plane ? 3 : 4;
  }
  f.p = params.initial_p_m;
  f.theta = params.initial_theta_rad;
  f.shapes.resize(nt);
  for (size_t k = 0; k < nt; ++k) f.shapes[k] = initialShape(targets[k], pointsOf(targets[k], f.p, f.theta));
  f.inlier.resize(nt);
  for (size_t k = 0; k < nt; ++k) f.inlier[k].assign(targets[k].samples.size(), 1);
  f.JtJ = Eigen::MatrixXd::Zero(f.np, f.np);
  f.Jtr = Eigen::VectorXd::Zero(f.np);
  return f;
}

// Sum of squared residuals (m²) over the inliers at p = pp, θ = tt and shapes `sh`.
double fitCost(const Fit& f, double pp, double tt, const std::vector<Shape>& sh) {
  double c = 0;
  for (size_t k = 0; k < f.targets.size(); ++k)
    for (size_t i = 0; i < f.targets[k].samples.size(); ++i) {
      if (!f.inlier[k][i]) continue;
      const SweepPoint& s = f.targets[k].samples[i];
      const double r = residual(f.targets[k], sh[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, pp, tt), nullptr);
      c += r * r;
    }
  return c;
}

// JᵀJ and Jᵀr at the current state; t1, t2 span each shape's tilts.
void linearise(Fit& f, const std::vector<Vec3>& t1, const std::vector<Vec3>& t2) {
  f.JtJ.setZero();
  f.Jtr.setZero();
  Eigen::VectorXd row(f.np);
  for (size_t k = 0; k < f.targets.size(); ++k) {
    const CalibrationTarget& target = f.targets[k];
    const bool plane = target.kind == CalibrationTarget::Kind::Plane;
    for (size_t i = 0; i < target.samples.size(); ++i) {
      if (!f.inlier[k][i]) continue;
      const SweepPoint& s = target.samples[i];
      const Vec3 x = unitPoint(s.range_m, s.alpha_rad, s.beta_rad, f.p, f.theta);
      Vec3 g;
      const double r = residual(target, f.shapes[k], x, &g);
      row.setZero();
      row(0) = g.dot(offsetDerivativeP(s.beta_rad, f.theta));
      row(1) = g.dot(offsetDerivativeTheta(s.beta_rad, f.theta, f.p));
      const size_t c = f.first[k];
      if (plane) {
        // n → normalize(n + a t1 + b t2), d → d + e.
        row(c) = t1[k].dot(x);
        row(c + 1) = t2[k].dot(x);
        row(c + 2) = -1;
      } else {
        // Axis direction tilts (a, b) about the point c, axis shifts (e, h) along t1, t2.
        const Vec3 v = x - f.shapes[k].c;
        const double along = f.shapes[k].n.dot(v);
        row(c) = -along * g.dot(t1[k]);
        row(c + 1) = -along * g.dot(t2[k]);
        row(c + 2) = -g.dot(t1[k]);
        row(c + 3) = -g.dot(t2[k]);
      }
      f.JtJ.noalias() += row * row.transpose();
      f.Jtr.noalias() += row * r;
    }
  }
}

// The shapes moved by the step's nuisance parameters.
std::vector<Shape> steppedShapes(const Fit& f, const Eigen::VectorXd& step, const std::vector<Vec3>& t1,
                                 const std::vector<Vec3>& t2) {
  std::vector<Shape> trial = f.shapes;
  for (size_t k = 0; k < f.targets.size(); ++k) {
    const size_t c = f.first[k];
    Shape& s = trial[k];
    if (f.targets[k].kind == CalibrationTarget::Kind::Plane) {
      s.n = (s.n + step(c) * t1[k] + step(c + 1) * t2[k]).normalized();
      s.d += step(c + 2);
    } else {
      s.n = (s.n + step(c) * t1[k] + step(c + 1) * t2[k]).normalized();
      s.c += step(c + 2) * t1[k] + step(c + 3) * t2[k];
    }
  }
  return trial;
}

// Gauss–Newton with Levenberg damping over the current inliers; whether it converged.
bool solve(Fit& f, const CalibrationParams& params, int& iterations) {
  const size_t nt = f.targets.size();
  double lambda = 1e-3;
  double current = fitCost(f, f.p, f.theta, f.shapes);
  bool converged = false;
  for (int it = 0; it < params.max_iterations; ++it) {
    ++iterations;
    std::vector<Vec3> t1(nt), t2(nt);
    for (size_t k = 0; k < nt; ++k) tangents(f.shapes[k].n, t1[k], t2[k]);
    linearise(f, t1, t2);
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      Eigen::MatrixXd A = f.JtJ;
      A.diagonal() += lambda * f.JtJ.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = -A.ldlt().solve(f.Jtr);
      const double p_new = f.p + step(0), theta_new = f.theta + step(1);
      std::vector<Shape> trial = steppedShapes(f, step, t1, t2);
      const double c = fitCost(f, p_new, theta_new, trial);
      if (std::isfinite(c) && c <= current) {
        const double change = current - c;
        f.p = p_new;
        f.theta = theta_new;
        f.shapes = trial;
        lambda = std::max(lambda / 3, 1e-9);
        improved = true;
        if (change <= 1e-12 * current || step.head<2>().norm() < 1e-10) converged = true;
        current = c;
      } else {
        lambda *= 10;
      }
    }
    if (!improved || converged) {
      converged = converged || !improved;  // no step lowers the cost: at the minimum within precision
      break;
    }
  }
  return converged;
}

// Robust σ from the median absolute residual; samples beyond params.outlier_sigmas of it, or seen at
// more than params.max_incidence_deg, leave the fit.
void dropOutliers(Fit& f, const CalibrationParams& params) {
  const size_t nt = f.targets.size();
  std::vector<double> abs_res;
  for (size_t k = 0; k < nt; ++k)
    for (const SweepPoint& s : f.targets[k].samples)
      abs_res.push_back(std::abs(
          residual(f.targets[k], f.shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, f.p, f.theta), nullptr)));
  std::nth_element(abs_res.begin(), abs_res.begin() + abs_res.size() / 2, abs_res.end());
  const double cut = params.outlier_sigmas <= 0 ? std::numeric_limits<double>::infinity()
                                                : params.outlier_sigmas * 1.4826 * abs_res[abs_res.size() / 2];
  const double cos_max = std::cos(params.max_incidence_deg * kRadPerDeg);
  for (size_t k = 0; k < nt; ++k)
    for (size_t i = 0; i < f.targets[k].samples.size(); ++i) {
      const SweepPoint& s = f.targets[k].samples[i];
      Vec3 g;
      const double r =
          residual(f.targets[k], f.shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, f.p, f.theta), &g);
      const Vec3 ray(std::cos(s.alpha_rad), std::sin(s.alpha_rad) * std::cos(s.beta_rad),
                     std::sin(s.alpha_rad) * std::sin(s.beta_rad));
      f.inlier[k][i] = std::abs(r) <= cut && std::abs(ray.dot(g)) >= cos_max;
    }
}

// Per-target residuals and shapes, p and θ in their positive form, standard errors and warnings.
void reportFit(const Fit& f, const CalibrationParams& params, CalibrationResult& result) {
  size_t used = 0;
  double total = 0;
  for (size_t k = 0; k < f.targets.size(); ++k) {
    const CalibrationTarget& target = f.targets[k];
    CalibrationTargetResult tr;
    tr.name = target.name;
    tr.points = target.samples.size();
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < target.samples.size(); ++i) {
      if (!f.inlier[k][i]) {
        ++tr.outliers;
        continue;
      }
      const SweepPoint& s = target.samples[i];
      const double r = residual(target, f.shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, f.p, f.theta), nullptr);
      sum += r * r;
      tr.max_abs_m = std::max(tr.max_abs_m, std::abs(r));
      ++n;
    }
    tr.rms_m = n ? std::sqrt(sum / n) : 0;
    tr.normal = f.shapes[k].n;
    tr.point = f.shapes[k].c;
    tr.offset_m = f.shapes[k].d;
    total += sum;
    used += n;
    result.targets.push_back(tr);
  }
  result.p_m = f.p;
  result.theta_rad = std::remainder(f.theta, 2 * M_PI);
  result.rms_m = used ? std::sqrt(total / used) : 0;
  if (f.p < 0) {
    // (−p, θ + π) is the same geometry; report the positive form.
    result.p_m = -f.p;
    result.theta_rad = std::remainder(f.theta + M_PI, 2 * M_PI);
  }
  const double dof = static_cast<double>(used) - static_cast<double>(f.np);
  if (dof > 0) {
    const Eigen::MatrixXd cov = f.JtJ.ldlt().solve(Eigen::MatrixXd::Identity(f.np, f.np)) * (total / dof);
    result.p_stderr_m = std::sqrt(std::max(0.0, cov(0, 0)));
    result.theta_stderr_rad = std::sqrt(std::max(0.0, cov(1, 1)));
  }
  if (!result.converged) result.warnings.push_back("the least-squares fit did not converge");
  for (const CalibrationTargetResult& t : result.targets)
    if (t.rms_m > params.max_rms_sigmas * params.sensor_sigma_m) {
      result.plausible = false;
      result.warnings.push_back("target " + t.name + " fits its shape to " + std::to_string(t.rms_m * 1000) +
                                " mm RMS, far above the sensor's " + std::to_string(params.sensor_sigma_m * 1000) +
                                " mm: it is not one " + "plane or cylinder" +
                                " (crop it to one face with @box); p and θ are not usable");
    }
  if (result.theta_stderr_rad > 0.5 * kRadPerDeg)
    result.warnings.push_back("θ is poorly determined (±" + std::to_string(result.theta_stderr_rad * kDegPerRad) +
                              "°): add a second plane at an angle to the first, or sweep a wider β range");
}

}  // namespace

CalibrationResult calibrateUnit(const std::vector<CalibrationTarget>& targets, const CalibrationParams& params) {
  validateTargets(targets, params);
  Fit fit = initialFit(targets, params);
  CalibrationResult result;
  // Fit, drop the outliers, fit again.
  result.converged = solve(fit, params, result.iterations);
  dropOutliers(fit, params);
  result.converged = solve(fit, params, result.iterations);
  reportFit(fit, params, result);
  return result;
}

}  // namespace sailshape

namespace sailshape {

namespace {

// Least-squares plane through points: unit normal and offset (n·x = d).
void planeOf(const std::vector<Vec3>& pts, Vec3& n, double& d) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& q : pts) c += q;
  c /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& q : pts) cov += (q - c) * (q - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  n = es.eigenvectors().col(0).normalized();
  d = n.dot(c);
}

}  // namespace

RangeScaleFit fitRangeScale(const std::vector<KnownSpan>& spans) {
  if (spans.empty()) throw InvalidInput("[fitRangeScale] no span given");
  RangeScaleFit fit;
  double md = 0, dd = 0;
  for (const KnownSpan& s : spans) {
    if (s.face_a.size() < 10 || s.face_b.size() < 10)
      throw InvalidInput("[fitRangeScale] span '" + s.name + "' needs at least 10 points on each face (got " +
                         std::to_string(s.face_a.size()) + " and " + std::to_string(s.face_b.size()) + ")");
    if (!(s.distance_m > 0))
      throw InvalidInput("[fitRangeScale] span '" + s.name + "' needs a distance > 0 (got " + std::to_string(s.distance_m) + ")");
    Vec3 na, nb;
    double da, db;
    planeOf(s.face_a, na, da);
    planeOf(s.face_b, nb, db);
    if (na.dot(nb) < 0) {
      nb = -nb;
      db = -db;
    }
    if (na.dot(nb) < std::cos(5 * kRadPerDeg))
      throw InvalidInput("[fitRangeScale] the faces of span '" + s.name + "' are " +
                         std::to_string(std::acos(std::min(1.0, na.dot(nb))) * kDegPerRad) + "° from parallel (at most 5°)");
    const double measured = std::abs(da - db);
    fit.measured_m.push_back(measured);
    md += measured * s.distance_m;
    dd += s.distance_m * s.distance_m;
  }
  fit.scale = md / dd;
  double sum2 = 0;
  for (size_t i = 0; i < spans.size(); ++i) {
    const double r = fit.measured_m[i] / fit.scale - spans[i].distance_m;
    sum2 += r * r;
  }
  fit.residual_rms_m = std::sqrt(sum2 / static_cast<double>(spans.size()));
  if (spans.size() > 1) fit.scale_stderr = std::sqrt(sum2 / static_cast<double>(spans.size() - 1) / dd) * fit.scale;
  return fit;
}

}  // namespace sailshape
