#include "bench/registration/open3d_registration.hpp"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>

#include <chrono>
#include <functional>
#include <memory>

namespace sailshape::bench {
namespace {

namespace o3g = open3d::geometry;
namespace o3r = open3d::pipelines::registration;

void estimateNormals(o3g::PointCloud& cloud, const Open3dRegistrationParams& p) {
  cloud.EstimateNormals(o3g::KDTreeSearchParamHybrid(p.normal_radius_voxels * p.voxel_m, p.normal_max_nn));
  if (p.orient_normals_to_scanner) cloud.OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
}

}  // namespace

Open3dRegistration registerWithOpen3d(const std::vector<Eigen::Vector3d>& reference,
                                      const std::vector<Eigen::Vector3d>& moving,
                                      const Open3dRegistrationParams& p) {
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  open3d::utility::random::Seed(p.seed);
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  Open3dRegistration out;
  auto t0 = Clock::now();
  // Open3D's names: source = moving, target = reference; its transformation maps source into target.
  o3g::PointCloud target(reference), source(moving);
  const std::shared_ptr<o3g::PointCloud> target_down = target.VoxelDownSample(p.voxel_m);
  const std::shared_ptr<o3g::PointCloud> source_down = source.VoxelDownSample(p.voxel_m);
  estimateNormals(*target_down, p);
  estimateNormals(*source_down, p);
  const o3g::KDTreeSearchParamHybrid fpfh_search(p.fpfh_radius_voxels * p.voxel_m, p.fpfh_max_nn);
  const std::shared_ptr<o3r::Feature> target_fpfh = o3r::ComputeFPFHFeature(*target_down, fpfh_search);
  const std::shared_ptr<o3r::Feature> source_fpfh = o3r::ComputeFPFHFeature(*source_down, fpfh_search);
  out.features_s = since(t0);

  t0 = Clock::now();
  const double ransac_distance = p.ransac_distance_voxels * p.voxel_m;
  const o3r::CorrespondenceCheckerBasedOnEdgeLength edge_check(p.edge_length_similarity);
  const o3r::CorrespondenceCheckerBasedOnDistance distance_check(ransac_distance);
  const std::vector<std::reference_wrapper<const o3r::CorrespondenceChecker>> checkers = {edge_check, distance_check};
  const o3r::RegistrationResult ransac = o3r::RegistrationRANSACBasedOnFeatureMatching(
      *source_down, *target_down, *source_fpfh, *target_fpfh, p.mutual_filter, ransac_distance,
      o3r::TransformationEstimationPointToPoint(false), 3, checkers,
      o3r::RANSACConvergenceCriteria(p.ransac_max_iterations, p.ransac_confidence));
  out.ransac_s = since(t0);

  // Refinement on the full clouds; point-to-plane needs the target's normals.
  t0 = Clock::now();
  estimateNormals(target, p);
  o3r::ICPConvergenceCriteria icp_criteria;
  icp_criteria.max_iteration_ = p.icp_max_iterations;
  const o3r::RegistrationResult icp =
      o3r::RegistrationICP(source, target, p.icp_distance_voxels * p.voxel_m, ransac.transformation_,
                           o3r::TransformationEstimationPointToPlane(), icp_criteria);
  out.icp_s = since(t0);

  out.rotation = icp.transformation_.topLeftCorner<3, 3>();
  out.translation = icp.transformation_.topRightCorner<3, 1>();
  out.reference_voxels = target_down->points_.size();
  out.moving_voxels = source_down->points_.size();
  out.ransac_fitness = ransac.fitness_;
  out.ransac_rmse_m = ransac.inlier_rmse_;
  out.ransac_inliers = ransac.correspondence_set_.size();
  out.icp_fitness = icp.fitness_;
  out.icp_rmse_m = icp.inlier_rmse_;
  return out;
}

}  // namespace sailshape::bench
