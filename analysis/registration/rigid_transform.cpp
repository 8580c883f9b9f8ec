#include "analysis/registration/rigid_transform.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/io/text_scan.hpp"

namespace sailshape {
namespace {

std::string vecText(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof(b), "(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z());
  return b;
}

// Numbers of each non-comment line, with their line numbers.
struct NumberLine {
  size_t line;
  std::vector<double> values;
};

std::vector<NumberLine> numberLines(const std::string& path) {
  const std::string text = detail::readWholeFile(path);
  detail::LineReader reader(text.data(), text.data() + text.size());
  std::vector<NumberLine> rows;
  std::vector<std::string_view> tokens;
  std::string_view line;
  while (reader.next(line)) {
    const size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    if (detail::trim(line).empty()) continue;
    detail::splitFields(line, tokens);
    NumberLine row{reader.line(), {}};
    for (std::string_view tok : tokens) {
      const double v = detail::numberOnLine(path, reader.line(), tok);
      if (!std::isfinite(v)) throw detail::atLine(path, reader.line(), "non-finite value " + detail::quoted(tok));
      row.values.push_back(v);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

KabschFit fitKabsch(const std::vector<PointPair>& pairs) {
  if (pairs.size() < 3)
    throw InvalidInput("[fitKabsch] needs at least 3 point pairs (got " + std::to_string(pairs.size()) + ")");
  Vec3 cm = Vec3::Zero(), cr = Vec3::Zero();
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pairs[i].moving.allFinite() || !pairs[i].reference.allFinite())
      throw InvalidInput("[fitKabsch] pair " + std::to_string(i) + " has a non-finite coordinate");
    cm += pairs[i].moving;
    cr += pairs[i].reference;
  }
  const double n = static_cast<double>(pairs.size());
  cm /= n;
  cr /= n;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero(), sm = Eigen::Matrix3d::Zero(), sr = Eigen::Matrix3d::Zero();
  for (const PointPair& p : pairs) {
    const Vec3 a = p.moving - cm, b = p.reference - cr;
    h += a * b.transpose();
    sm += a * a.transpose();
    sr += b * b.transpose();
  }
  // Collinear points leave the rotation about their line free: the second
  // largest spread must be a real fraction of the largest.
  for (const auto* s : {&sm, &sr}) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(*s);
    const Vec3 ev = es.eigenvalues();  // ascending
    if (!(ev(2) > 0) || ev(1) < 1e-8 * ev(2))
      throw InvalidInput(std::string("[fitKabsch] the ") + (s == &sm ? "moving" : "reference") +
                         " points are collinear or coincident (spread " + std::to_string(std::sqrt(std::max(ev(1), 0.0) / n)) +
                         " m across their line): a rotation about that line is undetermined");
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  KabschFit fit;
  if ((v * u.transpose()).determinant() < 0) {
    d(2, 2) = -1;  // flip the axis of least covariance: the nearest proper rotation
    fit.reflection_corrected = true;
  }
  const Eigen::Matrix3d r = v * d * u.transpose();
  fit.transform.linear() = r;
  fit.transform.translation() = cr - r * cm;
  double sum2 = 0;
  for (const PointPair& p : pairs) {
    const double e = (fit.transform * p.moving - p.reference).norm();
    sum2 += e * e;
    fit.max_residual_m = std::max(fit.max_residual_m, e);
  }
  fit.rms_m = std::sqrt(sum2 / n);
  return fit;
}

Eigen::Matrix3d rotationAligning(const Vec3& from, const Vec3& to) {
  if (!from.allFinite() || !to.allFinite() || from.norm() < 1e-12 || to.norm() < 1e-12)
    throw InvalidInput("[rotationAligning] directions must be finite and non-zero (got " + vecText(from) + " and " +
                       vecText(to) + ")");
  const Vec3 a = from.normalized(), b = to.normalized();
  const Vec3 v = a.cross(b);
  const double c = a.dot(b), s2 = v.squaredNorm();
  if (s2 < 1e-24) {
    if (c > 0) return Eigen::Matrix3d::Identity();
    // Antiparallel: half a turn about any axis normal to `a`.
    Vec3 axis = a.cross(Vec3::UnitX());
    if (axis.norm() < 0.1) axis = a.cross(Vec3::UnitY());
    return Eigen::AngleAxisd(M_PI, axis.normalized()).toRotationMatrix();
  }
  Eigen::Matrix3d vx;
  vx << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  // Study eq. 5.11: R = I + [v]x + [v]x² (1 − c) / |v|².
  return Eigen::Matrix3d::Identity() + vx + vx * vx * ((1 - c) / s2);
}

Eigen::Matrix3d rotationFromNormalPairs(const Vec3& ref1, const Vec3& ref2, const Vec3& mov1, const Vec3& mov2) {
  const Eigen::Matrix3d r1 = rotationAligning(mov1, ref1);
  const Vec3 v = r1 * mov2;
  const Vec3 a = v - v.dot(ref1) * ref1, b = ref2 - ref2.dot(ref1) * ref1;
  const double angle = std::atan2(a.cross(b).dot(ref1), a.dot(b));
  return Eigen::AngleAxisd(angle, ref1).toRotationMatrix() * r1;
}

double rotationDifferenceDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1) / 2, -1.0, 1.0);
  // acos loses precision near 0; the sine from the skew part keeps small angles exact.
  const Eigen::Matrix3d m = a.transpose() * b;
  const double s = 0.5 * Vec3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)).norm();
  return std::atan2(s, c) * kDegPerRad;
}

Cloud transformCloud(const Cloud& cloud, const RigidTransform& t) {
  Cloud out = cloud;
  for (Vec3& p : out.points) p = t * p;
  if (out.viewpoint) out.viewpoint = t * *out.viewpoint;
  return out;
}

Cloud removeRangeScale(const Cloud& cloud, double scale) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw InvalidInput("[removeRangeScale] scale must be finite and > 0 (got " + std::to_string(scale) + ")");
  Cloud out = cloud;
  const Vec3 o = cloud.viewpoint.value_or(Vec3::Zero());
  for (Vec3& q : out.points) q = o + (q - o) / scale;
  return out;
}

std::string formatTransform(const RigidTransform& t) {
  const Eigen::Matrix4d m = t.matrix();
  std::string out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (c) out += ' ';
      // Exact zero and one in the last row; full precision elsewhere.
      detail::appendNumber(out, r == 3 ? (c == 3 ? 1.0 : 0.0) : m(r, c));
    }
    out += '\n';
  }
  return out;
}

void writeTransform(const std::string& path, const RigidTransform& t) {
  if (!t.matrix().allFinite()) throw InvalidInput("[writeTransform] transform has a non-finite entry");
  detail::writeWholeFile(path, formatTransform(t));
}

RigidTransform readTransform(const std::string& path) {
  const std::vector<NumberLine> rows = numberLines(path);
  if (rows.size() != 4)
    throw detail::fileError(path, "a transform needs 4 rows of 4 numbers (found " + std::to_string(rows.size()) +
                                      " rows)");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    if (rows[r].values.size() != 4)
      throw detail::atLine(path, rows[r].line,
                           "expected 4 numbers, found " + std::to_string(rows[r].values.size()));
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r].values[c];
  }
  if (std::abs(m(3, 0)) > 1e-12 || std::abs(m(3, 1)) > 1e-12 || std::abs(m(3, 2)) > 1e-12 ||
      std::abs(m(3, 3) - 1) > 1e-12)
    throw detail::atLine(path, rows[3].line, "the last row must be 0 0 0 1");
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orth = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth > 1e-6 || r.determinant() < 0)
    throw detail::fileError(path, "the upper-left 3x3 is not a rotation (|RᵀR − I| = " + std::to_string(orth) +
                                      ", det = " + std::to_string(r.determinant()) + ")");
  // Re-orthonormalise so printed-and-read rotations stay exact rotations.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  RigidTransform t = RigidTransform::Identity();
  t.linear() = svd.matrixU() * svd.matrixV().transpose();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

std::vector<PointPair> readPointPairs(const std::string& path) {
  std::vector<PointPair> pairs;
  for (const NumberLine& row : numberLines(path)) {
    if (row.values.size() != 6)
      throw detail::atLine(path, row.line,
                           "expected 6 numbers (moving x y z, reference x y z), found " +
                               std::to_string(row.values.size()));
    const auto& v = row.values;
    pairs.push_back({Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])});
  }
  if (pairs.empty()) throw detail::fileError(path, "no point pairs (expected lines of 'xm ym zm xr yr zr')");
  return pairs;
}

}  // namespace sailshape
