#pragma once
// Registration of one unit's cloud into another's frame (SPEC §4 step 2, the
// study's §5.3): picked point pairs (Kabsch/SVD), plain ICP, or the study's
// plane-based method — three planes found in both clouds fix the rotation (first
// normal pair, then about it for the second) and the translation (difference of
// the three-plane intersection points, or one picked pair); the crossed filter
// keeps the overlap and ICP refines it.
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/registration/icp.hpp"
#include "analysis/registration/pose_verification.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "analysis/segmentation/plane_detection.hpp"

namespace sailshape {

struct PlaneMatchParams {
  double max_angle_mismatch_deg = 3.0;  // angles between plane normals must agree this well in both clouds
  double min_plane_angle_deg = 30.0;    // planes used together are at least this far from parallel
  double min_triple_det = 0.25;         // |det| of the three unit normals whose intersection gives the translation
  double verify_radius_m = 0.05;        // a moving plane's sample lands when a reference plane point lies this close
};

struct RegistrationParams {
  std::string method = "planes";  // planes | svd | icp
  PlaneDetectionParams planes;
  PlaneMatchParams match;
  // svd: at least 3 picked pairs. planes: 1 pair gives the translation instead of
  // the three-plane intersection (then two planes suffice), the study's option 1.
  std::vector<PointPair> pairs;
  // planes: user hints, one point on each plane to use (first plane first), in
  // both clouds; 3 hints, or 2 with a picked pair. Empty: automatic matching.
  std::vector<PointPair> plane_hints;
  // icp: plain ICP from this guess (the raw pose: identity) with wide correspondences.
  RigidTransform initial = RigidTransform::Identity();
  double icp_initial_correspondence_m = 1.0;
  double crossed_radius_m = 0.05;  // the crossed filter's radius
  bool refine = true;              // ICP after the coarse alignment
  IcpParams icp;
  size_t max_icp_points = 60'000;  // of each cloud's overlap, evenly spread, for speed
  // planes + point-to-plane refinement: points of each matched moving plane
  // (evenly spread) held to its reference plane alongside the overlap pairs.
  size_t max_anchor_points = 5'000;
  // planes: every pose the matched planes allow is screened by the verifier on
  // this many samples of each cloud; the best and those the screen cannot reject
  // against it (at most `refined_hypotheses`) are refined by ICP and scored on
  // all its samples, and the best must beat the runner-up by the verifier's
  // margin (else ambiguous).
  PoseVerificationParams verify;
  size_t screen_samples = 1500;
  size_t refined_hypotheses = 8;
  // The likeliest pose turned by the room's symmetries (90°, 180°, 270° about
  // each plane axis, the line placed where the data fit best) competes too.
  bool symmetric_alternatives = true;
  // Sensor uncertainty the fitness must stay under: σ + systematic error at model
  // scale (SPEC §4 step 4: 9 mm; 14 mm at full scale).
  double uncertainty_m = 0.009;
  size_t min_overlap_points = 200;
  // Of the overlapping points, at least this fraction must lie within
  // uncertainty_m of the reference surface: two clouds that merely cross (a
  // wrong alignment) have many points near the crossing but far off the surface.
  double min_inlier_fraction = 0.8;
};

struct PlanePairing {
  size_t reference_plane = 0, moving_plane = 0;  // indices into the detections
  Vec3 reference_normal = Vec3::Zero(), moving_normal = Vec3::Zero();
  size_t reference_points = 0, moving_points = 0;
  double angle_after_deg = 0;  // between the reference normal and the rotated moving normal
};

struct Registration {
  std::string method;
  RigidTransform transform = RigidTransform::Identity();  // moving → reference
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 translation = Vec3::Zero();                        // m
  RigidTransform coarse = RigidTransform::Identity();     // before refinement

  // Plane method.
  size_t reference_planes = 0, moving_planes = 0;
  std::vector<PlanePairing> pairings;  // every moving plane the chosen pose lands on a reference plane
  size_t candidates = 0;               // plane matches found
  size_t poses_verified = 0;           // distinct refined poses the verifier compared
  double coarse_overlap_fraction = 0;  // of the best pose's verification samples on the other cloud's surface
  double free_space_fraction = 0;      // of them in the other unit's free space
  size_t coarse_planes_on = 0;         // moving planes that land on a reference plane of the same orientation
  // The best pose's log-likelihood over the runner-up's (0 with one pose) and the
  // margin the verifier asks for; ambiguous when it falls short.
  double log_likelihood_ratio = 0, log_likelihood_ratio_needed = 0;
  bool ambiguous = false;

  // Overlap after the coarse alignment (crossed filter), and the distances from
  // those moving points to the reference before and after refinement.
  size_t overlap_reference_points = 0, overlap_moving_points = 0;
  NeighbourDistanceStats before_refinement, after_refinement;

  int icp_iterations = 0;
  bool converged = false;  // ICP converged (true when refinement is off)
  // RMS distance of the moving points overlapping the reference after the final
  // alignment (crossed filter) to the reference surface (the tangent plane at
  // the nearest reference point), m. Point-to-point distances
  // also hold the spacing of two scanners that never hit the same spot
  // (before/after_refinement show them).
  double fitness_rms_m = 0;
  double inlier_fraction = 0;      // of those distances within uncertainty_m
  bool below_uncertainty = false;  // fitness_rms_m ≤ uncertainty_m
  bool accepted = false;           // below the uncertainty, inlier_fraction ≥ min, converged, not ambiguous
  std::vector<std::string> warnings;
};

// Throws InvalidInput for bad parameters (unknown method, too few pairs or hints)
// and AnalysisError when the data cannot give a transform: fewer than three
// usable planes, only parallel (or coplanar-normal) planes, no matching plane
// triple, or no overlap after alignment. A transform that is only poor comes
// back with accepted = false and warnings.
Registration registerClouds(const Cloud& reference, const Cloud& moving, const RegistrationParams& params = {},
                            const Progress& progress = {});

// Rotation (first normal pair, then about it for the second; study eq. 5.11)
// and translation (intersection points) from three plane pairs. Throws
// AnalysisError when the planes' normals are coplanar.
RigidTransform transformFromPlanes(const DetectedPlane (&reference)[3], const DetectedPlane (&moving)[3]);

// How far a fresh registration lies from a stored one.
struct Drift {
  double rotation_deg = 0;        // angle of the rotation between the two
  double translation_m = 0;       // |t_fresh − t_stored|
  double max_displacement_m = 0;  // bound on how far a point within radius_m of the origin moved
  bool moved = false;             // max_displacement_m above the tolerance
};
Drift compareTransforms(const RigidTransform& stored, const RigidTransform& fresh, double radius_m = 5.0,
                        double max_displacement_m = 0.009);

}  // namespace sailshape
