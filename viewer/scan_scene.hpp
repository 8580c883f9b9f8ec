#pragma once
// What the 3D view and the panels show for one scan, computed off the UI
// thread: the flying surface (the pipeline run on the stored cloud), its signed
// deviation from the sail's design, and the design's sections at the flying
// sections' fractions.
#include <optional>
#include <string>
#include <vector>

#include "analysis/design/design_compare.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "database/scan_record.hpp"
#include "viewer/processing.hpp"

namespace sailshape::viewer {

struct SceneOptions {
  bool analyze_cloud = true;      // run the pipeline on the stored cloud for the flying surface
  AnalysisParams analysis;        // the pipeline's parameters for that run
  RoiBox roi;                     // the pipeline runs on the points inside (when enabled); the display keeps all
  bool design_sections = true;    // cut the design at the flying fractions (needed for the section table)
  bool fit_design = true;         // fit the design onto the flying surface (the "fitted design" layer)
  size_t max_cloud_points = 300'000;  // the raw cloud is thinned (every k-th point) above this for display
};

struct ScanScene {
  ScanRecord record;              // its cloud is moved to raw_cloud
  Cloud raw_cloud;                // as stored (thinned for display), boat frame, metres
  std::vector<double> raw_deviation_m;      // per raw_cloud point; empty without a design
  std::optional<SailAnalysis> analysis;     // the pipeline's run on the stored cloud
  std::string analysis_error;     // why that run failed (empty when it worked or did not run)
  std::vector<double> cluster_deviation_m;  // per analysis->sail_cloud point; empty without a design
  Mesh surface;                   // flying surface: stored with the analysis, else the re-analysis mesh; may be empty
  std::vector<double> surface_deviation_m;  // per surface vertex; empty without a design
  // The stored sections, or the fresh analysis's when the scan has none stored.
  SectionAnalysis sections;
  Mesh design;                    // empty when the sail has no design mesh
  SectionAnalysis design_sections;          // at the fractions of `sections`
  std::vector<SectionDelta> deltas;         // flying − design, per section
  std::optional<DistanceStats> deviation;   // of the surface (or the raw cloud without one)
  // Why the analysed sail is not the one its design describes (analysis/pipeline/
  // sail_region.hpp designMismatch), for the viewer to show in red; empty when it
  // flies as its design could at a plausible trim, or without an analysis or design.
  std::string design_mismatch;
  // The design fitted onto the flying surface (analysis/fit): the whole sail, where the scan reached
  // and where the fit carried the shape on from around (fitted->supported); per design vertex its
  // move along the design's normal, + to leeward. Empty without a design or a surface.
  std::optional<DesignFit> fitted;
  std::vector<double> fitted_move_m;
  std::vector<std::string> warnings;        // what could not be computed, and why
};

// Never throws for missing parts (no cloud, no design, a pipeline stage that
// fails): those become warnings and empty members. Throws Cancelled (worker.hpp)
// when the progress callback does.
ScanScene buildScanScene(ScanRecord record, std::optional<Mesh> design, const SceneOptions& options = {},
                         const Progress& progress = {});

// Every k-th point so that at most `max_points` remain (attributes kept).
Cloud thinCloud(const Cloud& cloud, size_t max_points);

}  // namespace sailshape::viewer
