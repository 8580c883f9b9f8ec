#include "analysis/sail_outline.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "analysis/errors.hpp"
#include "analysis/neighbours.hpp"

#include <Eigen/Eigenvalues>

namespace sailshape {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string fmt(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// The longest closed loop of boundary edges (edges used by exactly one triangle).
std::vector<uint32_t> outerBoundaryLoop(const Mesh& mesh) {
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(mesh.triangles.size() * 3);
  auto key = [](uint64_t a, uint64_t b) { return (a << 32) | b; };
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++directed[key(t[e], t[(e + 1) % 3])];
  std::unordered_multimap<uint32_t, uint32_t> next;
  for (const auto& [k, count] : directed) {
    const uint32_t a = static_cast<uint32_t>(k >> 32), b = static_cast<uint32_t>(k & 0xffffffffu);
    if (count == 1 && !directed.count(key(b, a))) next.emplace(a, b);
  }
  if (next.empty()) throw AnalysisError("[extractOutline] the mesh has no boundary edge (closed surface?)");
  std::unordered_set<uint64_t> used;
  std::vector<uint32_t> best;
  double best_len = -1;
  for (const auto& [start, first] : next) {
    if (used.count(key(start, first))) continue;
    std::vector<uint32_t> loop{start};
    uint32_t cur = start, nxt = first;
    bool closed = false;
    while (true) {
      used.insert(key(cur, nxt));
      if (nxt == start) {
        closed = true;
        break;
      }
      loop.push_back(nxt);
      cur = nxt;
      auto range = next.equal_range(cur);
      bool found = false;
      for (auto it = range.first; it != range.second; ++it)
        if (!used.count(key(cur, it->second))) {
          nxt = it->second;
          found = true;
          break;
        }
      if (!found || loop.size() > next.size()) break;
    }
    if (!closed || loop.size() < 3) continue;
    double len = 0;
    for (size_t i = 0; i < loop.size(); ++i)
      len += (mesh.vertices[loop[i]] - mesh.vertices[loop[(i + 1) % loop.size()]]).norm();
    if (len > best_len) {
      best_len = len;
      best = loop;
    }
  }
  if (best.empty()) throw AnalysisError("[extractOutline] the mesh boundary does not form a closed loop");
  return best;
}

// Point on a closed loop at arc position s (wrapped), given cumulative arc lengths.
Vec3 loopPointAt(const std::vector<Vec3>& pts, const std::vector<double>& cum, double total, double s) {
  s = std::fmod(s, total);
  if (s < 0) s += total;
  const size_t i = static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin()) - 1;
  const size_t j = (i + 1) % pts.size();
  const double seg = (i + 1 < cum.size() ? cum[i + 1] : total) - cum[i];
  const double t = seg > 0 ? (s - cum[i]) / seg : 0.0;
  return pts[i] + t * (pts[j] - pts[i]);
}

// Uniformly resampled and moving-average smoothed polyline; ends stay fixed.
std::vector<Vec3> smoothPolyline(const std::vector<Vec3>& line, double step, double window) {
  const double len = polylineLength(line);
  if (line.size() < 2 || len <= 0) return line;
  const size_t n = std::max<size_t>(2, static_cast<size_t>(std::ceil(len / std::max(step, 1e-6))) + 1);
  std::vector<Vec3> uniform(n);
  for (size_t i = 0; i < n; ++i) uniform[i] = pointAtFraction(line, static_cast<double>(i) / (n - 1));
  const size_t half = static_cast<size_t>(std::round(0.5 * window / (len / (n - 1))));
  std::vector<Vec3> out(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t h = std::min({half, i, n - 1 - i});  // symmetric window keeps the ends in place
    Vec3 sum = Vec3::Zero();
    for (size_t j = i - h; j <= i + h; ++j) sum += uniform[j];
    out[i] = sum / static_cast<double>(2 * h + 1);
  }
  return out;
}

// Area-weighted vertex normals.
std::vector<Vec3> vertexNormals(const Mesh& mesh) {
  std::vector<Vec3> n(mesh.vertices.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3 fn = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (uint32_t v : t) n[v] += fn;
  }
  for (Vec3& v : n)
    if (v.norm() > 0) v.normalize();
  return n;
}

// A sampled surface's boundary lies inside the true edge: the outermost samples
// sit some distance in. Sample offsets from the true edge are uniform on
// [0, ∞), so within the strip s ≤ D of the found edge (offset s from it,
// positive inwards) they are uniform on [−δ, D] and δ = D − 2·mean(s).
// Returns the edge moved out by δ, and δ.
std::pair<std::vector<Vec3>, double> pushEdgeOut(const std::vector<Vec3>& edge, const Mesh& mesh,
                                                 const std::vector<Vec3>& normals, const KdTree& vertex_tree,
                                                 double spacing) {
  const double strip = 4.0 * spacing;
  const size_t n = edge.size();
  if (n < 5) return {edge, 0.0};
  std::vector<Vec3> inward(n);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 t = (edge[std::min(i + 1, n - 1)] - edge[i > 0 ? i - 1 : 0]).normalized();
    vertex_tree.nearest(edge[i], 8, idx, d2);
    Vec3 normal = Vec3::Zero();
    Vec3 centre = Vec3::Zero();
    for (uint32_t v : idx) {
      normal += normals[v];
      centre += mesh.vertices[v];
    }
    centre /= static_cast<double>(idx.size());
    Vec3 in = normal.normalized().cross(t);
    if (in.dot(centre - edge[i]) < 0) in = -in;  // the vertex cloud lies inwards
    inward[i] = in;
  }
  // Offsets of the vertices near the middle 90 % of the edge (corners excluded).
  double sum = 0;
  size_t count = 0;
  const size_t lo = n / 20, hi = n - 1 - n / 20;
  for (size_t i = lo; i <= hi; ++i) {
    vertex_tree.withinRadius(edge[i], strip, idx, d2);
    for (uint32_t v : idx) {
      const Vec3 d = mesh.vertices[v] - edge[i];
      const Vec3 t = (edge[std::min(i + 1, n - 1)] - edge[i > 0 ? i - 1 : 0]).normalized();
      const double along = d.dot(t);
      if (std::abs(along) > 0.5 * (edge[std::min(i + 1, n - 1)] - edge[i]).norm()) continue;  // nearest sample only
      const double s = d.dot(inward[i]);
      if (s > strip) continue;
      sum += s;
      ++count;
    }
  }
  if (count < 30) return {edge, 0.0};
  const double delta = std::clamp(strip - 2.0 * sum / static_cast<double>(count), 0.0, strip);
  std::vector<Vec3> moved(n);
  for (size_t i = 0; i < n; ++i) moved[i] = edge[i] - delta * inward[i];
  return {moved, delta};
}

// Closest point between the lines fitted to two edges near their common corner
// (edges start at the corner), fitted over arc range [near, far].
Vec3 extrapolateCorner(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double near, double far) {
  auto fit = [&](const std::vector<Vec3>& e, Vec3& point, Vec3& dir) {
    std::vector<Vec3> pts;
    double s = 0;
    for (size_t i = 1; i < e.size(); ++i) {
      s += (e[i] - e[i - 1]).norm();
      if (s >= near && s <= far) pts.push_back(e[i]);
    }
    if (pts.size() < 3) return false;
    point = Vec3::Zero();
    for (const Vec3& p : pts) point += p;
    point /= static_cast<double>(pts.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const Vec3& p : pts) cov += (p - point) * (p - point).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    dir = eig.eigenvectors().col(2);
    return true;
  };
  Vec3 pa, da, pb, db;
  if (!fit(a, pa, da) || !fit(b, pb, db)) return a.front();
  const Vec3 w = pa - pb;
  const double A = da.dot(da), B = da.dot(db), C = db.dot(db), D = da.dot(w), E = db.dot(w);
  const double den = A * C - B * B;
  if (den < 1e-6) return a.front();  // edges nearly parallel: no defined corner
  const double sa = (B * E - C * D) / den, sb = (A * E - B * D) / den;
  return 0.5 * ((pa + sa * da) + (pb + sb * db));
}

}  // namespace

double polylineLength(const std::vector<Vec3>& line) {
  double len = 0;
  for (size_t i = 1; i < line.size(); ++i) len += (line[i] - line[i - 1]).norm();
  return len;
}

Vec3 pointAtFraction(const std::vector<Vec3>& line, double fraction) {
  if (line.empty()) throw InvalidInput("[pointAtFraction] empty polyline");
  if (line.size() == 1) return line[0];
  const double target = std::clamp(fraction, 0.0, 1.0) * polylineLength(line);
  double acc = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const double seg = (line[i] - line[i - 1]).norm();
    if (acc + seg >= target && seg > 0) return line[i - 1] + (target - acc) / seg * (line[i] - line[i - 1]);
    acc += seg;
  }
  return line.back();
}

SailOutline extractOutline(const Mesh& mesh, const OutlineParams& p) {
  if (mesh.triangles.empty()) throw InvalidInput("[extractOutline] empty mesh");
  if (p.corners != 0 && p.corners != 3 && p.corners != 4)
    throw InvalidInput("[extractOutline] corners must be 0 (auto), 3 or 4 (got " + std::to_string(p.corners) + ")");
  if (!p.design_lengths_m.empty() && p.design_lengths_m.size() != 3)
    throw InvalidInput("[extractOutline] design_lengths_m must be [luff, leech, foot] (got " +
                       std::to_string(p.design_lengths_m.size()) + " values)");
  SailOutline out;
  const std::vector<uint32_t> loop_idx = outerBoundaryLoop(mesh);
  std::vector<Vec3>& pts = out.boundary;
  for (uint32_t v : loop_idx) pts.push_back(mesh.vertices[v]);
  const size_t n = pts.size();
  std::vector<double> cum(n, 0.0), seg(n);
  for (size_t i = 0; i < n; ++i) seg[i] = (pts[(i + 1) % n] - pts[i]).norm();
  for (size_t i = 1; i < n; ++i) cum[i] = cum[i - 1] + seg[i - 1];
  const double total = cum[n - 1] + seg[n - 1];
  {
    std::vector<double> s = seg;
    std::nth_element(s.begin(), s.begin() + n / 2, s.end());
    out.boundary_spacing_m = s[n / 2];
  }
  const double w = p.corner_window_m > 0 ? p.corner_window_m : 0.02 * total;

  // Turning angle over arms of length w; at a corner it approaches the exterior angle.
  std::vector<double> turn(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a = pts[i] - loopPointAt(pts, cum, total, cum[i] - w);
    const Vec3 b = loopPointAt(pts, cum, total, cum[i] + w) - pts[i];
    const double c = a.dot(b) / std::max(1e-12, a.norm() * b.norm());
    turn[i] = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
  }
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return turn[a] > turn[b]; });
  const double min_sep = std::max(3.0 * w, 0.05 * total);
  auto arcDist = [&](size_t a, size_t b) {
    const double d = std::abs(cum[a] - cum[b]);
    return std::min(d, total - d);
  };
  std::vector<size_t> picked;
  for (size_t i : order) {
    if (picked.size() == 4) break;
    bool far = true;
    for (size_t j : picked) far = far && arcDist(i, j) >= min_sep;
    if (far) picked.push_back(i);
  }
  if (picked.size() < 3)
    throw AnalysisError("[extractOutline] the boundary (" + fmt(total, 2) + " m) has fewer than 3 distinct corners");
  size_t count = p.corners;
  if (count == 0) count = (picked.size() == 4 && turn[picked[3]] >= p.min_fourth_corner_deg) ? 4 : 3;
  if (picked.size() < count)
    throw AnalysisError("[extractOutline] asked for " + std::to_string(count) + " corners, found " +
                        std::to_string(picked.size()));
  picked.resize(count);
  // Refine: the apex is the vertex farthest from the chord across the corner.
  for (size_t& c : picked) {
    const Vec3 a = loopPointAt(pts, cum, total, cum[c] - w), b = loopPointAt(pts, cum, total, cum[c] + w);
    const Vec3 ab = (b - a).normalized();
    double best = -1;
    size_t best_i = c;
    for (size_t i = 0; i < n; ++i) {
      if (arcDist(i, c) > w) continue;
      const Vec3 d = pts[i] - a;
      const double dist = (d - ab * d.dot(ab)).norm();
      if (dist > best) {
        best = dist;
        best_i = i;
      }
    }
    c = best_i;
  }

  // Name the corners in the boat frame: head (and peak) highest, tack forward of clew.
  std::vector<size_t> by_z = picked;
  std::sort(by_z.begin(), by_z.end(), [&](size_t a, size_t b) { return pts[a].z() > pts[b].z(); });
  size_t head, tack, clew, peak = 0;
  auto forwardFirst = [&](size_t a, size_t b) { return pts[a].x() >= pts[b].x() ? std::make_pair(a, b) : std::make_pair(b, a); };
  if (count == 4) {
    std::tie(head, peak) = forwardFirst(by_z[0], by_z[1]);
    std::tie(tack, clew) = forwardFirst(by_z[2], by_z[3]);
  } else {
    head = by_z[0];
    std::tie(tack, clew) = forwardFirst(by_z[1], by_z[2]);
  }
  out.tack = pts[tack];
  out.clew = pts[clew];
  out.head = pts[head];
  out.has_peak = count == 4;
  if (out.has_peak) out.peak = pts[peak];
  out.corner_turn_deg = {turn[tack], turn[clew], turn[head]};
  if (out.has_peak) out.corner_turn_deg.push_back(turn[peak]);

  // Walk the loop between two corners, the way that does not pass another corner.
  auto edge = [&](size_t from, size_t to) {
    for (int dir : {1, -1}) {
      std::vector<Vec3> line{pts[from]};
      bool blocked = false;
      for (size_t i = (from + n + dir) % n;; i = (i + n + dir) % n) {
        line.push_back(pts[i]);
        if (i == to) break;
        if (std::find(picked.begin(), picked.end(), i) != picked.end()) {
          blocked = true;
          break;
        }
      }
      if (!blocked) return line;
    }
    throw AnalysisError("[extractOutline] corners are not in sail order along the boundary");
  };
  const double step = out.boundary_spacing_m;
  const double window = p.edge_smoothing_m > 0 ? p.edge_smoothing_m : 0.006 * total;
  out.luff = smoothPolyline(edge(tack, head), step, window);
  out.foot = smoothPolyline(edge(tack, clew), step, window);
  out.leech = smoothPolyline(edge(clew, out.has_peak ? peak : head), step, window);
  if (out.has_peak) out.top = smoothPolyline(edge(head, peak), step, window);

  // Move each edge out to where the surface really ends, then place the corners
  // where neighbouring edges meet (a sharp corner itself is never sampled).
  const std::vector<Vec3> normals = vertexNormals(mesh);
  const KdTree tree(mesh.vertices);
  double area_outside = 0;
  for (std::vector<Vec3>* e : {&out.luff, &out.foot, &out.leech, &out.top}) {
    if (e->empty()) continue;
    auto [moved, delta] = pushEdgeOut(*e, mesh, normals, tree, out.boundary_spacing_m);
    area_outside += delta * polylineLength(*e);
    *e = smoothPolyline(moved, step, window);  // per-sample inward directions are noisy
  }
  auto reversed = [](std::vector<Vec3> v) {
    std::reverse(v.begin(), v.end());
    return v;
  };
  const double near = 0.5 * w, far = 2.5 * w;
  out.tack = extrapolateCorner(out.luff, out.foot, near, far);
  out.clew = extrapolateCorner(out.leech, reversed(out.foot), near, far);
  if (out.has_peak) {
    out.head = extrapolateCorner(reversed(out.luff), out.top, near, far);
    out.peak = extrapolateCorner(reversed(out.leech), reversed(out.top), near, far);
    out.top.front() = out.head;
    out.top.back() = out.peak;
    out.leech.back() = out.peak;
  } else {
    out.head = extrapolateCorner(reversed(out.luff), reversed(out.leech), near, far);
    out.leech.back() = out.head;
  }
  out.luff.front() = out.tack;
  out.luff.back() = out.head;
  out.foot.front() = out.tack;
  out.foot.back() = out.clew;
  out.leech.front() = out.clew;
  out.luff_length_m = polylineLength(out.luff);
  out.leech_length_m = polylineLength(out.leech);
  out.foot_length_m = polylineLength(out.foot);
  out.top_length_m = polylineLength(out.top);
  out.area_m2 = meshArea(mesh) + area_outside;

  if (!p.design_lengths_m.empty()) {
    const char* names[3] = {"luff", "leech", "foot"};
    const double measured[3] = {out.luff_length_m, out.leech_length_m, out.foot_length_m};
    for (int i = 0; i < 3; ++i) {
      const double design = p.design_lengths_m[static_cast<size_t>(i)];
      if (!(design > 0)) continue;
      const double off = std::abs(measured[i] - design) / design;
      if (off > p.design_tolerance)
        throw AnalysisError(std::string("[extractOutline] ") + names[i] + " length " + fmt(measured[i]) + " m is " +
                            fmt(100 * off, 1) + " % off the design " + fmt(design) + " m (limit " +
                            fmt(100 * p.design_tolerance, 0) + " %): corners or segmentation are wrong");
    }
  }
  return out;
}

}  // namespace sailshape
