#pragma once
// The sail a scan was taken of: the region it flies in (its design's box grown by a
// margin), the analysis guided to the cluster that matches its design, and the check
// that what was found flies as that design could at some trim.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/pipeline/pipeline.hpp"

namespace sailshape {

// plausibleTrimDeviationM: analysis/design/design_compare.hpp.

// Axis-aligned, boat frame, metres.
using RegionBox = Eigen::AlignedBox3d;

// The design's bounding box grown by `margin_m` on every side. Throws InvalidInput for
// an empty design or a negative or non-finite margin.
RegionBox designRegion(const Mesh& design, double margin_m);
// XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX. Throws InvalidInput naming the problem for a count
// other than six, a value that is not a finite number, or min > max on an axis.
RegionBox parseRegionBox(const std::string& text);
std::string formatRegionBox(const RegionBox& box);  // as parseRegionBox reads it, mm resolution

// The points of `cloud` inside `box`, with their attributes, viewpoint and range.
// Throws AnalysisError when none is.
Cloud cropToRegion(const Cloud& cloud, const RegionBox& box);

// Points on the design's surface no farther apart than spacing_m (its vertices and
// points filling its larger triangles), for SailPickParams::design_points.
std::vector<Vec3> designSurfacePoints(const Mesh& design, double spacing_m);

// Sets `params` to pick the cluster that matches `design` (SailPickParams "design"
// within plausibleTrimDeviationM). The edge lengths are not made a stop
// (outline.design_lengths_m): designMismatch tells a sail far from its design.
void guideByDesign(AnalysisParams& params, const Mesh& design);

// The scan analysed as its sail: loses its mixed pixels on the whole scan (the
// surfaces behind tell them), is cropped to `region` and analysed with the pick guided
// by the design. Throws what analyzeSail and cropToRegion throw; `surface_only` as analyzeSail's.
SailAnalysis analyzeInRegion(const Cloud& scan, const RegionBox& region, const Mesh& design, AnalysisParams params,
                             const Progress& progress = {}, SailAnalysis* surface_only = nullptr);

// Whether the analysis found the sail it was asked for: empty when it flies as its
// design could at a plausible trim; otherwise one line saying how far off it is.
// Bounds: the RMS deviation beyond plausibleTrimDeviationM; the area beyond ±20 % of
// the design's (two edges each beyond their bound); an edge length beyond ±10 % of the
// design's (cloth stretch and halyard or cunningham tension change a luff by a few
// per cent) plus 3σ of the measured length.
std::string designMismatch(const Mesh& design, const MeshSections& design_sections, const SailAnalysis& flying,
                           const DistanceStats& deviation);

// designMismatch's bound on an edge: a measured length `flying_m` (1σ `sigma_m`) more than 10 %
// of the design's plus 3σ from `design_m`; > 0 longer, < 0 shorter, 0 within.
int edgeBeyondDesign(double flying_m, double design_m, double sigma_m);

}  // namespace sailshape
