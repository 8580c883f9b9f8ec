#pragma once
// Nearest-neighbour search over a fixed set of points (k-d tree, nanoflann inside).
#include <cstdint>
#include <memory>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

class KdTree {
 public:
  // Keeps a reference to `points`: they must outlive the tree and not change.
  explicit KdTree(const std::vector<Vec3>& points);
  ~KdTree();
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  // The k nearest points to q (fewer if the cloud is smaller), closest first;
  // squared distances in m².
  void nearest(const Vec3& q, size_t k, std::vector<uint32_t>& indices, std::vector<double>& dist2) const;
  // Every point within `radius_m` of q, closest first.
  void withinRadius(const Vec3& q, double radius_m, std::vector<uint32_t>& indices,
                    std::vector<double>& dist2) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The k nearest neighbours of every point, the point itself first. Row i holds
// point i's neighbours: index[i*k + j], squared distance dist2[i*k + j] (m²).
struct NeighbourTable {
  size_t k = 0;
  std::vector<uint32_t> index;
  std::vector<float> dist2;

  size_t size() const { return k == 0 ? 0 : index.size() / k; }
  const uint32_t* row(size_t i) const { return index.data() + i * k; }
  const float* rowDist2(size_t i) const { return dist2.data() + i * k; }
};

// The same queries as KdTree from a uniform grid of cubic cells `cell_m` wide, each
// cell's points stored together: on a scanned surface with cells about the
// k-th neighbour distance wide a query reads a few hundred points from nine or
// so cells instead of walking a tree, several times faster. Exact (rings of
// cells are added until no closer point can remain); ties go to the lower index.
class PointGrid {
 public:
  // Keeps a reference to `points`: they must outlive the grid and not change.
  // Throws InvalidInput when cell_m is not > 0.
  PointGrid(const std::vector<Vec3>& points, double cell_m);
  ~PointGrid();
  PointGrid(const PointGrid&) = delete;
  PointGrid& operator=(const PointGrid&) = delete;

  double cellSize() const;
  // Same contract as KdTree::nearest.
  void nearest(const Vec3& q, size_t k, std::vector<uint32_t>& indices, std::vector<double>& dist2) const;
  // Every point within `radius_m` of q, in the grid's storage order (not sorted;
  // the same order every run); with `points`, their coordinates too (read from
  // the grid's cell-ordered copy, cheaper than gathering them by index).
  void withinRadius(const Vec3& q, double radius_m, std::vector<uint32_t>& indices, std::vector<double>& dist2,
                    std::vector<Vec3>* points = nullptr) const;
  // Row i of `table` (k columns) for every point i of the grid's own cloud, as
  // nearestNeighbours() lays it out.
  void fillTable(NeighbourTable& table, size_t k, const Progress& progress) const;

  // The grid's occupied cells, in its storage (Morton) order: cell c holds the
  // points cellPoints()[cellStart()[c] .. cellStart()[c + 1]) (indices into
  // `points`), all within half a cell width of cellCentre(c) along each axis. A batch
  // of queries can go cell by cell and share what it gathers around each cell.
  size_t cellCount() const;
  const std::vector<uint32_t>& cellStart() const;
  const std::vector<uint32_t>& cellPoints() const;
  Vec3 cellCentre(size_t c) const;
  // Every point of every cell that withinRadius(q, radius_m) reads for a query q in
  // cell c, in the order it reads them, with their coordinates: filtering these by
  // distance gives that call's answer, in its order, without searching the cells again.
  void cellNeighbourhood(size_t c, double radius_m, std::vector<uint32_t>& indices, std::vector<Vec3>& points) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A grid over `points` with cells about 1.5 × the median distance to the k-th
// neighbour wide (estimated from a sample), the width k-nearest queries run fastest at.
std::unique_ptr<PointGrid> gridForNeighbours(const std::vector<Vec3>& points, size_t k);

// The k nearest neighbours of every point (see NeighbourTable), from a PointGrid.
// Throws InvalidInput when k < 1 or the cloud has fewer than k points.
NeighbourTable nearestNeighbours(const std::vector<Vec3>& points, size_t k, const Progress& progress = {});

// The table of the sub-cloud {points[kept[0]], points[kept[1]], ...} (`kept`
// ascending, indices into `points`) with k columns, from `table` of the whole
// cloud: each row keeps its kept neighbours in order; a row left with fewer than
// k is searched again. The same rows nearestNeighbours() gives on the sub-cloud.
// Throws InvalidInput when k exceeds table.k or the sub-cloud, or `kept` is not
// ascending within the table.
NeighbourTable subsetTable(const NeighbourTable& table, const std::vector<Vec3>& points,
                           const std::vector<uint32_t>& kept, size_t k);

// Median distance from each point to its nearest other point, m (0 for < 2 points).
double medianSpacing(const NeighbourTable& table);

// Median distance to the k-th nearest point (the point itself counts as the
// first), over about `samples` points spread through `points`, m.
double medianNeighbourDistance(const KdTree& tree, const std::vector<Vec3>& points, size_t k, size_t samples = 512);
double medianNeighbourDistance(const PointGrid& grid, const std::vector<Vec3>& points, size_t k, size_t samples = 512);
// Whether medianNeighbourDistance(grid, points, 2, samples) < limit_m (the median
// distance from the same sample of points to their nearest other point), answered
// from cells limit_m wide around the samples instead of a grid: one pass hashing
// the points, no sorting, several times cheaper for a yes-or-no on a large cloud.
bool medianNeighbourDistanceBelow(const std::vector<Vec3>& points, double limit_m, size_t samples = 512);

// Integer cell of a uniform grid of cubes `size` metres wide, and its key: the
// three cell indices packed 21 bits each, so distinct cells within 2^20 cells of
// the origin on every axis (20 km at 2 cm) have distinct keys. (A hash that mixed
// them by XOR gave mirrored cells, (x, y, z) and (−x, −y, z), one key: around a
// boat frame's origin at the mast foot, sail and mast samples shared voxels.)
Eigen::Vector3i voxelOf(const Vec3& p, double size);
int64_t voxelKey(const Eigen::Vector3i& cell);
inline int64_t voxelKey(const Vec3& p, double size) { return voxelKey(voxelOf(p, size)); }

// One point per occupied voxel of a grid `voxel_m` wide (voxelOf's cells): the mean
// of its points and of each attribute they carry, in the order the voxels are first
// met; with each input point's voxel and each voxel's count. Throws InvalidInput for
// a voxel that is not positive and finite.
struct VoxelMeans {
  Cloud cloud;                     // keeps the input's viewpoint
  std::vector<uint32_t> voxel_of;  // per input point
  std::vector<uint32_t> count;     // per voxel
};
VoxelMeans voxelMeans(const Cloud& cloud, double voxel_m);

// The same over square columns `across_m` wide standing on a plane (`axes`' columns:
// col(0) its normal, as PrincipalAxes gives them). A cube voxel about as wide as the
// range noise cuts a noisy surface's samples apart by their noise, and the means of
// the parts lie off the surface by about ±0.8σ; a column holds the whole noise band.
// A column whose points lie more than `max_depth_m` apart along the normal (the
// surface steep in it, or two sheets over one another) is not merged: each of its
// points is a cell of its own. Throws InvalidInput for a width that is not positive
// and finite or a depth that is negative or not finite.
VoxelMeans columnMeans(const Cloud& cloud, const Eigen::Matrix3d& axes, double across_m, double max_depth_m);

// Of the slots j with d2[j] <= limit2, the k nearest by (distance², slot) into
// `out`; returns the k-th distance², or -1 when fewer than k lie within limit2.
// The squared distances are counted in bins of limit2 / kBins (a sample spread
// evenly over a surface spreads its squared distances evenly too), and only the
// bin holding the k-th is selected from: one pass over the candidates instead of
// the several a general selection makes. `out` holds the nearer bins' slots in
// ascending order, then the rest; `bin`, `part` and `part_d2` are scratch.
double selectNearest(const std::vector<double>& d2, double limit2, size_t k, std::vector<uint8_t>& bin,
                     std::vector<uint32_t>& part, std::vector<double>& part_d2, std::vector<uint32_t>& out);

// Dense ids 0, 1, 2, ... for int64 keys (voxel keys) in the order they are first
// seen: an open-addressing table, several times faster than std::unordered_map
// for the hundreds of thousands of keys of a cloud.
class KeyIds {
 public:
  explicit KeyIds(size_t expected_keys = 16);
  // The key's id; a key not seen before gets the next id (size() before the call).
  uint32_t idOf(int64_t key);
  // The key's id without adding it; false for a key not seen.
  bool find(int64_t key, uint32_t& id) const;
  size_t size() const { return ids_; }

 private:
  void grow();
  std::vector<int64_t> key_;
  std::vector<uint32_t> id_;  // kFree where no key is stored
  size_t ids_ = 0;
  int shift_ = 60;
};

}  // namespace sailshape
