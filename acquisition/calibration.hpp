#pragma once
// The unit's geometric constants p and θ (SPEC §2) by least squares: choose
// them so that sweeps of known shapes — planes of unknown position, cylinders
// of known radius — fit best (the study's procedure, chapter 4). Each target
// brings its own nuisance parameters (plane normal and offset; cylinder axis);
// p and θ are shared. Gauss–Newton with Levenberg damping, then one refit
// without residuals beyond a robust cut (mixed pixels, stray returns) and
// without samples at steep incidence.
//
// Conditioning: a single plane seen over a narrow β range cannot separate θ
// from the plane's tilt; two planes at an angle (a wall and the floor) or a
// cylinder, seen over a wide β range, can. The result reports standard errors
// so a poor set-up shows.
#include <string>
#include <vector>

#include "acquisition/sweep.hpp"

namespace sailshape {

struct CalibrationTarget {
  enum class Kind { Plane, Cylinder } kind = Kind::Plane;
  double radius_m = 0;              // cylinders: known radius
  std::vector<SweepPoint> samples;  // r, α, β of the target's points only
  std::string name;
};

struct CalibrationParams {
  double initial_p_m = 0.05;        // must be > 0: θ has no effect at p = 0
  double initial_theta_rad = 0.0;
  int max_iterations = 100;
  double outlier_sigmas = 4.0;      // refit without |residual| > this × robust σ (0: keep all)
  // The refit also drops samples seen at more than this incidence: SPEC §3's noise is flat only up to ≈ 70°,
  // and the steep samples would otherwise weigh as much as the good ones.
  double max_incidence_deg = 65.0;
  // A target whose residual RMS exceeds max_rms_sigmas × the sensor's σ is not
  // the shape it was said to be (a "plane" that is the whole tunnel): the fit is
  // implausible. SPEC §3's σ spans 3.3–4.1 mm across materials below 70°
  // incidence, so twice 4 mm lies beyond every honest plane.
  double sensor_sigma_m = 0.004;
  double max_rms_sigmas = 2.0;
};

struct CalibrationTargetResult {
  std::string name;
  size_t points = 0, outliers = 0;
  double rms_m = 0;                 // residual RMS after the fit (outliers excluded)
  double max_abs_m = 0;
  // The fitted shape (unit frame): plane n·x = d, or cylinder axis through `point` along `normal`.
  Vec3 normal = Vec3::Zero(), point = Vec3::Zero();
  double offset_m = 0;
};

struct CalibrationResult {
  double p_m = 0, theta_rad = 0;
  double p_stderr_m = 0, theta_stderr_rad = 0;  // from the normal equations and the residual variance
  double rms_m = 0;                             // over all targets
  int iterations = 0;
  bool converged = false;
  // Every target's residual RMS within max_rms_sigmas × sensor_sigma_m; when
  // not, a warning names the target and p and θ must not be used.
  bool plausible = true;
  std::vector<CalibrationTargetResult> targets;
  std::vector<std::string> warnings;
};

// Throws InvalidInput: no target, a target with fewer than 10 samples, a cylinder without a positive
// radius, initial_p_m ≤ 0, sensor_sigma_m or max_rms_sigmas ≤ 0.
CalibrationResult calibrateUnit(const std::vector<CalibrationTarget>& targets, const CalibrationParams& params = {});

}  // namespace sailshape

namespace sailshape {

// Range-scale calibration (issue 35). A systematic range error (SPEC §3: up to
// ≈ 0.3 % of range) multiplies every range by a scale k = 1 + s: seen from the
// unit, the whole scene is stretched by k about the scanner (to within p·s, a
// fraction of a millimetre), so two parallel faces a known distance D apart (the
// tunnel's width or height, opposite faces of a reference cube) measure k·D apart.
struct KnownSpan {
  std::string name;                  // "tunnel width", "cube edge", ...
  std::vector<Vec3> face_a, face_b;  // points of the two faces, unit frame (metres)
  double distance_m = 0;             // their true separation
};

struct RangeScaleFit {
  double scale = 1;           // measured range / true range (k)
  double scale_stderr = 0;    // from the spans' residuals (0 with one span)
  double residual_rms_m = 0;  // of measured / k − true over the spans
  std::vector<double> measured_m;  // each span's separation as measured (fitted planes)
};

// Least squares k = Σ m·D / Σ D² over the spans. Throws InvalidInput for no
// span, a face with fewer than 10 points, a distance ≤ 0, or faces more than 5°
// from parallel.
RangeScaleFit fitRangeScale(const std::vector<KnownSpan>& spans);

// removeRangeScale (analysis/registration/rigid_transform.hpp) applies a fitted scale.

}  // namespace sailshape
