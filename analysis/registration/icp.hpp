#pragma once
// Fine registration (SPEC §4 step 2, last stage): the crossed filter that keeps
// only the overlap of two roughly aligned clouds, ICP point-to-point and
// point-to-plane, and the distribution of nearest-neighbour distances that
// shows what a refinement did.
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/registration/rigid_transform.hpp"

namespace sailshape {

// Points of each cloud with at least one point of the other cloud within
// radius_m (the study's "crossed" filter): the overlap, where correspondences
// can be right. `moving` must already be in the reference frame.
struct CrossedFilter {
  std::vector<uint32_t> reference;  // indices into the reference cloud
  std::vector<uint32_t> moving;     // indices into the moving cloud
};
CrossedFilter crossedFilter(const Cloud& reference, const Cloud& moving, double radius_m);

// Distances from each moving point to its nearest reference point, m.
struct NeighbourDistanceStats {
  size_t count = 0;
  double mean_m = 0, median_m = 0, p90_m = 0, max_m = 0, rms_m = 0;
  double bin_m = 0.005;              // histogram bin width
  std::vector<size_t> histogram;     // counts in [i·bin, (i+1)·bin); the last bin also holds everything beyond
};
// Throws InvalidInput for an empty cloud or a bin width/count that is not positive.
NeighbourDistanceStats nearestDistanceStats(const Cloud& reference, const Cloud& moving, double bin_m = 0.005,
                                   size_t bins = 20);

struct IcpParams {
  std::string method = "point-to-plane";  // or "point-to-point"
  int max_iterations = 50;
  // Pairs farther apart than this are not correspondences; overlap is what the
  // crossed filter left, so this can stay a few σ wide.
  double max_correspondence_m = 0.05;
  // Pairs whose normals differ more than this are dropped (point-to-plane):
  // near an edge the nearest reference point may sit on the other face.
  double max_normal_angle_deg = 20.0;
  int normal_k = 20;
  // Point-to-plane uses only reference points this flat (surface variation,
  // see Normals): edges and corners have no tangent plane to slide on.
  double max_curvature = 0.01;
  // Point-to-plane pairs are weighted by Tukey's biweight on 1.4826·MAD of the
  // residuals, never on a scale below this (noise-free data would give zero).
  double min_robust_scale_m = 1e-4;
  // Stop when one iteration moves the cloud less than this (rotation, translation).
  double min_step_rotation_deg = 1e-3;
  double min_step_translation_m = 1e-5;
  size_t min_correspondences = 30;
};

struct IcpResult {
  RigidTransform transform = RigidTransform::Identity();  // moving → reference, including the initial guess
  int iterations = 0;
  bool converged = false;
  size_t correspondences = 0;  // in the last iteration
  double rms_m = 0;            // point-to-plane (or point-to-point) residual RMS in the last iteration
  std::vector<std::string> warnings;
};

// A plane both clouds saw (matched by the plane method): every moving point on
// it, wherever it lies, is held to the reference's fitted plane, in the same
// least squares as the point-to-plane pairs. Whole walls seen by each unit fix
// the rotation far better than the strip where the two clouds overlap.
struct PlaneAnchor {
  Vec3 normal = Vec3::UnitZ();  // reference plane {x : normal·x = offset_m}, reference frame
  double offset_m = 0;
  std::vector<Vec3> moving_points;  // moving frame
};

// Refines `initial` (moving → reference). Throws InvalidInput for bad
// parameters or clouds too small for the normals; running out of
// correspondences or iterations is a result (converged = false, a warning).
IcpResult refineIcp(const Cloud& reference, const Cloud& moving, const RigidTransform& initial,
                    const IcpParams& params = {}, const Progress& progress = {},
                    const std::vector<PlaneAnchor>& anchors = {});

}  // namespace sailshape
