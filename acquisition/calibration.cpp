#include "acquisition/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {

namespace {

// Nuisance state of one target. Planes: normal n, offset d (n·x = d). Cylinders: axis point c and unit
// direction a (c kept as the point of the axis nearest the centroid).
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
    // The scanner sees the near side: the axis lies one radius behind the centroid, away from the origin.
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

}  // namespace

CalibrationResult calibrateUnit(const std::vector<CalibrationTarget>& targets, const CalibrationParams& params) {
  if (targets.empty()) throw InvalidInput("[calibrateUnit] no target given");
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
  const size_t nt = targets.size();
  // Parameters: p, θ, then per target 3 (plane: two normal tilts and the offset) or 4 (cylinder: two axis
  // tilts and two axis shifts).
  std::vector<size_t> first(nt);
  size_t np = 2;
  for (size_t k = 0; k < nt; ++k) {
    first[k] = np;
    np += targets[k].kind == CalibrationTarget::Kind::Plane ? 3 : 4;
  }
  double p = params.initial_p_m, theta = params.initial_theta_rad;
  std::vector<Shape> shapes(nt);
  for (size_t k = 0; k < nt; ++k) shapes[k] = initialShape(targets[k], pointsOf(targets[k], p, theta));
  std::vector<std::vector<char>> inlier(nt);
  for (size_t k = 0; k < nt; ++k) inlier[k].assign(targets[k].samples.size(), 1);

  CalibrationResult result;
  const auto cost = [&](double pp, double tt, const std::vector<Shape>& sh) {
    double c = 0;
    for (size_t k = 0; k < nt; ++k)
      for (size_t i = 0; i < targets[k].samples.size(); ++i) {
        if (!inlier[k][i]) continue;
        const SweepPoint& s = targets[k].samples[i];
        const double r = residual(targets[k], sh[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, pp, tt), nullptr);
        c += r * r;
      }
    return c;
  };

  Eigen::MatrixXd JtJ(np, np);
  Eigen::VectorXd Jtr(np);
  for (int pass = 0; pass < 2; ++pass) {
    double lambda = 1e-3;
    double current = cost(p, theta, shapes);
    bool converged = false;
    for (int it = 0; it < params.max_iterations; ++it) {
      ++result.iterations;
      JtJ.setZero();
      Jtr.setZero();
      std::vector<Vec3> t1(nt), t2(nt);
      for (size_t k = 0; k < nt; ++k) tangents(shapes[k].n, t1[k], t2[k]);
      Eigen::VectorXd row(np);
      for (size_t k = 0; k < nt; ++k) {
        const bool plane = targets[k].kind == CalibrationTarget::Kind::Plane;
        for (size_t i = 0; i < targets[k].samples.size(); ++i) {
          if (!inlier[k][i]) continue;
          const SweepPoint& s = targets[k].samples[i];
          const Vec3 x = unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta);
          Vec3 g;
          const double r = residual(targets[k], shapes[k], x, &g);
          row.setZero();
          row(0) = g.dot(offsetDerivativeP(s.beta_rad, theta));
          row(1) = g.dot(offsetDerivativeTheta(s.beta_rad, theta, p));
          const size_t f = first[k];
          if (plane) {
            // n → normalize(n + a t1 + b t2), d → d + e.
            row(f) = t1[k].dot(x);
            row(f + 1) = t2[k].dot(x);
            row(f + 2) = -1;
          } else {
            // Axis direction tilts (a, b) about the point c, axis shifts (e, h) along t1, t2.
            const Vec3 v = x - shapes[k].c;
            const double along = shapes[k].n.dot(v);
            row(f) = -along * g.dot(t1[k]);
            row(f + 1) = -along * g.dot(t2[k]);
            row(f + 2) = -g.dot(t1[k]);
            row(f + 3) = -g.dot(t2[k]);
          }
          JtJ.noalias() += row * row.transpose();
          Jtr.noalias() += row * r;
        }
      }
      bool improved = false;
      for (int tries = 0; tries < 12 && !improved; ++tries) {
        Eigen::MatrixXd A = JtJ;
        A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
        const Eigen::VectorXd step = -A.ldlt().solve(Jtr);
        const double p_new = p + step(0), theta_new = theta + step(1);
        std::vector<Shape> trial = shapes;
        for (size_t k = 0; k < nt; ++k) {
          const size_t f = first[k];
          Shape& s = trial[k];
          if (targets[k].kind == CalibrationTarget::Kind::Plane) {
            s.n = (s.n + step(f) * t1[k] + step(f + 1) * t2[k]).normalized();
            s.d += step(f + 2);
          } else {
            s.n = (s.n + step(f) * t1[k] + step(f + 1) * t2[k]).normalized();
            s.c += step(f + 2) * t1[k] + step(f + 3) * t2[k];
          }
        }
        const double c = cost(p_new, theta_new, trial);
        if (std::isfinite(c) && c <= current) {
          const double change = current - c;
          p = p_new;
          theta = theta_new;
          shapes = trial;
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
    result.converged = converged;
    if (pass == 1) break;
    // Robust σ from the median absolute residual; drop the far ones and fit again.
    std::vector<double> abs_res;
    for (size_t k = 0; k < nt; ++k)
      for (const SweepPoint& s : targets[k].samples)
        abs_res.push_back(std::abs(residual(targets[k], shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta), nullptr)));
    std::nth_element(abs_res.begin(), abs_res.begin() + abs_res.size() / 2, abs_res.end());
    const double cut = params.outlier_sigmas <= 0 ? std::numeric_limits<double>::infinity() : params.outlier_sigmas * 1.4826 * abs_res[abs_res.size() / 2];
    const double cos_max = std::cos(params.max_incidence_deg * M_PI / 180);
    for (size_t k = 0; k < nt; ++k)
      for (size_t i = 0; i < targets[k].samples.size(); ++i) {
        const SweepPoint& s = targets[k].samples[i];
        Vec3 g;
        const double r =
            residual(targets[k], shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta), &g);
        const Vec3 ray(std::cos(s.alpha_rad), std::sin(s.alpha_rad) * std::cos(s.beta_rad),
                       std::sin(s.alpha_rad) * std::sin(s.beta_rad));
        inlier[k][i] = std::abs(r) <= cut && std::abs(ray.dot(g)) >= cos_max;
      }
  }

  // Diagnostics.
  size_t used = 0;
  double total = 0;
  for (size_t k = 0; k < nt; ++k) {
    CalibrationTargetResult tr;
    tr.name = targets[k].name;
    tr.points = targets[k].samples.size();
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < targets[k].samples.size(); ++i) {
      if (!inlier[k][i]) {
        ++tr.outliers;
        continue;
      }
      const SweepPoint& s = targets[k].samples[i];
      const double r = residual(targets[k], shapes[k], unitPoint(s.range_m, s.alpha_rad, s.beta_rad, p, theta), nullptr);
      sum += r * r;
      tr.max_abs_m = std::max(tr.max_abs_m, std::abs(r));
      ++n;
    }
    tr.rms_m = n ? std::sqrt(sum / n) : 0;
    tr.normal = shapes[k].n;
    tr.point = shapes[k].c;
    tr.offset_m = shapes[k].d;
    total += sum;
    used += n;
    result.targets.push_back(tr);
  }
  result.p_m = p;
  result.theta_rad = std::remainder(theta, 2 * M_PI);
  result.rms_m = used ? std::sqrt(total / used) : 0;
  if (p < 0) {
    // (−p, θ + π) is the same geometry; report the positive form.
    result.p_m = -p;
    result.theta_rad = std::remainder(theta + M_PI, 2 * M_PI);
  }
  const double dof = static_cast<double>(used) - static_cast<double>(np);
  if (dof > 0) {
    const Eigen::MatrixXd cov = JtJ.ldlt().solve(Eigen::MatrixXd::Identity(np, np)) * (total / dof);
    result.p_stderr_m = std::sqrt(std::max(0.0, cov(0, 0)));
    result.theta_stderr_rad = std::sqrt(std::max(0.0, cov(1, 1)));
  }
  if (!result.converged) result.warnings.push_back("the least-squares fit did not converge");
  if (result.theta_stderr_rad > 0.5 * M_PI / 180)
    result.warnings.push_back("θ is poorly determined (±" + std::to_string(result.theta_stderr_rad * 180 / M_PI) +
                              "°): add a second plane at an angle to the first, or sweep a wider β range");
  return result;
}

}  // namespace sailshape
