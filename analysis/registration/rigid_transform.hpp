#pragma once
// Rigid transforms between frames (SPEC §4 step 2): the Kabsch/SVD fit from
// point pairs, the rotation taking one direction onto another (study eq. 5.11),
// and the 4×4 text file a registration is stored in and reapplied from.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

// Maps coordinates of the moving frame into the reference frame: x_ref = R·x_mov + t.
using RigidTransform = Eigen::Isometry3d;

// One picked correspondence: the same physical point in both clouds, metres.
struct PointPair {
  Vec3 moving = Vec3::Zero();
  Vec3 reference = Vec3::Zero();
};

struct KabschFit {
  RigidTransform transform = RigidTransform::Identity();
  double rms_m = 0;                 // RMS of |R·moving + t − reference| over the pairs
  double max_residual_m = 0;
  bool reflection_corrected = false;  // the SVD's best orthogonal matrix was a reflection (det −1) and was flipped
};

// Least-squares rotation and translation taking pairs[i].moving onto
// pairs[i].reference (Kabsch/SVD, with the reflection guard). Throws InvalidInput
// for fewer than 3 pairs, non-finite coordinates, or moving/reference points that
// are (nearly) collinear, which leaves a rotation free.
KabschFit fitKabsch(const std::vector<PointPair>& pairs);

// The shortest rotation taking unit direction `from` onto `to` (Rodrigues form,
// the study's eq. 5.11); antiparallel directions turn 180° about an axis normal
// to `from`. Throws InvalidInput for a zero or non-finite vector.
Eigen::Matrix3d rotationAligning(const Vec3& from, const Vec3& to);

// Rotation from two pairs of unit normals as the study builds it (§5.3): align
// mov1 onto ref1, then turn about ref1 until mov2 lies in the plane of ref1 and ref2.
Eigen::Matrix3d rotationFromNormalPairs(const Vec3& ref1, const Vec3& ref2, const Vec3& mov1, const Vec3& mov2);

// Angle of the rotation R_a⁻¹·R_b, degrees: how far two rotations differ.
double rotationDifferenceDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// The cloud with points and viewpoint mapped by `t` (other attributes kept).
Cloud transformCloud(const Cloud& cloud, const RigidTransform& t);

// The cloud with a range scale taken out (SPEC §3's systematic range error:
// measured range = scale × true range): every point pulled towards the cloud's
// viewpoint (the origin without one) by 1 / scale. Throws InvalidInput for a
// scale ≤ 0 or not finite.
Cloud removeRangeScale(const Cloud& cloud, double scale);

// Four lines of four numbers, row-major, the last line 0 0 0 1; full double
// precision. Throws FileError naming the file when it cannot be written.
void writeTransform(const std::string& path, const RigidTransform& t);
std::string formatTransform(const RigidTransform& t);

// Reads what writeTransform writes ('#' starts a comment; blank lines ignored).
// Throws FileError naming the file and line on a missing file, a line without
// exactly four numbers, other than four rows, a last row other than 0 0 0 1, or
// an upper-left 3×3 that is not a rotation (orthonormal within 1e-6, det +1).
RigidTransform readTransform(const std::string& path);

// Point pairs as text: one pair a line, "xm ym zm xr yr zr" (moving point, then
// the same point in the reference cloud, metres); '#' comments and blank lines
// ignored. Throws FileError naming the file and line on a missing file or a line
// without exactly six finite numbers, or a file without any pair.
std::vector<PointPair> readPointPairs(const std::string& path);

}  // namespace sailshape
