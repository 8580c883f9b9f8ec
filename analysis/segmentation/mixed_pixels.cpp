#include "analysis/segmentation/mixed_pixels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

namespace {

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// A row of the grid (along a line, or across the lines at one α step): its samples
// as (place along the row, sample), by place, one sample a place.
using Row = std::vector<std::pair<int64_t, uint32_t>>;

// The scan's own grid: its lines (samples of one turn of the mirror, at one
// turntable angle β give or take the turntable's drift during the turn) and each
// sample's step along its line (α). Both are read off the angles alone, so the
// cloud may come in any order.
struct ScanGrid {
  std::vector<Row> lines;           // per line: its samples by α step
  std::vector<int64_t> line_step;   // per line: its place across the lines
  double d_alpha = 0, d_beta = 0;   // the angular steps, rad
};

// The samples of each scan line, lines by ascending β. Within a line β moves on by
// the drift of one α step at most; between lines by about the whole line step. Most
// gaps are of the first kind.
std::vector<std::vector<uint32_t>> lineMembers(const Cloud& c) {
  const size_t n = c.size();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return c.beta_rad[a] < c.beta_rad[b]; });
  std::vector<double> gaps;
  gaps.reserve(n);
  for (size_t i = 1; i < n; ++i) gaps.push_back(c.beta_rad[order[i]] - c.beta_rad[order[i - 1]]);
  const double split = std::max(20.0 * medianOf(gaps), 1e-9);
  std::vector<std::vector<uint32_t>> members(1);
  for (size_t i = 0; i < n; ++i) {
    if (i > 0 && gaps[i - 1] > split) members.emplace_back();
    members.back().push_back(order[i]);
  }
  return members;
}

// The median step between lines' mean β.
double medianLineStep(const std::vector<ScanLine>& lines) {
  std::vector<double> steps;
  for (size_t i = 1; i < lines.size(); ++i) steps.push_back(lines[i].beta_rad - lines[i - 1].beta_rad);
  return medianOf(steps);
}

ScanGrid scanGrid(const Cloud& c) {
  ScanGrid g;
  std::vector<ScanLine> lines = scanLines(c);
  std::vector<double> alpha_steps;
  for (ScanLine& line : lines) {
    std::vector<uint32_t>& m = line.samples;
    std::sort(m.begin(), m.end(), [&](uint32_t a, uint32_t b) { return c.alpha_rad[a] < c.alpha_rad[b]; });
    for (size_t i = 1; i < m.size(); ++i) {
      const double d = c.alpha_rad[m[i]] - c.alpha_rad[m[i - 1]];
      if (d > 1e-9) alpha_steps.push_back(d);
    }
  }
  g.d_alpha = medianOf(alpha_steps);
  g.d_beta = medianLineStep(lines);
  if (!(g.d_alpha > 0)) return g;
  double alpha_min = c.alpha_rad[0];
  for (double a : c.alpha_rad) alpha_min = std::min(alpha_min, a);
  for (const ScanLine& scan_line : lines) {
    Row line;
    for (uint32_t s : scan_line.samples) {
      const int64_t k = std::llround((c.alpha_rad[s] - alpha_min) / g.d_alpha);
      if (line.empty() || line.back().first != k) line.emplace_back(k, s);  // a second echo at one step stays off the grid
    }
    g.lines.push_back(std::move(line));
    g.line_step.push_back(g.d_beta > 0 ? std::llround((scan_line.beta_rad - lines.front().beta_rad) / g.d_beta) : 0);
  }
  return g;
}

// Marks in `mixed` the short runs of `row` between two edges stepping the same way;
// `delta` is the row's angular step.
void markRow(const Row& row, double delta, const std::vector<double>& range, const MixedPixelParams& p,
             std::vector<char>& mixed) {
  const size_t m = row.size();
  auto pos = [&](size_t i) { return row[i].first; };
  auto sample = [&](size_t i) { return row[i].second; };
  const double second = p.jump_sigmas * std::sqrt(6.0) * p.sensor_sigma_m;
  const double first = p.jump_sigmas * std::sqrt(2.0) * p.sensor_sigma_m;
  const double steepest = std::tan(p.max_incidence_deg * kRadPerDeg);
  std::vector<double> dr;
  std::vector<int64_t> steps;
  std::vector<char> edge;
  std::vector<size_t> stretch_from, stretch_to;  // per pair: the stretch of large steps the same way it is in
  for (size_t a = 0; a < m;) {
    // A chain: samples no more than max_missing apart.
    size_t b = a;
    while (b + 1 < m && pos(b + 1) - pos(b) <= p.max_missing + 1) ++b;
    if (b - a >= 2) {
      const size_t pairs = b - a;
      dr.assign(pairs, 0);
      steps.assign(pairs, 1);
      edge.assign(pairs, 0);
      for (size_t j = 0; j < pairs; ++j) {
        dr[j] = range[sample(a + j + 1)] - range[sample(a + j)];
        steps[j] = pos(a + j + 1) - pos(a + j);
      }
      // A step larger than noise (5 σ of a difference) belongs to a stretch of such
      // steps the same way. A short one (no wider than a transition across an edge)
      // is measured against the slopes beyond it, so that a transition stepping
      // evenly through several mixed samples still shows; a longer one is a steep
      // surface, and each step is measured against its neighbours.
      auto big = [&](size_t j) { return std::abs(dr[j]) > first; };
      stretch_from.assign(pairs, 0);
      stretch_to.assign(pairs, 0);
      for (size_t j = 0; j < pairs;) {
        size_t e = j;
        if (big(j))
          while (e + 1 < pairs && big(e + 1) && (dr[e + 1] > 0) == (dr[j] > 0)) ++e;
        for (size_t k = j; k <= e; ++k) {
          stretch_from[k] = j;
          stretch_to[k] = e;
        }
        j = e + 1;
      }
      for (size_t j = 0; j < pairs; ++j) {
        const double st = static_cast<double>(steps[j]);
        if (std::abs(dr[j]) > st * range[sample(a + j)] * delta * steepest + first) {
          edge[j] = 1;
          continue;
        }
        if (!big(j)) continue;
        const size_t s0 = stretch_from[j], s1 = stretch_to[j];
        const double span = static_cast<double>(pos(a + s1 + 1) - pos(a + s0)) * delta;
        const bool transition = span <= p.max_run_rad + delta;
        const bool has_prev = transition ? s0 > 0 : j > 0;
        const bool has_next = transition ? s1 + 1 < pairs : j + 1 < pairs;
        const size_t prev = transition ? s0 - 1 : j - 1, next = transition ? s1 + 1 : j + 1;
        auto offSlope = [&](size_t k) { return std::abs(dr[j] - dr[k] / static_cast<double>(steps[k]) * st) > second; };
        edge[j] = (has_prev || has_next) && (!has_prev || offSlope(prev)) && (!has_next || offSlope(next));
      }
      // Runs of samples between edges: run [u, v] (chain indices) has edge u-1 before it and edge v after it.
      size_t u = 0;
      for (size_t j = 0; j < pairs; ++j) {
        if (!edge[j]) continue;
        if (u > 0) {
          const size_t v = j;
          const bool same_way = (dr[u - 1] > 0) == (dr[v] > 0);
          const double width = static_cast<double>(pos(a + v) - pos(a + u) + 1) * delta;
          if (same_way && width <= p.max_run_rad)
            for (size_t k = u; k <= v; ++k) mixed[sample(a + k)] = 1;
        }
        u = j + 1;
      }
    }
    a = b + 1;
  }
}

}  // namespace

void checkMixedPixelParams(const MixedPixelParams& p) {
  auto bad = [](const std::string& what) { throw InvalidInput("[removeMixedPixels] " + what); };
  if (!(p.sensor_sigma_m > 0) || !std::isfinite(p.sensor_sigma_m))
    bad("sensor_sigma_m must be > 0 (got " + std::to_string(p.sensor_sigma_m) + ")");
  if (!(p.jump_sigmas > 0) || !std::isfinite(p.jump_sigmas))
    bad("jump_sigmas must be > 0 (got " + std::to_string(p.jump_sigmas) + ")");
  if (!(p.max_incidence_deg > 0 && p.max_incidence_deg < 90))
    bad("max_incidence_deg must be in (0, 90) (got " + std::to_string(p.max_incidence_deg) + ")");
  if (!(p.max_run_rad > 0) || !std::isfinite(p.max_run_rad))
    bad("max_run_rad must be > 0 (got " + std::to_string(p.max_run_rad) + ")");
  if (p.max_missing < 0) bad("max_missing must be >= 0 (got " + std::to_string(p.max_missing) + ")");
}

Cleaning removeMixedPixels(const Cloud& cloud, const MixedPixelParams& params) {
  checkMixedPixelParams(params);
  Cleaning out;
  out.kept.resize(cloud.size());
  std::iota(out.kept.begin(), out.kept.end(), 0u);
  if (!cloud.hasScanAngles() || !cloud.viewpoint) {
    out.warnings.push_back(std::string("mixed pixels not looked for: the cloud has no ") +
                           (cloud.hasScanAngles() ? "viewpoint (scanner position)" : "scan angles (alpha, beta)"));
    return out;
  }
  if (cloud.alpha_rad.size() != cloud.size() || cloud.beta_rad.size() != cloud.size())
    throw InvalidInput("[removeMixedPixels] the cloud has " + std::to_string(cloud.size()) + " points but " +
                       std::to_string(cloud.alpha_rad.size()) + " alpha and " + std::to_string(cloud.beta_rad.size()) +
                       " beta angles");
  for (size_t i = 0; i < cloud.size(); ++i)
    if (!std::isfinite(cloud.alpha_rad[i]) || !std::isfinite(cloud.beta_rad[i]))
      throw InvalidInput("[removeMixedPixels] point " + std::to_string(i) + " has a non-finite scan angle");
  out.threshold_m = params.jump_sigmas * std::sqrt(6.0) * params.sensor_sigma_m;
  if (cloud.size() < 3) return out;

  std::vector<double> range(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) range[i] = (cloud.points[i] - *cloud.viewpoint).norm();
  const ScanGrid grid = scanGrid(cloud);
  if (!(grid.d_alpha > 0)) return out;

  std::vector<char> mixed(cloud.size(), 0);
  for (const Row& line : grid.lines) markRow(line, grid.d_alpha, range, params, mixed);  // along each line
  if (grid.d_beta > 0) {  // across the lines, at each α step
    std::unordered_map<int64_t, Row> columns;
    for (size_t l = 0; l < grid.lines.size(); ++l)
      for (const auto& [k, s] : grid.lines[l]) columns[k].emplace_back(grid.line_step[l], s);
    for (auto& [k, column] : columns) {
      std::sort(column.begin(), column.end());
      // Two lines at one place: the first stands for it.
      column.erase(std::unique(column.begin(), column.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                   column.end());
      markRow(column, grid.d_beta, range, params, mixed);
    }
  }
  out.kept.clear();
  for (uint32_t i = 0; i < cloud.size(); ++i) (mixed[i] ? out.removed : out.kept).push_back(i);
  return out;
}

std::vector<ScanLine> scanLines(const Cloud& cloud) {
  std::vector<ScanLine> out;
  if (!cloud.hasScanAngles() || cloud.alpha_rad.size() != cloud.size() || cloud.beta_rad.size() != cloud.size())
    return out;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (!std::isfinite(cloud.alpha_rad[i]) || !std::isfinite(cloud.beta_rad[i])) return out;
  if (cloud.empty()) return out;
  for (std::vector<uint32_t>& m : lineMembers(cloud)) {
    double b = 0;
    for (uint32_t s : m) b += cloud.beta_rad[s];
    out.push_back({b / static_cast<double>(m.size()), std::move(m)});
  }
  return out;
}

double scanLineStepRad(const Cloud& cloud) { return medianLineStep(scanLines(cloud)); }

}  // namespace sailshape
