#pragma once
// Registration into the boat frame (SPEC §2, §4 step 2) from a reference object
// whose faces are known in boat coordinates: the cube on the deck of the study's
// full-scale tests, or the chamber walls of a wind tunnel. Planes found in the
// cloud are matched to the faces like the plane-based registration matches two
// clouds, then every matched plane's points are fitted onto their face.
//
// Reference file (JSON, metres, boat frame: +X forward, +Y port, +Z up):
//   {
//     "name": "cube on the foredeck",
//     "faces": [ {"name": "deck", "normal": [0, 0, 1], "point": [0, 0, 0]} ],
//     "cube":  {"name": "cube", "centre": [1.2, 0.0, 0.25], "size_m": 0.5, "yaw_deg": 0}
//   }
// Each face is a plane through "point" with unit "normal" pointing to where the
// scanners stand (out of the object, into the chamber). "cube" (optional) adds
// the four sides and the top of an axis-aligned cube resting on the deck,
// turned by yaw_deg about +Z. At least three faces are needed in all.
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "analysis/segmentation/plane_detection.hpp"

namespace sailshape {

struct ReferenceFace {
  std::string name;
  Vec3 normal = Vec3::UnitZ();  // unit, boat frame, towards the scanners
  double offset_m = 0;          // the face's plane is {x : normal·x = offset_m}
};

struct BoatReference {
  std::string name;
  std::vector<ReferenceFace> faces;
};

// The five visible faces (four sides, top) of a cube of edge size_m whose
// bottom centre is `centre` − (0, 0, size/2), turned by yaw_deg about +Z.
std::vector<ReferenceFace> cubeFaces(const std::string& name, const Vec3& centre, double size_m, double yaw_deg);

// Throws FileError naming the file and the field on a missing file, bad JSON,
// a face without name/normal/point, a zero normal, or fewer than three faces.
BoatReference readBoatReference(const std::string& path);
// Same from text already read; `source` names it in errors.
BoatReference parseBoatReference(const std::string& json_text, const std::string& source);

struct BoatRegistrationParams {
  PlaneDetectionParams planes;
  double max_angle_mismatch_deg = 3.0;
  double min_plane_angle_deg = 30.0;
  double min_triple_det = 0.25;
  double max_face_distance_m = 0.05;  // a plane lies on a face when its centroid is this close (and normals agree)
  // The unit's rough orientation (unit → boat), used only to choose between
  // matches a symmetric object cannot tell apart; matches farther than
  // prior_tolerance_deg from it do not count.
  Eigen::Matrix3d prior_rotation = Eigen::Matrix3d::Identity();
  double prior_tolerance_deg = 180.0;  // 180: no prior
  double uncertainty_m = 0.009;        // SPEC §4 step 4, model scale
  int refine_iterations = 10;
  // The unit's range scale k (measured range / true range, SPEC §3's systematic
  // error: up to ≈ 0.3 % of range) is fitted with the pose: faces of known
  // separation seen from one unit (a tunnel's floor and ceiling, its two side
  // walls) fix it, since a scaled scene stands k·D between them. This prior σ on
  // k − 1 holds it at 1 where the faces seen cannot (one face of each
  // direction: the scale trades against the translation); 0: no scale fitted.
  double range_scale_prior_sigma = 0.003;
};

struct FaceMatch {
  std::string face;
  size_t plane = 0;        // index into the cloud's detected planes
  size_t points = 0;
  double rms_m = 0;        // the plane's points to the face, after registration
  double angle_deg = 0;    // between the face normal and the registered plane normal
};

struct BoatRegistration {
  RigidTransform transform = RigidTransform::Identity();  // cloud (unit) → boat frame
  std::vector<FaceMatch> faces;  // every plane that lies on a face
  size_t planes = 0;             // detected in the cloud
  double fitness_rms_m = 0;      // matched planes' points to their faces, m
  // The unit's range scale fitted with the pose, and its σ (the prior's when the
  // faces do not fix it). The transform applies to the cloud with the scale
  // taken out: toBoatFrame.
  double range_scale = 1, range_scale_sigma = 0;
  bool below_uncertainty = false;
  bool ambiguous = false;        // another match explains as much (a symmetric object without a prior)
  bool accepted = false;         // below the uncertainty, three independent faces, not ambiguous
  std::vector<std::string> warnings;
};

// Throws InvalidInput for bad parameters or a reference without three faces
// whose normals are independent, and AnalysisError when the cloud has fewer
// than three usable planes or none of its plane triples matches the faces.
BoatRegistration registerToBoat(const Cloud& cloud, const BoatReference& reference,
                                const BoatRegistrationParams& params = {}, const Progress& progress = {});

// The unit's cloud in the boat frame: its range scale taken out, then the transform.
Cloud toBoatFrame(const Cloud& cloud, const RigidTransform& transform, double range_scale);

}  // namespace sailshape
