#pragma once
// Planar regions of a scene (tunnel walls, floor, ceiling, deck, the faces of a
// reference cube), for the plane-based registration of SPEC §4 step 2: region
// growing on normals and curvature proposes regions, a RANSAC plane test keeps
// the flat ones and peels further planes off regions that hold several and
// off the points no region took, a least-squares fit on the inliers gives
// each plane's pose.
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/segmentation/segmentation.hpp"

namespace sailshape {

struct DetectedPlane {
  Vec3 normal = Vec3::UnitZ();  // unit; oriented towards the scanner (the cloud's viewpoint, else its origin)
  double offset_m = 0;          // the plane is {x : normal·x = offset_m}
  Vec3 centroid = Vec3::Zero();  // of the inliers
  size_t points = 0;             // inliers
  double rms_m = 0;              // RMS distance of the inliers to the plane
  double extent_m = 0;           // larger in-plane spread (2 × 2σ along the first principal axis)
  double width_m = 0;            // smaller in-plane spread (2 × 2σ along the second principal axis)
  std::vector<uint32_t> indices;  // inliers, into the cloud
};

struct PlaneDetectionParams {
  int normal_k = 20;
  RegionGrowingParams region{20, 4.0, 0.02, 200, 50'000'000};
  double ransac_threshold_m = 0.012;  // 3σ of the sensor's random error (SPEC §3)
  int ransac_iterations = 100;
  double min_inlier_fraction = 0.85;  // of a region's points within the threshold of its RANSAC plane
  double max_rms_m = 0.008;           // a plane's inliers lie within ~2σ RMS of it
  // A region that is not one plane (two faces of a cube joined over their
  // edge), and the connected points no region took (a face seen head-on at a
  // density where the noise exceeds the curvature limit), are split: the
  // dominant plane is peeled off and each connected rest of at least
  // region.min_points tried again. Such a piece must lie as close to its
  // plane as the sensor allows (SPEC §3, σ = 4 mm): within σ + 25 % RMS.
  double max_piece_rms_m = 0.005;
  // No plane may bow from flat by more than σ/2 RMS (a quadric fitted to its
  // points' distances, noise aside): a patch or band of a curved sail does.
  double max_bow_m = 0.002;
  double min_extent_m = 0.25;         // both in-plane spreads at least this
  // Regions of one physical plane split by an occlusion are merged when their
  // normals are within this angle and their offsets within this distance.
  double merge_angle_deg = 2.0;
  double merge_distance_m = 0.03;
  size_t max_planes = 12;  // the largest are kept
  uint64_t seed = 1;
};

struct PlaneDetection {
  std::vector<DetectedPlane> planes;  // largest (most inliers) first
  size_t regions = 0;                 // regions region growing proposed
  size_t split_planes = 0;            // planes peeled from regions that were not one plane
  std::vector<std::string> warnings;  // e.g. regions rejected as not flat
};

// Throws InvalidInput for bad parameters or a cloud with fewer points than
// normal_k; finding no plane is not an error (the caller decides).
PlaneDetection detectPlanes(const Cloud& cloud, const PlaneDetectionParams& params = {},
                            const Progress& progress = {});

// Least-squares plane through points[indices] (normal sign arbitrary), with
// its spreads; throws InvalidInput for fewer than 3 points.
DetectedPlane fitPlane(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices);

// The point common to three planes; throws AnalysisError when their normals
// are (nearly) coplanar (|det| < min_det), so no single point exists.
Vec3 intersectPlanes(const DetectedPlane& a, const DetectedPlane& b, const DetectedPlane& c, double min_det = 0.05);

}  // namespace sailshape
