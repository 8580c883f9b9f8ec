#pragma once
// The whole analysis of one flying-sail cloud (SPEC §4 steps 3–6):
// normals → segmentation → cleaning → smoothing → surface → outline → sections.
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/outline/sail_outline.hpp"
#include "analysis/sections/luff_curve.hpp"
#include "analysis/sections/sections.hpp"
#include "analysis/segmentation/cleaning.hpp"
#include "analysis/segmentation/mixed_pixels.hpp"
#include "analysis/segmentation/segmentation.hpp"
#include "analysis/segmentation/spars.hpp"
#include "analysis/spatial/normals.hpp"
#include "analysis/spatial/viewpoint_estimate.hpp"
#include "analysis/surface/smoothing.hpp"
#include "analysis/surface/surface.hpp"

namespace sailshape {

struct AnalysisParams {
  double sensor_sigma_m = 0.004;   // SPEC §3; feeds smoothing classes and uncertainties
  // A scan that carries its samples' scan angles and the scanner's position loses
  // its mixed pixels first (analysis/segmentation/mixed_pixels.hpp). Its sensor_sigma_m follows
  // the one above.
  bool mixed_pixels = true;
  MixedPixelParams mixed;
  // A cloud without the scanner's position (plain XYZ) has it estimated from how its
  // samples' density falls with range and obliquity (analysis/spatial/viewpoint_estimate.hpp),
  // so the outline can still tell where the scan merely stopped from where the sail ends.
  bool estimate_viewpoint = true;
  NormalParams normals;
  bool segment = true;             // false: the cloud is the sail alone, skip segmentation
  // Segmentation runs on a voxel-grid sample this many sensor σ wide when the
  // scan is denser (0: full resolution), so normals and curvature see the same
  // neighbourhood size relative to the noise whatever the scanner's density.
  double segmentation_voxel_sigmas = 5.0;
  // The working resolution (0: off, every sample goes on). With working_voxel_sigmas > 0, after
  // segmentation a scan with three samples or more per column on average goes on as one
  // point per occupied column, the mean of its samples (and of their attributes): as good
  // a point as a smoothing over them, and fewer points to carry. The columns stand square
  // on the sail's best-fit plane (square columns, not cube voxels: a cube's face running
  // along a noisy surface would cut its samples apart by their noise and put the means
  // off the surface), working_voxel_sigmas sensor σ wide (5: 2 cm) but never wider than
  // working_voxel_of_extent times the sail's bounding-box diagonal, so a model-scale sail
  // keeps its detail (a 40,000-point scan of a 10 m sail has its points 2.2 cm, 1/480 of
  // its 10.6 m diagonal, apart). A column whose samples lie more than
  // working_column_depth_sigmas σ apart along the plane's normal (the surface steeper
  // than about 45° to the plane there, or two sheets over one another) keeps every
  // sample. The corners still read the scan's own outermost samples.
  double working_voxel_sigmas = 5;
  double working_column_depth_sigmas = 12;
  double working_voxel_of_extent = 1.0 / 500;
  RegionGrowingParams region_growing;
  SailPickParams sail_pick;
  // Round spars (mast, boom) found beside the picked sail: points on them leave the
  // sail, and the sail's edge strip whose neighbourhoods mixed in spar points comes
  // back where it lies on the sail's surface. Its sensor_sigma_m follows the one above.
  bool find_spars = true;
  SparSearchParams spars;
  bool statistical_outliers = true;
  StatisticalOutlierParams statistical;
  bool radius_outliers = true;
  RadiusOutlierParams radius;
  bool readmit_surface_points = true;  // give back removed points that lie on the surface
  ReadmitParams readmit;
  bool smooth = true;
  SmoothingParams smoothing;
  SurfaceParams surface;
  OutlineParams outline;
  SectionParams sections;
};

struct StageReport {
  std::string name;
  size_t points_in = 0, points_out = 0;
  double seconds = 0;
  std::vector<std::string> warnings;
};

struct SailAnalysis {
  size_t points_in = 0;
  size_t sail_points = 0;            // scan points on the sail after segmentation and cleaning
  size_t working_points = 0;         // the points the stages after segmentation worked on
  double working_voxel_m = 0;        // their columns' width (0: the scan's own points)
  Cloud sail_cloud;                  // the smoothed sail points
  Mesh mesh;
  SailOutline outline;
  SectionAnalysis sections;
  LuffCurve luff;
  Smoothing smoothing_stats;         // displacement classes (cloud emptied to save memory)
  std::vector<ClusterInfo> clusters; // what segmentation found
  std::vector<SparFit> spars;        // round spars found beside the sail
  std::vector<StageReport> stages;
  std::vector<std::string> warnings; // every stage's warnings, prefixed by stage
  // Set when the scan alone gave no sections and the sail's design, fitted onto its samples,
  // stood in for what it did not reach (analysis/pipeline/design_prior.hpp): why the scan
  // alone refused, and the fit.
  std::string inferred_because;
  std::optional<DesignFit> design_fit;
  // Where the scanner stood, estimated from the samples' density, when the cloud did not
  // say (AnalysisParams::estimate_viewpoint); the outline's coverage was read from it.
  std::optional<ViewpointEstimate> viewpoint_estimate;
};

// p.mixed with p's sensor σ.
MixedPixelParams mixedPixelParams(const AnalysisParams& p);
// The scan less its mixed pixels (when it carries scan angles and a viewpoint and
// p.mixed_pixels is set), for a crop to the sail before analyzeSail: they are
// told by the surfaces on both sides of them, which the crop would cut off.
Cloud withoutMixedPixels(const Cloud& scan, const AnalysisParams& p);

// A corner whose samples' scan line has lost lines beside it (Cloud::lost_beta_rad:
// the sweep never received them) may lie a line spacing further out than the samples
// place it for each lost in a row; that, |corner − viewpoint| times the turntable's
// step between lines, joins the corner's σ. Needs the scan's angles and viewpoint;
// `scan` is the cloud the outline was found on, in its frame. Lost lines must be
// ascending, as sweeps write them. Returns a warning per corner widened.
std::vector<std::string> widenCornersBesideLostLines(SailOutline& outline, const Cloud& scan);

// The sail's own samples in a scene cloud, as analyzeSail finds them before it smooths:
// mixed pixels out, the sail's region segmented from spars, deck and walls (unless
// p.segment is false), outliers removed. For the design fit, which needs the samples
// themselves. Throws as analyzeSail does for the input and AnalysisError when no sail is found.
Cloud sailSamples(const Cloud& cloud, const AnalysisParams& params = {}, const Progress& progress = {});

// Throws InvalidInput for an empty cloud or bad parameters, AnalysisError when
// a stage cannot produce its result (no sail found, no boundary, ...). When the
// outline or the sections refuse (a patch of a sail, a scan that never reached a
// corner) and `surface_only` is given, it receives what was measured before the
// refusal, the sail's points and surface (sections empty; the outline too unless the
// sections refused it: its coverage says which corners the scan did not reach), and the
// AnalysisError is thrown on: distances to a design need no outline.
SailAnalysis analyzeSail(const Cloud& cloud, const AnalysisParams& params = {}, const Progress& progress = {},
                         SailAnalysis* surface_only = nullptr);

// The section parameters for cutting a.mesh: p.sections with p's sensor σ, and the noise
// model of a's smoothing (its neighbourhoods' radius and the smoothed surface's σ).
SectionParams sectionParamsFor(const AnalysisParams& p, const SailAnalysis& a);

// Throws AnalysisError for a length, area or section value that is not a number or that no
// measured sail has: a failure of the analysis to say so, not a result to report.
void refuseImplausibleResults(const SailAnalysis& a);

}  // namespace sailshape
