#pragma once
// Surface reconstruction (SPEC §4 step 5): project the points to a 2D domain,
// Delaunay-triangulate there, lift the connectivity back to 3D and drop
// triangles with an edge longer than a threshold.
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

struct SurfaceParams {
  // "plane": the best-fit plane; "scan_angles": the scanner's (α, β) per point,
  // for strongly twisted or off-wind sails; "auto": scan_angles when present.
  std::string projection = "auto";
  double max_edge_m = 0.0;       // 0: max_edge_factor × median Delaunay edge length
  double max_edge_factor = 4.0;
  bool largest_component_only = true;
};

struct Surface {
  Mesh mesh;                     // vertices are the input points that some triangle uses
  std::vector<uint32_t> vertex_source;  // input index of each mesh vertex
  std::string projection;        // what was used
  double max_edge_m = 0;         // the threshold applied
  size_t delaunay_triangles = 0;       // proper ones: zero-area slivers between collinear points are skipped
  size_t dropped_long_edges = 0;
  size_t dropped_small_components = 0;
  std::vector<std::string> warnings;
};

// Throws InvalidInput for fewer than 3 points or an unknown projection, and
// AnalysisError when no triangle survives.
Surface reconstructSurface(const Cloud& cloud, const SurfaceParams& params = {}, const Progress& progress = {});

}  // namespace sailshape
