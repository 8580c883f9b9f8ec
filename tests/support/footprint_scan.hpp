#pragma once
// A scan that stops short of the sail's edges by the beam's footprint (SPEC §3:
// a beam straddling an edge returns a mixed pixel, which the cleaning removes),
// for the outline's footprint correction (analysis/outline) and for the
// viewer's re-analysis of a stored scan with its unit's beam.
#include <cmath>
#include <random>

#include "analysis/core/cloud.hpp"

namespace sailshape::test {

// A flat triangular main in the plane y = 0, 10 m luff, its head's angle 19°,
// seen from 8 m to windward.
inline const Vec3 kTack(0.0, 0.0, 1.0), kHead(-0.5, 0.0, 11.0), kClew(-3.6, 0.0, 1.3);
inline const Vec3 kScanner(-1.5, -8.0, 5.0);

inline bool insideTriangle(const Vec3& p) {
  auto side = [](const Vec3& a, const Vec3& b, const Vec3& q) {
    return (b.x() - a.x()) * (q.z() - a.z()) - (b.z() - a.z()) * (q.x() - a.x());
  };
  const double s1 = side(kTack, kHead, p), s2 = side(kHead, kClew, p), s3 = side(kClew, kTack, p);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

// Samples spread uniformly over the sail, each kept only when its whole beam lies
// on the sail: 32 rays round the beam's rim (leaving the exit window, of diameter
// `exit_m`, spreading at half of `divergence_rad`) all land inside the triangle. The
// beam is modelled here ray by ray, apart from how the outline corrects for it.
// The cloud's viewpoint is the scanner.
inline Cloud scanWithFootprint(int samples, unsigned seed, double exit_m, double divergence_rad) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Cloud c;
  c.viewpoint = kScanner;
  for (int i = 0; i < samples; ++i) {  // the trimmed band is left empty, the rest at one density
    double a = u01(rng), b = u01(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vec3 p = kTack + a * (kHead - kTack) + b * (kClew - kTack);
    const Vec3 d = (p - kScanner).normalized();
    const Vec3 e1 = d.unitOrthogonal(), e2 = d.cross(e1);
    bool whole = true;
    for (int k = 0; k < 32 && whole; ++k) {
      const double phi = 2.0 * M_PI * k / 32.0;
      const Vec3 rim = std::cos(phi) * e1 + std::sin(phi) * e2;
      const Vec3 origin = kScanner + 0.5 * exit_m * rim, dir = d + 0.5 * divergence_rad * rim;
      const Vec3 hit = origin + (-origin.y() / dir.y()) * dir;  // onto y = 0
      whole = insideTriangle(hit);
    }
    if (whole) c.points.push_back(p);
  }
  return c;
}

}  // namespace sailshape::test
