#pragma once
// What a user would pick in Open3D 0.16 instead of sailshape's registration:
// the global registration tutorial's chain (voxel downsampling, normals, FPFH,
// RANSAC on feature matches, then point-to-plane ICP on the full clouds). Open3D
// stays inside open3d_registration.cpp: this header holds only Eigen types that
// need no alignment, so nothing of Open3D (nor its Eigen settings) reaches the
// translation units that include PCL through sailshape's libraries.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sailshape::bench {

// Multiples of the voxel are the tutorial's (docs/tutorial/pipelines/global_registration).
struct Open3dRegistrationParams {
  double voxel_m = 0.05;                 // the tutorial's size for clouds in metres
  double normal_radius_voxels = 2;       // normals: hybrid search, this radius, at most normal_max_nn
  int normal_max_nn = 30;
  double fpfh_radius_voxels = 5;         // FPFH: hybrid search, this radius, at most fpfh_max_nn
  int fpfh_max_nn = 100;
  bool mutual_filter = true;             // a feature match must be each other's nearest
  double ransac_distance_voxels = 1.5;   // RANSAC inlier distance and the distance checker's
  double edge_length_similarity = 0.9;   // CorrespondenceCheckerBasedOnEdgeLength
  int ransac_max_iterations = 100000;
  double ransac_confidence = 0.999;
  double icp_distance_voxels = 0.4;      // point-to-plane ICP's correspondence distance
  int icp_max_iterations = 30;           // ICPConvergenceCriteria's default
  // Normals point to each unit's origin (the scanner) before FPFH; the tutorial
  // leaves them as the eigen-solver gives them.
  bool orient_normals_to_scanner = false;
  int seed = 0;                          // utility::random::Seed, for RANSAC's draws
};

struct Open3dRegistration {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // moving → reference
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // m
  size_t reference_voxels = 0, moving_voxels = 0;          // points after downsampling
  double ransac_fitness = 0, ransac_rmse_m = 0;            // RANSAC's result, on the downsampled clouds
  size_t ransac_inliers = 0;
  double icp_fitness = 0, icp_rmse_m = 0;                  // ICP's: fraction of moving points within icp distance
  double features_s = 0, ransac_s = 0, icp_s = 0;          // wall time of the stages (downsampling, normals, FPFH)
};

// Points in each unit's own frame (the scanner at the origin), metres.
Open3dRegistration registerWithOpen3d(const std::vector<Eigen::Vector3d>& reference,
                                      const std::vector<Eigen::Vector3d>& moving,
                                      const Open3dRegistrationParams& params = {});

}  // namespace sailshape::bench
