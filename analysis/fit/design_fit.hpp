#pragma once
// The design as a prior (issue 37): the design mesh deformed onto a flying sail's
// samples, its vertices kept in their order and its triangles unchanged. First a rigid
// alignment (point-to-plane ICP from the identity: designs arrive in the boat frame),
// then a non-rigid fit regularised like a membrane with bending stiffness: where the
// scan has samples the surface passes through them within the noise, where it has none
// the deformation continues smoothly from around. Every vertex carries its displacement
// from the design, its distance to the nearest sample and its σ.
#include <array>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

struct DesignFitParams {
  double sensor_sigma_m = 0.004;  // SPEC §3, for the robust gate and σ before the residuals are known
  bool rigid = true;              // refine the design's pose first (false: the design stands where it is)
  double rigid_max_correspondence_m = 0.3;
  // A design stands in the boat frame to within its rigging (rake, tack fitting): a few cm. A
  // rigid alignment that would move it further is a changed shape sliding along itself (a
  // deeper sail fits a design moved down), not a misplaced design: the design then stays.
  double rigid_max_move_m = 0.15;
  int outer_iterations = 8;       // correspondences found again, rotations and system solved again
  // The regulariser's two lengths. Against samples of density ρ and noise σ, a shape feature
  // shorter than bending_length_m bends less than the data ask (the fit smooths it), longer ones
  // follow the data; membrane_length_m does the same for in-plane stretch. Both only weigh the
  // regulariser against the data: where there are no samples the regulariser alone decides.
  double bending_length_m = 0.1;
  double membrane_length_m = 0.04;
  // The first iterations, far from the samples, are this many times stiffer (the stiffness
  // falls geometrically to 1 over the first half of the iterations), so wrong early
  // correspondences cannot fold the mesh.
  double initial_stiffness = 16;
  // A vertex within this distance of a sample is supported (0: three times the samples'
  // median spacing).
  double support_radius_m = 0;
  // How far the flying sail's camber may differ from the design's where nothing was seen, as a
  // fraction of the chord (0.03: 3 % of chord, a trim step's change). A parabolic section of
  // depth c·chord bends at 8c/chord, so the curvature may differ by Δκ = 8·0.03/chord, the
  // mean chord being the design's area over its height; σ grows as ½·Δκ·d² with the distance
  // d from the samples, besides the g·d of the slope's turn (see fitDesign), and never beyond the
  // vertex's move from the design plus half a plausible trim (plausibleTrimDeviationM).
  double camber_change_prior = 0.03;
  // Stretch beyond this (per-edge length change, %) is warned about: see fitDesign.
  double max_plausible_strain_pct = 5.0;
  // The scan lies "nowhere near" the design when the median distance of its samples to the
  // design exceeds this fraction of the design's bounding-box diagonal.
  double max_median_distance_of_extent = 0.25;
};

struct StrainStats {
  size_t edges = 0;
  double mean_pct = 0, rms_pct = 0, p5_pct = 0, p95_pct = 0, min_pct = 0, max_pct = 0;
};

struct DesignFit {
  Mesh fitted;                            // design's vertices moved, design's triangles
  Eigen::Matrix4d rigid = Eigen::Matrix4d::Identity();  // design → boat frame, from the rigid stage
  double rigid_rms_m = 0;                 // point-to-plane RMS of the rigid stage
  std::vector<Vec3> displacement_m;       // per vertex: fitted − design, m
  std::vector<double> support_distance_m; // per vertex: to the nearest sample, m
  std::vector<char> supported;            // per vertex: support_distance_m ≤ support_radius_m
  std::vector<double> sigma_m;            // per vertex: 1σ of the fitted position along the normal, m
  // Per vertex: 1σ of the fitted surface's slope where it was inferred (0 where supported: the
  // samples measure it there), rad.
  std::vector<double> slope_sigma_rad;
  // RMS angle between the fitted and the design's normals where supported, rad: how far the
  // flying surface's slope turned from the design's where it was seen.
  double turn_rad = 0;
  std::vector<double> edge_strain_pct;    // per mesh edge (edges order): length change from the design, %
  std::vector<std::array<uint32_t, 2>> edges;  // unique edges, i < j
  double support_radius_m = 0;
  double coverage = 0;                    // fraction of the design's area within support_radius_m of samples
  double rms_m = 0;                       // RMS distance of the samples used to the fitted surface
  size_t samples = 0, samples_used = 0;   // samples given, samples within the final robust gate
  double noise_m = 0;                     // robust σ of those distances (1.4826·MAD)
  StrainStats strain, strain_supported;   // every edge; edges with both ends supported
  int iterations = 0;
  std::vector<std::string> warnings;
};

// Throws InvalidInput for a design without triangles, an index out of range, no samples, a
// non-finite coordinate, bad parameters, or samples nowhere near the design (then they are not
// this sail, or not in its frame). A fit that stretched beyond max_plausible_strain_pct is a
// result with a warning.
DesignFit fitDesign(const Mesh& design, const std::vector<Vec3>& samples, const DesignFitParams& params = {},
                    const Progress& progress = {});

// Per design vertex, how the fit moved it: along the design's normal turned towards `leeward`
// (m, + to leeward) and the rest of its move, in the design's tangent plane (m, ≥ 0).
struct VertexMoves {
  std::vector<double> normal_m, along_m;
};
VertexMoves vertexMoves(const Mesh& design, const DesignFit& fit, const Vec3& leeward);

// Per fitted vertex: the mean length change of the edges it ends, % (the cloth's stretch there).
std::vector<double> vertexStretchPct(const DesignFit& fit);

}  // namespace sailshape
