#pragma once
// Point clouds in SI units. Per-point attributes are optional: each vector is
// either empty or the same length as `points`.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <vector>

namespace sailshape {

using Vec3 = Eigen::Vector3d;

struct Cloud {
  std::vector<Vec3> points;            // metres, frame given by context (boat frame after registration)
  std::vector<float> intensity;        // RSSI or reflectivity, device units
  std::vector<double> alpha_rad;       // scanner mirror angle α of each sample (SPEC §2)
  std::vector<double> beta_rad;        // turntable angle β of each sample
  std::optional<Vec3> viewpoint;       // scanner origin, same frame as points
  // The range of the scanner that took the samples (SPEC §3: 20 m for the LMS111, 80 m
  // for the LMS511), m; 0: unknown. Where the samples stop at it, the scan ran out of
  // range there, whatever lay beyond.
  double scanner_range_m = 0;
  // Turntable angles β of the scan lines the sweep lost (the scanner counted them and
  // none arrived), ascending, each at its line's middle beam. An edge beside one may lie
  // a line spacing further out than the samples say.
  std::vector<double> lost_beta_rad;

  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool hasIntensity() const { return !intensity.empty(); }
  bool hasScanAngles() const { return !alpha_rad.empty() && !beta_rad.empty(); }
};

// The subset of `cloud` at `indices`, attributes included.
Cloud selectPoints(const Cloud& cloud, const std::vector<uint32_t>& indices);

// Unit normals and surface variation (curvature) per point, same order as the cloud.
struct Normals {
  std::vector<Vec3> normals;
  std::vector<double> curvature;  // λ0 / (λ0 + λ1 + λ2) of the neighbourhood covariance, in [0, 1/3]
};

}  // namespace sailshape
