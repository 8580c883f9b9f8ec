#pragma once
// Telling candidate poses apart (issue 35). A box room maps onto itself turned
// end for end or floor for ceiling, so overlap alone cannot choose: what does is
// the little that is not symmetric (a cube, an end wall) and the free space each
// unit saw through. Under a pose, each cloud's samples are placed along the
// other unit's beams (its range image about its viewpoint): a sample nearer than
// every return the other unit got that way (by more than 3σ_e) lies in space
// its beam crossed — impossible for a right pose but for the rate ε of stray
// returns (mixed pixels at edges). σ_e² = 2σ² + s²(r₁² + r₂²): both units'
// random error and the systematic range error s (SPEC §3).
// A sample among the other's returns that way (within their range span [near,
// far] widened by 3σ_e) coincides with its surface: a point anywhere along the
// beam (density 1/L, L the other's longest range) lands there with odds
// L / (far − near + 6σ_e). Coincidences count once per cell (coincidence_cell_m),
// weighted by the fraction of the cell's samples that coincide: samples on one
// surface coincide together, and counted one by one they would reward where the
// units' beams happen to be dense rather than the pose (a floor-for-ceiling swap
// that brings the units to one height overlaps more); a surface that merely
// crosses the other's coincides along a line, a small fraction of its cells.
//   log-likelihood = Σ_cells f·log(L / span) + Σ_samples in free space log ε
// Samples hidden behind the other's surface or out of its view carry nothing.
// `consistency` (every sample's log-density) ranks plane matches coarsely.
#include <memory>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/registration/rigid_transform.hpp"

namespace sailshape {

struct PoseVerificationParams {
  double sigma_m = 0.004;                 // random range error of one unit (SPEC §3)
  double systematic_fraction = 0.003;     // systematic range error bound (SPEC §3: up to 0.3 % of range)
  double free_space_outlier_rate = 0.01;  // ε
  size_t samples_per_cloud = 20000;       // evenly spread over each cloud
  double match_radius_m = 0.05;           // without viewpoints: a point farther than this from the other cloud is off its surface
  // Coincident surface counts once per cell of this size (the smallest plane the
  // detector accepts): neighbouring samples on one surface coincide together,
  // so their coincidences are one piece of evidence, not one per sample.
  double coincidence_cell_m = 0.25;
  // Risk of accepting the wrong one of two poses: the log-likelihood ratio must
  // exceed log(1/α) and z_α standard errors of the per-sample differences.
  double false_accept_probability = 1e-6;
};

struct PoseEvidence {
  double log_likelihood = 0;  // coincidence + Σ per_sample
  double coincidence = 0;     // Σ over cells holding coincident samples of f·log(L / span)
  size_t coincident_cells = 0;
  double consistency = 0;     // per-sample overlap score, for ranking only
  size_t on_surface = 0, hidden = 0, in_free_space = 0;
  std::vector<double> per_sample;  // free-space evidence of each sample, reference samples then moving samples
};

struct PoseComparison {
  double log_ratio = 0;       // log_likelihood(best) − log_likelihood(other)
  double standard_error = 0;  // √n · sd of the per-sample free-space differences
  double needed = 0;          // max(log(1/α), z_α · standard_error)
  bool decisive = false;      // log_ratio > needed
};

class PoseVerifier {
 public:
  // Both clouds in their own frames; either may lack a viewpoint (then it gives
  // no free-space evidence). Throws InvalidInput for bad parameters or empty clouds.
  PoseVerifier(const Cloud& reference, const Cloud& moving, const PoseVerificationParams& params = {});
  ~PoseVerifier();
  PoseVerifier(const PoseVerifier&) = delete;
  PoseVerifier& operator=(const PoseVerifier&) = delete;

  // `moving_to_reference`: the pose to score. `samples_limit`: use at most this
  // many samples of each cloud (a coarse screen), 0: all of them.
  PoseEvidence evaluate(const RigidTransform& moving_to_reference, size_t samples_limit = 0) const;
  PoseComparison compare(const PoseEvidence& best, const PoseEvidence& other) const;

 private:
  struct Side;
  PoseVerificationParams p_;
  std::unique_ptr<Side> reference_, moving_;
};

// One line naming a pose: "179.99° about (1.000, 0.000, 0.000), t = (0.100, 2.000, 1.000) m".
std::string describePose(const RigidTransform& t);

}  // namespace sailshape
