#include "analysis/spatial/neighbours.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <mutex>
#include <nanoflann.hpp>
#include <string>
#include <type_traits>
#include <utility>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

struct PointAdaptor {
  const std::vector<Vec3>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointAdaptor>,
                                                 PointAdaptor, 3, uint32_t>;

}  // namespace

struct KdTree::Impl {
  PointAdaptor adaptor;
  Tree tree;
  explicit Impl(const std::vector<Vec3>& points)
      : adaptor{points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree.buildIndex();
  }
};

KdTree::KdTree(const std::vector<Vec3>& points) : impl_(std::make_unique<Impl>(points)) {}
KdTree::~KdTree() = default;

void KdTree::nearest(const Vec3& q, size_t k, std::vector<uint32_t>& indices, std::vector<double>& dist2) const {
  k = std::min(k, impl_->adaptor.pts.size());
  indices.resize(k);
  dist2.resize(k);
  if (k == 0) return;
  const size_t found = impl_->tree.knnSearch(q.data(), k, indices.data(), dist2.data());
  indices.resize(found);
  dist2.resize(found);
}

void KdTree::withinRadius(const Vec3& q, double radius_m, std::vector<uint32_t>& indices,
                          std::vector<double>& dist2) const {
  std::vector<std::pair<uint32_t, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = true;
  impl_->tree.radiusSearch(q.data(), radius_m * radius_m, matches, params);
  indices.resize(matches.size());
  dist2.resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    indices[i] = matches[i].first;
    dist2[i] = matches[i].second;
  }
}

namespace {

// (squared distance, index): ordered by distance, ties by index.
using Candidate = std::pair<double, uint32_t>;

// Sorts the k nearest of `cand` to its front (cand.size() >= k).
void keepNearest(std::vector<Candidate>& cand, size_t k) {
  if (cand.size() > k) std::nth_element(cand.begin(), cand.begin() + static_cast<long>(k - 1), cand.end());
  std::sort(cand.begin(), cand.begin() + static_cast<long>(k));
}

// The candidates at slots sel[0 .. n) (squared distances dd, all <= limit2, and
// indices idx) into `cand`, sorted by (distance², index): a counting sort into 64
// bins of limit2 / 64 (a surface's squared distances spread evenly over them),
// then an insertion sort that only mends each bin's order. For the few dozen
// candidates of a table row, several times cheaper than nth_element and sort.
// Needs a finite limit2 (and n small: the insertion sort is quadratic within a bin).
void sortWithin(const std::vector<double>& dd, const std::vector<uint32_t>& idx, const std::vector<uint32_t>& sel,
                size_t n, double limit2, std::vector<Candidate>& cand) {
  constexpr int kBins = 64;
  const double scale = limit2 > 0 ? kBins / limit2 : 0.0;
  uint32_t start[kBins + 1] = {};
  thread_local std::vector<uint8_t> bin;
  bin.resize(n);
  for (size_t j = 0; j < n; ++j) {
    bin[j] = static_cast<uint8_t>(std::min(kBins - 1, static_cast<int>(dd[sel[j]] * scale)));
    ++start[bin[j] + 1];
  }
  for (int b = 0; b < kBins; ++b) start[b + 1] += start[b];
  cand.resize(n);
  for (size_t j = 0; j < n; ++j) cand[start[bin[j]]++] = {dd[sel[j]], idx[sel[j]]};
  for (size_t j = 1; j < n; ++j) {
    const Candidate c = cand[j];
    size_t i = j;
    for (; i > 0 && c < cand[i - 1]; --i) cand[i] = cand[i - 1];
    cand[i] = c;
  }
}

// Writes the first k candidates as point i's row, the point itself first: duplicate
// points (distance 0, lower index) can push it out of the k or off slot 0.
void writeRow(const std::vector<Candidate>& cand, size_t k, uint32_t i, uint32_t* row, float* row_d2) {
  size_t self = k;
  for (size_t j = 0; j < k; ++j)
    if (cand[j].second == i) self = j;
  row[0] = i;
  row_d2[0] = 0.0f;
  size_t out = 1;
  for (size_t j = 0; j < k && out < k; ++j) {
    if (j == self) continue;
    row[out] = cand[j].second;
    row_d2[out] = static_cast<float>(cand[j].first);
    ++out;
  }
}

constexpr int kCoordBits = 21;  // cells per axis < 2^21
constexpr int64_t kCoordLimit = int64_t{1} << kCoordBits;
constexpr uint64_t kEmptySlot = ~uint64_t{0};
// Beyond this many rings of cells a query falls back to the k-d tree (a point far from all others).
constexpr int kMaxRing = 6;

}  // namespace

struct PointGrid::Impl {
  const std::vector<Vec3>& pts;
  double cell = 1, inv = 1;
  Vec3 origin = Vec3::Zero();
  std::vector<Vec3> sorted;              // the points cell by cell
  std::vector<uint32_t> sorted_index;    // their indices in `pts`
  std::vector<uint32_t> cell_start;      // cell c holds sorted[cell_start[c] .. cell_start[c+1])
  std::vector<Eigen::Vector3i> cell_coord;
  std::vector<uint64_t> slot_key;        // open addressing: packed cell coordinates -> cell
  std::vector<uint32_t> slot_cell;
  int slot_shift = 64;
  mutable std::once_flag tree_once;
  mutable std::unique_ptr<KdTree> tree;

  Impl(const std::vector<Vec3>& points, double cell_m) : pts(points) {
    if (!(cell_m > 0) || !std::isfinite(cell_m))
      throw InvalidInput("[PointGrid] cell_m must be > 0 (got " + std::to_string(cell_m) + ")");
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec3& p : pts) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (pts.empty()) lo = hi = Vec3::Zero();
    origin = lo;
    cell = std::max(cell_m, (hi - lo).maxCoeff() / static_cast<double>(kCoordLimit - 2));
    inv = 1.0 / cell;

    // The table grows with the cells (at most half full), not with the points: a
    // few thousand cells' table stays in cache while every point looks its cell up.
    setSlots(16);
    std::vector<uint32_t> cell_of(pts.size());
    std::vector<uint32_t> count;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3i c = coordOf(pts[i]);
      const uint64_t key = pack(c);
      size_t s = slotOf(key);
      while (slot_key[s] != kEmptySlot && slot_key[s] != key) s = (s + 1) & (slot_key.size() - 1);
      if (slot_key[s] == kEmptySlot) {
        slot_key[s] = key;
        slot_cell[s] = static_cast<uint32_t>(count.size());
        count.push_back(0);
        cell_coord.push_back(c);
      }
      cell_of[i] = slot_cell[s];
      ++count[slot_cell[s]];
      if (2 * count.size() > slot_key.size()) setSlots(2 * slot_key.size());
    }
    // Cells in Morton (Z-curve) order of their coordinates: cells near in space
    // are near in memory, so the 27 cells around a query and the next cell's
    // neighbours mostly come from cache (first-seen order follows the input's,
    // which can be random).
    const size_t cells = count.size();
    std::vector<uint64_t> code(cells);
    for (size_t c = 0; c < cells; ++c)
      code[c] = spread(cell_coord[c].x()) | (spread(cell_coord[c].y()) << 1) | (spread(cell_coord[c].z()) << 2);
    std::vector<uint32_t> by_code(cells);
    for (uint32_t c = 0; c < cells; ++c) by_code[c] = c;
    std::sort(by_code.begin(), by_code.end(), [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
    std::vector<uint32_t> rank(cells);
    for (uint32_t r = 0; r < cells; ++r) rank[by_code[r]] = r;
    for (size_t s = 0; s < slot_key.size(); ++s)
      if (slot_key[s] != kEmptySlot) slot_cell[s] = rank[slot_cell[s]];
    for (uint32_t& c : cell_of) c = rank[c];
    std::vector<uint32_t> count_sorted(cells);
    std::vector<Eigen::Vector3i> coord_sorted(cells);
    for (size_t c = 0; c < cells; ++c) {
      count_sorted[rank[c]] = count[c];
      coord_sorted[rank[c]] = cell_coord[c];
    }
    count.swap(count_sorted);
    cell_coord.swap(coord_sorted);
    cell_start.assign(count.size() + 1, 0);
    for (size_t c = 0; c < count.size(); ++c) cell_start[c + 1] = cell_start[c] + count[c];
    sorted.resize(pts.size());
    sorted_index.resize(pts.size());
    std::vector<uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (size_t i = 0; i < pts.size(); ++i) {
      const uint32_t at = fill[cell_of[i]]++;
      sorted[at] = pts[i];
      sorted_index[at] = static_cast<uint32_t>(i);
    }
  }

  Eigen::Vector3i coordOf(const Vec3& p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) {
      const double v = std::floor((p[a] - origin[a]) * inv);
      c[a] = static_cast<int>(std::max(-1e9, std::min(1e9, v)));
    }
    return c;
  }
  // The 21 low bits of v spread to every third bit.
  static uint64_t spread(int v) {
    uint64_t x = static_cast<uint64_t>(v) & 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
  }
  static uint64_t pack(const Eigen::Vector3i& c) {
    return static_cast<uint64_t>(c.x()) | (static_cast<uint64_t>(c.y()) << kCoordBits) |
           (static_cast<uint64_t>(c.z()) << (2 * kCoordBits));
  }
  size_t slotOf(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> slot_shift); }
  // Resizes the table to `slots` (a power of two) and puts the stored cells back.
  void setSlots(size_t slots) {
    std::vector<uint64_t> old_key(slots, kEmptySlot);
    std::vector<uint32_t> old_cell(slots, 0);
    old_key.swap(slot_key);
    old_cell.swap(slot_cell);
    slot_shift = 64 - static_cast<int>(std::log2(static_cast<double>(slots)) + 0.5);
    for (size_t o = 0; o < old_key.size(); ++o) {
      if (old_key[o] == kEmptySlot) continue;
      size_t s = slotOf(old_key[o]);
      while (slot_key[s] != kEmptySlot) s = (s + 1) & (slots - 1);
      slot_key[s] = old_key[o];
      slot_cell[s] = old_cell[o];
    }
  }
  // The cell at c, or -1 when no point lies there.
  long find(const Eigen::Vector3i& c) const {
    for (int a = 0; a < 3; ++a)
      if (c[a] < 0 || c[a] >= kCoordLimit) return -1;
    const uint64_t key = pack(c);
    for (size_t s = slotOf(key);; s = (s + 1) & (slot_key.size() - 1)) {
      if (slot_key[s] == key) return slot_cell[s];
      if (slot_key[s] == kEmptySlot) return -1;
    }
  }
  // Calls f(cell) for every occupied cell whose coordinates differ from c by exactly
  // `ring` in their largest component (ring 0: c itself).
  template <class F>
  void forRing(const Eigen::Vector3i& c, int ring, F&& f) const {
    for (int dx = -ring; dx <= ring; ++dx)
      for (int dy = -ring; dy <= ring; ++dy) {
        const bool side = std::abs(dx) == ring || std::abs(dy) == ring;
        for (int dz = -ring; dz <= ring; dz += (side || ring == 0) ? 1 : 2 * ring) {
          const long cell_id = find(c + Eigen::Vector3i(dx, dy, dz));
          if (cell_id >= 0) f(static_cast<size_t>(cell_id));
        }
      }
  }
  // Calls f(cell) for every occupied cell that may hold a point within radius_m of a
  // point in cell c: the rings around c, or every cell when those would be more.
  template <class F>
  void forCellsWithin(const Eigen::Vector3i& c, double radius_m, F&& f) const {
    const double rings = std::ceil(radius_m * inv);
    const size_t cells = cell_start.size() - 1;
    if (rings > 64 || std::pow(2 * rings + 1, 3) > static_cast<double>(cells)) {
      for (size_t id = 0; id < cells; ++id) f(id);
      return;
    }
    for (int ring = 0; ring <= static_cast<int>(rings); ++ring) forRing(c, ring, f);
  }
  // Distance from q (in cell c) to the nearest face of its cell.
  double marginInCell(const Vec3& q, const Eigen::Vector3i& c) const {
    double m = cell;
    for (int a = 0; a < 3; ++a) {
      const double lo = origin[a] + c[a] * cell;
      m = std::min({m, q[a] - lo, lo + cell - q[a]});
    }
    return std::max(0.0, m);
  }
  const KdTree& kdTree() const {
    std::call_once(tree_once, [this] { tree = std::make_unique<KdTree>(pts); });
    return *tree;
  }

  // The k nearest to q into cand's front, sorted; false when it took the k-d tree
  // (then idx/d2 hold the answer instead).
  void nearest(const Vec3& q, size_t k, std::vector<Candidate>& cand, std::vector<uint32_t>& idx,
               std::vector<double>& d2) const {
    cand.clear();
    const Eigen::Vector3i c = coordOf(q);
    auto add = [&](size_t cell_id) {
      for (uint32_t j = cell_start[cell_id]; j < cell_start[cell_id + 1]; ++j)
        cand.emplace_back((sorted[j] - q).squaredNorm(), sorted_index[j]);
    };
    const double margin = marginInCell(q, c);
    for (int ring = 0;; ++ring) {
      forRing(c, ring, add);
      // Every point within this distance of q is in the rings visited so far.
      const double sure = static_cast<double>(ring) * cell + margin;
      if (cand.size() >= k) {
        std::nth_element(cand.begin(), cand.begin() + static_cast<long>(k - 1), cand.end());
        if (cand[k - 1].first <= sure * sure || cand.size() == pts.size()) break;
      }
      if (ring >= kMaxRing) {
        kdTree().nearest(q, k, idx, d2);
        cand.clear();
        for (size_t j = 0; j < idx.size(); ++j) cand.emplace_back(d2[j], idx[j]);
        std::sort(cand.begin(), cand.end());
        return;
      }
    }
    keepNearest(cand, k);
  }
};

PointGrid::PointGrid(const std::vector<Vec3>& points, double cell_m)
    : impl_(std::make_unique<Impl>(points, cell_m)) {}
PointGrid::~PointGrid() = default;

double PointGrid::cellSize() const { return impl_->cell; }
size_t PointGrid::cellCount() const { return impl_->cell_start.size() - 1; }
const std::vector<uint32_t>& PointGrid::cellStart() const { return impl_->cell_start; }
const std::vector<uint32_t>& PointGrid::cellPoints() const { return impl_->sorted_index; }
Vec3 PointGrid::cellCentre(size_t c) const {
  return impl_->origin + (impl_->cell_coord.at(c).cast<double>() + Vec3::Constant(0.5)) * impl_->cell;
}

void PointGrid::nearest(const Vec3& q, size_t k, std::vector<uint32_t>& indices, std::vector<double>& dist2) const {
  k = std::min(k, impl_->pts.size());
  thread_local std::vector<Candidate> cand;
  if (k == 0) {
    indices.clear();
    dist2.clear();
    return;
  }
  impl_->nearest(q, k, cand, indices, dist2);
  indices.resize(k);
  dist2.resize(k);
  for (size_t j = 0; j < k; ++j) {
    indices[j] = cand[j].second;
    dist2[j] = cand[j].first;
  }
}

void PointGrid::withinRadius(const Vec3& q, double radius_m, std::vector<uint32_t>& indices,
                             std::vector<double>& dist2, std::vector<Vec3>* points) const {
  indices.clear();
  dist2.clear();
  if (points) points->clear();
  if (!(radius_m >= 0)) return;
  const double r2 = radius_m * radius_m;
  const Impl& g = *impl_;
  g.forCellsWithin(g.coordOf(q), radius_m, [&](size_t cell_id) {
    for (uint32_t j = g.cell_start[cell_id]; j < g.cell_start[cell_id + 1]; ++j) {
      const double d = (g.sorted[j] - q).squaredNorm();
      if (d <= r2) {
        indices.push_back(g.sorted_index[j]);
        dist2.push_back(d);
        if (points) points->push_back(g.sorted[j]);
      }
    }
  });
}

void PointGrid::cellNeighbourhood(size_t c, double radius_m, std::vector<uint32_t>& indices,
                                  std::vector<Vec3>& points) const {
  indices.clear();
  points.clear();
  if (!(radius_m >= 0)) return;
  const Impl& g = *impl_;
  g.forCellsWithin(g.cell_coord.at(c), radius_m, [&](size_t cell_id) {
    indices.insert(indices.end(), g.sorted_index.begin() + g.cell_start[cell_id],
                   g.sorted_index.begin() + g.cell_start[cell_id + 1]);
    points.insert(points.end(), g.sorted.begin() + g.cell_start[cell_id], g.sorted.begin() + g.cell_start[cell_id + 1]);
  });
}

void PointGrid::fillTable(NeighbourTable& table, size_t k, const Progress& progress) const {
  const Impl& g = *impl_;
  if (k < 1 || g.pts.size() < k)
    throw InvalidInput("[PointGrid::fillTable] k = " + std::to_string(k) + " needs 1 <= k <= " +
                       std::to_string(g.pts.size()) + " points");
  table.k = k;
  table.index.resize(g.pts.size() * k);
  table.dist2.resize(g.pts.size() * k);
  const long cells = static_cast<long>(g.cell_start.size() - 1);
  // A few blocks: progress (and a cancelling callback) between them, few barriers
  // (a thread descheduled on a busy machine stalls the other at each).
  const long block = std::max<long>(256, cells / 4);
  for (long first = 0; first < cells; first += block) {
    const long last = std::min(cells, first + block);
#pragma omp parallel
    {
      // Each cell's points share the candidates of the 27 cells around it: every
      // point within one cell width of any of them.
      std::vector<double> nx, ny, nz, dd;  // candidates' coordinates (vectorisable) and squared distances
      std::vector<uint32_t> near_idx, sel;
      std::vector<Candidate> cand;
      std::vector<uint32_t> idx;
      std::vector<double> d2;
#pragma omp for schedule(dynamic, 16)
      for (long c = first; c < last; ++c) {
        nx.clear();
        ny.clear();
        nz.clear();
        near_idx.clear();
        auto gather = [&](size_t id) {
          for (uint32_t j = g.cell_start[id]; j < g.cell_start[id + 1]; ++j) {
            nx.push_back(g.sorted[j].x());
            ny.push_back(g.sorted[j].y());
            nz.push_back(g.sorted[j].z());
            near_idx.push_back(g.sorted_index[j]);
          }
        };
        const Eigen::Vector3i& coord = g.cell_coord[static_cast<size_t>(c)];
        g.forRing(coord, 0, gather);
        g.forRing(coord, 1, gather);
        const size_t m = near_idx.size();
        dd.resize(m);
        const bool everything = m == g.pts.size();
        for (uint32_t s = g.cell_start[static_cast<size_t>(c)]; s < g.cell_start[static_cast<size_t>(c) + 1]; ++s) {
          const Vec3& q = g.sorted[s];
          const uint32_t i = g.sorted_index[s];
          const double qx = q.x(), qy = q.y(), qz = q.z();
          for (size_t j = 0; j < m; ++j)
            dd[j] = (nx[j] - qx) * (nx[j] - qx) + (ny[j] - qy) * (ny[j] - qy) + (nz[j] - qz) * (nz[j] - qz);
          // Every point within `sure` of q is among the candidates: when k of them
          // are, they are the k nearest. A tighter limit first (most points' k-th
          // neighbour lies well inside it) leaves fewer to select from.
          const double sure = g.cell + g.marginInCell(q, coord);
          const double sure2 = everything ? std::numeric_limits<double>::infinity() : sure * sure;
          bool done = false;
          for (double limit2 : {std::min(sure2, 0.7 * g.cell * g.cell), sure2}) {
            // Every slot written, kept when within the limit: no branch to mispredict.
            sel.resize(m);
            size_t within = 0;
            for (size_t j = 0; j < m; ++j) {
              sel[within] = static_cast<uint32_t>(j);
              within += dd[j] <= limit2 ? 1 : 0;
            }
            if (within >= k && within <= 1024 && std::isfinite(limit2)) {
              sortWithin(dd, near_idx, sel, within, limit2, cand);
              done = true;
              break;
            }
            if (within >= k) {
              cand.resize(within);
              for (size_t j = 0; j < within; ++j) cand[j] = {dd[sel[j]], near_idx[sel[j]]};
              keepNearest(cand, k);
              done = true;
              break;
            }
          }
          if (!done) g.nearest(q, k, cand, idx, d2);
          writeRow(cand, k, i, table.index.data() + static_cast<size_t>(i) * k,
                   table.dist2.data() + static_cast<size_t>(i) * k);
        }
      }
    }
    progress("neighbours", static_cast<double>(last) / static_cast<double>(cells));
  }
}

std::unique_ptr<PointGrid> gridForNeighbours(const std::vector<Vec3>& points, size_t k) {
  k = std::max<size_t>(1, k);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (points.size() < 2) return std::make_unique<PointGrid>(points, 1.0);
  // First guess: the points spread over the part of the bounding box's largest
  // face they cover, counted in bins holding about 16 points each if the face
  // were full (a triangular sail covers about half its box; a wrong guess costs a
  // second grid, not exactness).
  int axis[3] = {0, 1, 2};
  const Vec3 e = hi - lo;
  std::sort(axis, axis + 3, [&](int a, int b) { return e[a] > e[b]; });
  const int u = axis[0], v = axis[1];
  const double face = std::max({e[u] * e[v], 1e-6 * e[u] * e[u], 1e-12});
  const int bins = static_cast<int>(std::clamp(std::sqrt(static_cast<double>(points.size()) / 16.0), 1.0, 256.0));
  std::vector<char> occupied(static_cast<size_t>(bins) * static_cast<size_t>(bins), 0);
  auto bin = [&](double x, double lo_x, double size) {
    return std::clamp(static_cast<int>((x - lo_x) / std::max(size, 1e-12) * bins), 0, bins - 1);
  };
  for (const Vec3& p : points) occupied[static_cast<size_t>(bin(p[u], lo[u], e[u]) * bins + bin(p[v], lo[v], e[v]))] = 1;
  size_t count = 0;
  for (char o : occupied) count += o;
  const double area = face * static_cast<double>(count) / static_cast<double>(occupied.size());
  const double density = static_cast<double>(points.size()) / std::max(area, 1e-12);
  const double guess = 1.5 * std::sqrt(static_cast<double>(k) / (M_PI * density));
  auto grid = std::make_unique<PointGrid>(points, guess);
  const double median = medianNeighbourDistance(*grid, points, std::min(k, points.size()), 64);
  const double cell = 1.5 * median;
  if (cell > 0 && (cell < 0.85 * grid->cellSize() || cell > 1.2 * grid->cellSize()))
    grid = std::make_unique<PointGrid>(points, cell);
  return grid;
}

NeighbourTable nearestNeighbours(const std::vector<Vec3>& points, size_t k, const Progress& progress) {
  if (k < 1) throw InvalidInput("[nearestNeighbours] k must be >= 1 (got 0)");
  if (points.size() < k)
    throw InvalidInput("[nearestNeighbours] cloud has " + std::to_string(points.size()) +
                       " points, fewer than k = " + std::to_string(k));
  NeighbourTable table;
  gridForNeighbours(points, k)->fillTable(table, k, progress);
  return table;
}

NeighbourTable subsetTable(const NeighbourTable& table, const std::vector<Vec3>& points,
                           const std::vector<uint32_t>& kept, size_t k) {
  if (k < 1 || k > table.k || k > kept.size())
    throw InvalidInput("[subsetTable] k = " + std::to_string(k) + " needs 1 <= k <= the table's " +
                       std::to_string(table.k) + " columns and the " + std::to_string(kept.size()) + " kept points");
  if (table.size() != points.size())
    throw InvalidInput("[subsetTable] the table has " + std::to_string(table.size()) + " rows for " +
                       std::to_string(points.size()) + " points");
  constexpr uint32_t kGone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> renumber(points.size(), kGone);
  for (size_t j = 0; j < kept.size(); ++j) {
    if (kept[j] >= points.size() || (j > 0 && kept[j] <= kept[j - 1]))
      throw InvalidInput("[subsetTable] kept indices must be ascending and below " + std::to_string(points.size()) +
                         " (got " + std::to_string(kept[j]) + " at position " + std::to_string(j) + ")");
    renumber[kept[j]] = static_cast<uint32_t>(j);
  }
  NeighbourTable sub;
  sub.k = k;
  sub.index.resize(kept.size() * k);
  sub.dist2.resize(kept.size() * k);
  std::vector<uint32_t> short_rows;
  for (size_t j = 0; j < kept.size(); ++j) {
    const uint32_t* row = table.row(kept[j]);
    const float* d2 = table.rowDist2(kept[j]);
    size_t out = 0;
    for (size_t c = 0; c < table.k && out < k; ++c)
      if (renumber[row[c]] != kGone) {
        sub.index[j * k + out] = renumber[row[c]];
        sub.dist2[j * k + out] = d2[c];
        ++out;
      }
    if (out < k) short_rows.push_back(static_cast<uint32_t>(j));
  }
  if (!short_rows.empty()) {
    // Removed neighbours left these rows short: search the sub-cloud itself.
    std::vector<Vec3> sub_points(kept.size());
    for (size_t j = 0; j < kept.size(); ++j) sub_points[j] = points[kept[j]];
    const auto grid = gridForNeighbours(sub_points, k);
    std::vector<Candidate> cand;
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    for (uint32_t j : short_rows) {
      grid->nearest(sub_points[j], k, idx, d2);
      cand.resize(k);
      for (size_t c = 0; c < k; ++c) cand[c] = {d2[c], idx[c]};
      writeRow(cand, k, j, sub.index.data() + j * k, sub.dist2.data() + j * k);
    }
  }
  return sub;
}

double medianSpacing(const NeighbourTable& table) {
  if (table.k < 2 || table.size() < 2) return 0.0;
  std::vector<float> d(table.size());
  for (size_t i = 0; i < table.size(); ++i) d[i] = table.rowDist2(i)[1];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return std::sqrt(static_cast<double>(d[d.size() / 2]));
}

namespace {
template <class Search>
double medianKthDistance(const Search& search, const std::vector<Vec3>& points, size_t k, size_t samples) {
  if (points.size() < 2 || k < 2) return 0.0;
  std::vector<double> d;
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  const size_t step = std::max<size_t>(1, points.size() / std::max<size_t>(1, samples));
  for (size_t i = 0; i < points.size(); i += step) {
    search.nearest(points[i], k, idx, d2);
    d.push_back(std::sqrt(d2.back()));
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}
}  // namespace

double medianNeighbourDistance(const KdTree& tree, const std::vector<Vec3>& points, size_t k, size_t samples) {
  return medianKthDistance(tree, points, k, samples);
}

double medianNeighbourDistance(const PointGrid& grid, const std::vector<Vec3>& points, size_t k, size_t samples) {
  return medianKthDistance(grid, points, k, samples);
}

Eigen::Vector3i voxelOf(const Vec3& p, double size) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / size)), static_cast<int>(std::floor(p.y() / size)),
                         static_cast<int>(std::floor(p.z() / size)));
}

int64_t voxelKey(const Eigen::Vector3i& c) {
  constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
  auto bits = [](int v) { return static_cast<uint64_t>(static_cast<int64_t>(v)) & kMask; };
  return static_cast<int64_t>((bits(c.x()) << 42) | (bits(c.y()) << 21) | bits(c.z()));
}

namespace {
constexpr uint32_t kFree = std::numeric_limits<uint32_t>::max();
int shiftFor(size_t slots) { return 64 - static_cast<int>(std::lround(std::log2(static_cast<double>(slots)))); }
}  // namespace

KeyIds::KeyIds(size_t expected_keys) {
  size_t slots = 16;
  while (slots < 2 * expected_keys) slots *= 2;
  key_.assign(slots, 0);
  id_.assign(slots, kFree);
  shift_ = shiftFor(slots);
}

uint32_t KeyIds::idOf(int64_t key) {
  const size_t mask = key_.size() - 1;
  for (size_t s = (static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_;; s = (s + 1) & mask) {
    if (id_[s] == kFree) {
      key_[s] = key;
      id_[s] = static_cast<uint32_t>(ids_++);
      const uint32_t id = id_[s];
      if (2 * ids_ > key_.size()) grow();  // at most half full: short probe runs
      return id;
    }
    if (key_[s] == key) return id_[s];
  }
}

bool KeyIds::find(int64_t key, uint32_t& id) const {
  const size_t mask = key_.size() - 1;
  for (size_t s = (static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_;; s = (s + 1) & mask) {
    if (id_[s] == kFree) return false;
    if (key_[s] == key) {
      id = id_[s];
      return true;
    }
  }
}

bool medianNeighbourDistanceBelow(const std::vector<Vec3>& points, double limit_m, size_t samples) {
  const size_t n = points.size();
  if (n < 2) return 0.0 < limit_m;  // medianNeighbourDistance gives 0
  if (!(limit_m > 0)) return false;
  // A point nearer than limit_m lies in one of the 27 cells around the sample's; the
  // cells are a hair wider so that rounding in the cell index cannot push it further.
  const double cell = limit_m * (1 + 1e-9);
  // The same samples as medianNeighbourDistance; the median is the (m/2)-th smallest
  // of their m distances, below the limit when more than m/2 of them are.
  const size_t step = std::max<size_t>(1, n / std::max<size_t>(1, samples));
  // Only the cells around the samples are read: a table of those few thousand keys
  // stays in cache while every point is looked up in it once.
  KeyIds ids(27 * (n / step + 1));
  for (size_t i = 0; i < n; i += step) {
    const Eigen::Vector3i c = voxelOf(points[i], cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) ids.idOf(voxelKey(Eigen::Vector3i(c.x() + dx, c.y() + dy, c.z() + dz)));
  }
  constexpr uint32_t kElsewhere = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> cell_of(n, kElsewhere), start(ids.size() + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    uint32_t id = 0;
    if (ids.find(voxelKey(points[i], cell), id)) {
      cell_of[i] = id;
      ++start[id + 1];
    }
  }
  for (size_t c = 0; c < ids.size(); ++c) start[c + 1] += start[c];
  std::vector<uint32_t> members(start.back());
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t i = 0; i < n; ++i)
      if (cell_of[i] != kElsewhere) members[fill[cell_of[i]]++] = i;
  }
  size_t m = 0, below = 0;
  for (size_t i = 0; i < n; i += step) {
    ++m;
    const Eigen::Vector3i c = voxelOf(points[i], cell);
    double best2 = std::numeric_limits<double>::infinity();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          uint32_t id = 0;
          if (!ids.find(voxelKey(Eigen::Vector3i(c.x() + dx, c.y() + dy, c.z() + dz)), id)) continue;
          for (uint32_t s = start[id]; s < start[id + 1]; ++s)
            if (members[s] != i) best2 = std::min(best2, (points[members[s]] - points[i]).squaredNorm());
        }
    below += std::sqrt(best2) < limit_m ? 1 : 0;
  }
  return below >= m / 2 + 1;
}

void KeyIds::grow() {
  std::vector<int64_t> old_key;
  std::vector<uint32_t> old_id;
  old_key.swap(key_);
  old_id.swap(id_);
  key_.assign(2 * old_key.size(), 0);
  id_.assign(2 * old_key.size(), kFree);
  shift_ = shiftFor(key_.size());
  const size_t mask = key_.size() - 1;
  for (size_t o = 0; o < old_key.size(); ++o) {
    if (old_id[o] == kFree) continue;
    size_t s = (static_cast<uint64_t>(old_key[o]) * 0x9E3779B97F4A7C15ull) >> shift_;
    while (id_[s] != kFree) s = (s + 1) & mask;
    key_[s] = old_key[o];
    id_[s] = old_id[o];
  }
}

double selectNearest(const std::vector<double>& d2, double limit2, size_t k, std::vector<uint8_t>& bin,
                     std::vector<uint32_t>& part, std::vector<double>& part_d2, std::vector<uint32_t>& out) {
  if (k == 0) {
    out.clear();
    return 0;
  }
  constexpr int kBins = 128;  // bin kBins: beyond limit2
  const double scale = limit2 > 0 && std::isfinite(limit2) ? kBins / limit2 : 0.0;
  const size_t m = d2.size();
  bin.resize(m);
  // Bins first (a loop the compiler vectorises), then counted into four
  // histograms in turn, so that runs of one bin do not wait on each other.
  const double* d = d2.data();
  uint8_t* bn = bin.data();
  for (size_t j = 0; j < m; ++j) {
    const double s = std::min(d[j] * scale, static_cast<double>(kBins - 1));
    bn[j] = static_cast<uint8_t>(static_cast<int>(d[j] <= limit2 ? s : static_cast<double>(kBins)));
  }
  uint32_t counts[4][kBins + 1] = {};
  size_t j = 0;
  for (; j + 4 <= m; j += 4) {
    ++counts[0][bn[j]];
    ++counts[1][bn[j + 1]];
    ++counts[2][bn[j + 2]];
    ++counts[3][bn[j + 3]];
  }
  for (; j < m; ++j) ++counts[0][bn[j]];
  uint32_t count[kBins + 1];
  for (int b = 0; b <= kBins; ++b) count[b] = counts[0][b] + counts[1][b] + counts[2][b] + counts[3][b];
  size_t below = 0;
  int last = 0;  // the bin holding the k-th nearest
  while (last < kBins && below + count[last] < k) below += count[last++];
  if (last == kBins) return -1;
  // Slots of the nearer bins are all in; those of bin `last` are selected from.
  // One pass keeps the slots up to bin `last`, a short one moves those of `last` apart.
  out.resize(m);
  size_t o = 0;
  for (size_t i = 0; i < m; ++i) {
    out[o] = static_cast<uint32_t>(i);
    o += bn[i] <= last ? 1 : 0;
  }
  part.resize(o);
  size_t q = 0, kept = 0;
  for (size_t i = 0; i < o; ++i) {
    const uint32_t slot = out[i];
    out[kept] = slot;
    part[q] = slot;
    const bool in_last = bn[slot] == last;
    kept += in_last ? 0 : 1;
    q += in_last ? 1 : 0;
  }
  o = kept;
  const size_t need = k - below;
  part_d2.resize(q);
  for (size_t i = 0; i < q; ++i) part_d2[i] = d2[part[i]];
  std::nth_element(part_d2.begin(), part_d2.begin() + static_cast<long>(need - 1), part_d2.begin() + static_cast<long>(q));
  const double t = part_d2[need - 1];
  size_t ties = 1;  // how many at exactly t belong to the k: the lowest slots
  for (size_t i = 0; i + 1 < need; ++i) ties += part_d2[i] == t ? 1 : 0;
  out.resize(o + q);
  for (size_t i = 0; i < q; ++i) {
    const double dd = d2[part[i]];
    const bool tie = dd == t && ties > 0;
    out[o] = part[i];
    o += (dd < t || tie) ? 1 : 0;
    ties -= tie ? 1 : 0;
  }
  out.resize(o);
  return t;
}

namespace {

// One point per cell: the mean of the points of `in` that cell_of puts in it and of
// each attribute they carry. Cells are numbered 0 .. cells - 1; `who` names the caller
// in errors.
VoxelMeans meansOver(const Cloud& in, std::vector<uint32_t> cell_of, size_t cells, const char* who) {
  VoxelMeans out;
  out.cloud.viewpoint = in.viewpoint;
  out.voxel_of = std::move(cell_of);
  out.count.assign(cells, 0);
  std::vector<Vec3> sum(cells, Vec3::Zero());
  for (size_t i = 0; i < in.size(); ++i) {
    sum[out.voxel_of[i]] += in.points[i];
    ++out.count[out.voxel_of[i]];
  }
  out.cloud.points.resize(cells);
  for (size_t v = 0; v < cells; ++v) out.cloud.points[v] = sum[v] / static_cast<double>(out.count[v]);
  auto average = [&](const auto& values, auto& means) {
    if (values.empty()) return;
    if (values.size() != in.size())
      throw InvalidInput(std::string("[") + who + "] an attribute has " + std::to_string(values.size()) + " values for " +
                         std::to_string(in.size()) + " points");
    std::vector<double> total(cells, 0.0);
    for (size_t i = 0; i < in.size(); ++i) total[out.voxel_of[i]] += static_cast<double>(values[i]);
    means.resize(cells);
    for (size_t v = 0; v < cells; ++v)
      means[v] = static_cast<typename std::decay_t<decltype(means)>::value_type>(total[v] / out.count[v]);
  };
  average(in.intensity, out.cloud.intensity);
  average(in.alpha_rad, out.cloud.alpha_rad);
  average(in.beta_rad, out.cloud.beta_rad);
  return out;
}

}  // namespace

VoxelMeans voxelMeans(const Cloud& in, double voxel_m) {
  if (!(voxel_m > 0) || !std::isfinite(voxel_m))
    throw InvalidInput("[voxelMeans] voxel must be > 0 and finite (got " + std::to_string(voxel_m) + " m)");
  KeyIds ids(in.size() / 4);
  std::vector<uint32_t> cell_of(in.size());
  for (size_t i = 0; i < in.size(); ++i) cell_of[i] = ids.idOf(voxelKey(in.points[i], voxel_m));
  return meansOver(in, std::move(cell_of), ids.size(), "voxelMeans");
}

VoxelMeans columnMeans(const Cloud& in, const Eigen::Matrix3d& axes, double across_m, double max_depth_m) {
  if (!(across_m > 0) || !std::isfinite(across_m) || !(max_depth_m >= 0) || !std::isfinite(max_depth_m))
    throw InvalidInput("[columnMeans] need a column width > 0 and a depth >= 0, both finite (got " +
                       std::to_string(across_m) + " m and " + std::to_string(max_depth_m) + " m)");
  const Vec3 normal = axes.col(0);
  // Plane coordinates scaled to columns one unit wide; the depth axis collapses.
  Eigen::Matrix3d to_column = axes.transpose() / across_m;
  to_column.row(0).setZero();
  KeyIds ids(in.size() / 4);
  std::vector<uint32_t> column_of(in.size());
  std::vector<double> low, high;
  for (size_t i = 0; i < in.size(); ++i) {
    const uint32_t c = ids.idOf(voxelKey(to_column * in.points[i], 1.0));
    const double depth = normal.dot(in.points[i]);
    if (c == low.size()) {
      low.push_back(depth);
      high.push_back(depth);
    }
    low[c] = std::min(low[c], depth);
    high[c] = std::max(high[c], depth);
    column_of[i] = c;
  }
  // Cells in the order first met: a shallow column is one, a deep one a cell per point.
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> cell_of_column(low.size(), kNone);
  std::vector<uint32_t> cell_of(in.size());
  uint32_t cells = 0;
  for (size_t i = 0; i < in.size(); ++i) {
    const uint32_t c = column_of[i];
    if (high[c] - low[c] > max_depth_m) {
      cell_of[i] = cells++;
    } else {
      if (cell_of_column[c] == kNone) cell_of_column[c] = cells++;
      cell_of[i] = cell_of_column[c];
    }
  }
  return meansOver(in, std::move(cell_of), cells, "columnMeans");
}

}  // namespace sailshape
