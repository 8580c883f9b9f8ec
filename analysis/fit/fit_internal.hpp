#pragma once
// What design_fit.cpp and deformation.cpp share: the design mesh's connectivity, the
// samples' correspondences on the deforming surface, and one step of the non-rigid solve.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"

namespace sailshape::fit_detail {

// Connectivity of a triangle mesh, in compressed rows (row i: [start[i], start[i + 1])).
struct Topology {
  std::vector<std::array<uint32_t, 2>> edges;      // unique, i < j
  std::vector<std::array<int64_t, 2>> edge_triangles;  // per edge: its one or two triangles (-1: none)
  std::vector<uint32_t> ring_start, ring;          // per vertex: its neighbours
  std::vector<uint32_t> fan_start, fan;            // per vertex: its triangles
};
Topology meshTopology(const Mesh& mesh);

// One sample's foot on the surface: triangle, barycentric weights, point, unit normal.
struct Foot {
  int64_t triangle = -1;  // -1: none found
  Eigen::Vector3d bary = Eigen::Vector3d::Zero();
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  double distance_m = 0;
};
// The closest point of the surface `vertices` (topology `top`, triangles of `mesh`) to each
// sample, searched in the fans of the two vertices nearest it.
std::vector<Foot> findFeet(const Mesh& mesh, const std::vector<Vec3>& vertices, const Topology& top,
                           const std::vector<Vec3>& samples);

// The membrane and bending regulariser of the design (see deformation.cpp), fixed for a fit.
struct Regulariser;
struct RegulariserDeleter {
  void operator()(Regulariser* r) const;
};
using RegulariserPtr = std::unique_ptr<Regulariser, RegulariserDeleter>;
RegulariserPtr buildRegulariser(const Mesh& design, const Topology& top, double membrane_length_m,
                                double bending_length_m);

// The factorisation the global steps share: the system's sparsity is the regulariser's every
// iteration (the data couple only vertices of one triangle, which the membrane couples too),
// so its ordering is computed once.
struct StepSolver;
struct StepSolverDeleter {
  void operator()(StepSolver* s) const;
};
using StepSolverPtr = std::unique_ptr<StepSolver, StepSolverDeleter>;
StepSolverPtr makeStepSolver();

// One global step: the vertices minimising data + stiffness · regulariser, with the
// rotations read from `current` (the local step) and the samples held to their feet's
// tangent planes. `use[s]` says whether sample s counts; `sample_area_m2` is the area
// each sample stands for.
std::vector<Vec3> deformStep(const Regulariser& reg, const Mesh& design, const Topology& top,
                             const std::vector<Vec3>& current, const std::vector<Vec3>& samples,
                             const std::vector<Foot>& feet, const std::vector<char>& use, double sample_area_m2,
                             double stiffness, StepSolver& solver);

// Area of each vertex's share of its triangles (a third of each), m².
std::vector<double> vertexAreas(const Mesh& mesh);

}  // namespace sailshape::fit_detail
