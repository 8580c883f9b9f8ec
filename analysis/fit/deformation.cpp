// The non-rigid part of the design fit: an as-rigid-as-possible membrane with a bending term,
// solved by alternating a local step (each vertex's rotation from its deformed 1-ring) and a
// global step (one sparse least squares for all vertices, the same matrix for x, y and z).
//
// Energy, every term an integral over the design's area (m⁴, so that only ratios matter):
//   data      Σ_s a_s |Σ_v b_sv x_v − q_s|²    a sample held to its foot's tangent plane
//                                              (q_s: the foot moved along the normal onto the
//                                              sample: point-to-plane, the foot free to stay)
//   membrane  L_m² Σ_e A_e/l_e² |x_i − x_j − R_e (x⁰_i − x⁰_j)|²    ≈ L_m² ∫ strain² dA
//   bending   L_b⁴ Σ_h A_h/d_h² |J_h(x) − R_h J_h(x⁰)|²             ≈ L_b⁴ ∫ (Δ curvature)² dA
// with R_e, R_h the mean rotation of the edge's two ends. J_h(x) is the jump of the surface's
// derivative across the interior edge h: ∂x/∂m₁ on one triangle plus ∂x/∂m₂ on the other, m₁
// and m₂ the unit directions across the edge into each triangle (on the design); on a flat
// unfolded hinge it is zero, on the design it is the design's own bend there (≈ κ·d_h). The
// rotated rest bend as target keeps the bending term free for rigid motion of any part, so the
// unsupported part of the sail continues the supported part's shape and tilt: it bends as the
// design does, turned with its neighbourhood. A_e, A_h: a third of the two triangles' area;
// d_h: the distance between their centroids across the edge.
#include <Eigen/SVD>
#include <iostream>  // Eigen/MetisSupport uses std::cerr without including it
#include <Eigen/MetisSupport>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <map>

#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/fit/fit_internal.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape::fit_detail {

Topology meshTopology(const Mesh& mesh) {
  const size_t n = mesh.vertices.size();
  Topology top;
  std::vector<std::array<uint64_t, 2>> keyed;  // (edge key, triangle)
  keyed.reserve(3 * mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint64_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      keyed.push_back({(a << 32) | b, t});
    }
  std::sort(keyed.begin(), keyed.end());
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i;
    std::array<int64_t, 2> tris{-1, -1};
    for (; j < keyed.size() && keyed[j][0] == keyed[i][0]; ++j)
      if (j - i < 2) tris[j - i] = static_cast<int64_t>(keyed[j][1]);
    top.edges.push_back({static_cast<uint32_t>(keyed[i][0] >> 32), static_cast<uint32_t>(keyed[i][0] & 0xffffffffu)});
    top.edge_triangles.push_back(tris);
    i = j;
  }
  auto compress = [n](const std::vector<std::array<uint32_t, 2>>& pairs, std::vector<uint32_t>& start,
                      std::vector<uint32_t>& items) {
    start.assign(n + 1, 0);
    for (const auto& p : pairs) ++start[p[0] + 1];
    for (size_t v = 0; v < n; ++v) start[v + 1] += start[v];
    items.resize(pairs.size());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& p : pairs) items[fill[p[0]]++] = p[1];
  };
  std::vector<std::array<uint32_t, 2>> ring, fan;
  for (const auto& e : top.edges) {
    ring.push_back({e[0], e[1]});
    ring.push_back({e[1], e[0]});
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t]) fan.push_back({v, static_cast<uint32_t>(t)});
  compress(ring, top.ring_start, top.ring);
  compress(fan, top.fan_start, top.fan);
  return top;
}

std::vector<double> vertexAreas(const Mesh& mesh) {
  std::vector<double> area(mesh.vertices.size(), 0.0);
  for (const auto& t : mesh.triangles) {
    const double a =
        0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]).norm();
    for (uint32_t v : t) area[v] += a / 3.0;
  }
  return area;
}

namespace {

// Barycentric weights of p (on or near triangle a, b, c), by areas of the sub-triangles.
Eigen::Vector3d barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return {1.0, 0.0, 0.0};
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

}  // namespace

std::vector<Foot> findFeet(const Mesh& mesh, const std::vector<Vec3>& x, const Topology& top,
                           const std::vector<Vec3>& samples) {
  const KdTree tree(x);
  std::vector<Foot> feet(samples.size());
#pragma omp parallel
  {
    std::vector<uint32_t> idx;
    std::vector<double> d2;
#pragma omp for schedule(dynamic, 1024)
    for (size_t s = 0; s < samples.size(); ++s) {
      const Vec3& p = samples[s];
      tree.nearest(p, 2, idx, d2);
      Foot best;
      double best_d2 = std::numeric_limits<double>::infinity();
      for (uint32_t v : idx)
        for (uint32_t k = top.fan_start[v]; k < top.fan_start[v + 1]; ++k) {
          const auto& t = mesh.triangles[top.fan[k]];
          const Vec3 q = closestPointOnTriangle(p, x[t[0]], x[t[1]], x[t[2]]);
          const double dd = (q - p).squaredNorm();
          if (dd < best_d2) {
            best_d2 = dd;
            best.triangle = top.fan[k];
            best.point = q;
          }
        }
      if (best.triangle >= 0) {
        const auto& t = mesh.triangles[static_cast<size_t>(best.triangle)];
        best.bary = barycentric(best.point, x[t[0]], x[t[1]], x[t[2]]).cwiseMax(0.0);
        best.bary /= std::max(1e-12, best.bary.sum());
        best.normal = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).normalized();
        best.distance_m = std::sqrt(best_d2);
      }
      feet[s] = best;
    }
  }
  return feet;
}

struct Regulariser {
  Eigen::SparseMatrix<double> matrix;  // N×N, the same for x, y and z
  // Rows of the membrane: edge e with its weight; of the bending: hinge h with its
  // vertices, coefficients (J_h(x) = Σ c_k x_{v_k}), weight and rest bend J_h(x⁰).
  std::vector<double> edge_weight;
  struct Hinge {
    std::array<uint32_t, 4> v{};
    std::array<double, 4> c{};
    double weight = 0;
    Vec3 rest = Vec3::Zero();
    uint32_t edge = 0;
  };
  std::vector<Hinge> hinges;
};

void RegulariserDeleter::operator()(Regulariser* r) const { delete r; }

namespace {

// Gradient of each barycentric coordinate of triangle (a, b, c), in its plane: n × (opposite edge) / 2A.
std::array<Vec3, 3> barycentricGradients(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 cr = (b - a).cross(c - a);
  const double twice_area = cr.norm();
  const Vec3 n = cr / twice_area;
  return {n.cross(c - b) / twice_area, n.cross(a - c) / twice_area, n.cross(b - a) / twice_area};
}

// The hinge across interior edge e, or weight 0 when a triangle is degenerate.
Regulariser::Hinge makeHinge(const Mesh& m, const Topology& top, size_t e, double bending4) {
  Regulariser::Hinge h;
  h.edge = static_cast<uint32_t>(e);
  const uint32_t i = top.edges[e][0], j = top.edges[e][1];
  const auto& x = m.vertices;
  std::map<uint32_t, double> coef;
  double area = 0, across = 0;
  const Vec3 along = (x[j] - x[i]).normalized();
  for (int side = 0; side < 2; ++side) {
    const auto& t = m.triangles[static_cast<size_t>(top.edge_triangles[e][side])];
    const double a2 = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm();
    if (!(a2 > 1e-14)) return h;
    uint32_t opposite = t[0];
    for (uint32_t v : t)
      if (v != i && v != j) opposite = v;
    Vec3 mdir = (x[opposite] - x[i]) - (x[opposite] - x[i]).dot(along) * along;
    const double height = mdir.norm();
    mdir /= height;
    const auto g = barycentricGradients(x[t[0]], x[t[1]], x[t[2]]);
    for (int k = 0; k < 3; ++k) coef[t[k]] += g[k].dot(mdir);
    area += a2 / 6.0;
    across += height / 3.0;
  }
  int k = 0;
  for (const auto& [v, c] : coef) {
    h.v[k] = v;
    h.c[k] = c;
    h.rest += c * x[v];
    ++k;
  }
  h.weight = bending4 * area / (across * across);
  return h;
}

}  // namespace

RegulariserPtr buildRegulariser(const Mesh& design, const Topology& top, double membrane_length_m,
                                double bending_length_m) {
  RegulariserPtr reg(new Regulariser);
  const size_t n = design.vertices.size();
  std::vector<double> tri_area(design.triangles.size());
  for (size_t t = 0; t < design.triangles.size(); ++t) {
    const auto& tr = design.triangles[t];
    tri_area[t] = 0.5 * (design.vertices[tr[1]] - design.vertices[tr[0]])
                            .cross(design.vertices[tr[2]] - design.vertices[tr[0]])
                            .norm();
  }
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * top.edges.size() + 16 * top.edges.size());
  const double membrane2 = membrane_length_m * membrane_length_m;
  const double bending4 = std::pow(bending_length_m, 4);
  reg->edge_weight.resize(top.edges.size());
  for (size_t e = 0; e < top.edges.size(); ++e) {
    const uint32_t i = top.edges[e][0], j = top.edges[e][1];
    double area = 0;
    for (int64_t t : top.edge_triangles[e])
      if (t >= 0) area += tri_area[static_cast<size_t>(t)] / 3.0;
    const double l2 = (design.vertices[i] - design.vertices[j]).squaredNorm();
    const double w = l2 > 0 ? membrane2 * area / l2 : 0.0;
    reg->edge_weight[e] = w;
    trip.emplace_back(i, i, w);
    trip.emplace_back(j, j, w);
    trip.emplace_back(i, j, -w);
    trip.emplace_back(j, i, -w);
    if (top.edge_triangles[e][1] < 0) continue;
    Regulariser::Hinge h = makeHinge(design, top, e, bending4);
    if (!(h.weight > 0)) continue;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) trip.emplace_back(h.v[a], h.v[b], h.weight * h.c[a] * h.c[b]);
    reg->hinges.push_back(h);
  }
  reg->matrix.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  reg->matrix.setFromTriplets(trip.begin(), trip.end());
  return reg;
}

namespace {

// Local step: the rotation carrying each vertex's design 1-ring (and normal) onto its current one.
std::vector<Eigen::Matrix3d> vertexRotations(const Mesh& design, const Topology& top, const std::vector<Vec3>& x) {
  const size_t n = design.vertices.size();
  Mesh current{x, design.triangles};
  const std::vector<Vec3> n0 = vertexNormals(design), n1 = vertexNormals(current);
  std::vector<Eigen::Matrix3d> rot(n, Eigen::Matrix3d::Identity());
#pragma omp parallel for schedule(static)
  for (size_t v = 0; v < n; ++v) {
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    double scale = 0;
    for (uint32_t k = top.ring_start[v]; k < top.ring_start[v + 1]; ++k) {
      const uint32_t u = top.ring[k];
      const Vec3 d0 = design.vertices[u] - design.vertices[v];
      cov += d0 * (x[u] - x[v]).transpose();
      scale += d0.squaredNorm();
    }
    // The normal pair fixes the rotation about the ring's own plane where the ring is flat.
    const size_t ring = top.ring_start[v + 1] - top.ring_start[v];
    if (ring > 0) cov += (scale / static_cast<double>(ring)) * n0[v] * n1[v].transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d r = svd.matrixV() * svd.matrixU().transpose();
    if (r.determinant() < 0) {
      Eigen::Matrix3d v3 = svd.matrixV();
      v3.col(2) *= -1;
      r = v3 * svd.matrixU().transpose();
    }
    rot[v] = r;
  }
  return rot;
}

}  // namespace

// Ordered by METIS's nested dissection: the membrane and bending terms couple each vertex
// with its 2-ring on a mesh a few hundred vertices across, where dissection leaves the
// factor a good deal less fill than the default minimum-degree ordering, and the eight
// factorisations of a fit are its largest cost (bench/README.md).
struct StepSolver {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::MetisOrdering<int>> ldlt;
  bool analysed = false;
};
void StepSolverDeleter::operator()(StepSolver* s) const { delete s; }
StepSolverPtr makeStepSolver() { return StepSolverPtr(new StepSolver); }

std::vector<Vec3> deformStep(const Regulariser& reg, const Mesh& design, const Topology& top,
                             const std::vector<Vec3>& current, const std::vector<Vec3>& samples,
                             const std::vector<Foot>& feet, const std::vector<char>& use, double sample_area_m2,
                             double stiffness, StepSolver& step_solver) {
  const size_t n = design.vertices.size();
  const std::vector<Eigen::Matrix3d> rot = vertexRotations(design, top, current);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), 3);
  for (size_t e = 0; e < top.edges.size(); ++e) {
    const uint32_t i = top.edges[e][0], j = top.edges[e][1];
    const Vec3 target = 0.5 * (rot[i] + rot[j]) * (design.vertices[i] - design.vertices[j]);
    const double w = stiffness * reg.edge_weight[e];
    rhs.row(i) += w * target.transpose();
    rhs.row(j) -= w * target.transpose();
  }
  for (const Regulariser::Hinge& h : reg.hinges) {
    const auto& ed = top.edges[h.edge];
    const Vec3 target = 0.5 * (rot[ed[0]] + rot[ed[1]]) * h.rest;
    for (int k = 0; k < 4; ++k) rhs.row(h.v[k]) += stiffness * h.weight * h.c[k] * target.transpose();
  }
  // Data: each sample's 3×3 block on its triangle, summed per triangle first.
  std::vector<Eigen::Matrix3d> block(design.triangles.size(), Eigen::Matrix3d::Zero());
  std::vector<char> touched(design.triangles.size(), 0);
  for (size_t s = 0; s < samples.size(); ++s) {
    if (!use[s]) continue;
    const Foot& f = feet[s];
    const auto t = static_cast<size_t>(f.triangle);
    const Vec3 q = f.point + f.normal * f.normal.dot(samples[s] - f.point);
    block[t] += sample_area_m2 * f.bary * f.bary.transpose();
    touched[t] = 1;
    for (int k = 0; k < 3; ++k) rhs.row(design.triangles[t][k]) += sample_area_m2 * f.bary[k] * q.transpose();
  }
  std::vector<Eigen::Triplet<double>> trip;
  const std::vector<double> area = vertexAreas(design);
  // A faint pull towards where each vertex stands (10⁻⁶ of its area): the system stays
  // definite where no sample reaches, and moves nothing measurably.
  for (size_t v = 0; v < n; ++v) {
    const double w = 1e-6 * area[v];
    trip.emplace_back(v, v, w);
    rhs.row(v) += w * current[v].transpose();
  }
  for (size_t t = 0; t < design.triangles.size(); ++t) {
    if (!touched[t]) continue;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) trip.emplace_back(design.triangles[t][a], design.triangles[t][b], block[t](a, b));
  }
  Eigen::SparseMatrix<double> m(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  m.setFromTriplets(trip.begin(), trip.end());
  m += stiffness * reg.matrix;
  auto& solver = step_solver.ldlt;
  if (!step_solver.analysed) {
    solver.analyzePattern(m);
    step_solver.analysed = true;
  }
  solver.factorize(m);
  if (solver.info() != Eigen::Success) throw AnalysisError("[fitDesign] the deformation's system is singular");
  const Eigen::MatrixXd sol = solver.solve(rhs);
  std::vector<Vec3> x(n);
  for (size_t v = 0; v < n; ++v) x[v] = sol.row(static_cast<Eigen::Index>(v)).transpose();
  return x;
}

}  // namespace sailshape::fit_detail
