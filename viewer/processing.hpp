#pragma once
// The processing tabs (ROI, filters, transform, normals, segmentation,
// surface, sections): their parameters and what Run computes. The stages chain
// in that order; Run on a tab runs every stage up to it from the stored cloud,
// so each tab's result reflects the parameters of all earlier tabs.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/pipeline/pipeline.hpp"
#include "database/sqlite.hpp"

namespace sailshape {
struct ScanRecord;  // database/scan_record.hpp
}  // namespace sailshape

namespace sailshape::viewer {

enum class ProcessingStage { Roi, Filters, Transform, Normals, Segmentation, Surface, Sections };
const char* stageName(ProcessingStage stage);
const std::vector<ProcessingStage>& allStages();

// Axis-aligned crop box in the cloud's frame, metres.
struct RoiBox {
  bool enabled = false;
  Vec3 min_m{-30.0, -30.0, -5.0}, max_m{30.0, 30.0, 40.0};
};

// Applied after the filters: p' = Rz(yaw)·Ry(pitch)·Rx(roll)·p + t (degrees, metres),
// e.g. to bring a scanner-frame cloud into the boat frame.
struct CloudTransform {
  double roll_deg = 0, pitch_deg = 0, yaw_deg = 0;
  Vec3 translation_m = Vec3::Zero();
  bool identity() const;
};

struct ProcessingParams {
  RoiBox roi;
  CloudTransform transform;
  // Every pipeline parameter; the Filters tab owns statistical/radius outliers
  // (run before the transform up to the segmentation stage; the surface and
  // sections stages run them inside analyzeSail), the later stages the rest.
  AnalysisParams analysis;
};

struct StageResult {
  ProcessingStage stage = ProcessingStage::Roi;
  Cloud cloud;                          // the points after the stage, for display
  std::vector<double> scalar;           // per point: curvature (normals) or cluster rank (segmentation, −1 none)
  std::string scalar_name;
  std::optional<SailAnalysis> analysis; // surface and sections stages
  std::vector<std::string> summary;     // lines shown under the tab's Run button
  std::vector<std::string> warnings;
};

// Throws InvalidInput when min > max on an axis, AnalysisError when nothing is left.
Cloud cropToBox(const Cloud& cloud, const RoiBox& roi);
Cloud transformCloud(const Cloud& cloud, const CloudTransform& transform);

// Runs the chain up to `stage`. Throws InvalidInput for an empty cloud or bad
// parameters, AnalysisError when a stage cannot produce its result.
StageResult runStages(const Cloud& input, const ProcessingParams& params, ProcessingStage stage,
                      const Progress& progress = {});

// For a re-analysis of `record`'s stored cloud: when `params` set no beam and the
// scan's stored settings name the unit's scanner model, sets that model's beam
// (acquisition/sensor_model useScannerBeam), so the edges move out by its
// footprint as the scan's first analysis did. Needs the cloud's viewpoint.
// Returns the model's name ("lms511"), empty when it set nothing.
std::string useScanBeam(ProcessingParams& params, const ScanRecord& record);

// Stores a surface/sections result as a new analysis of `scan_id` (the scan
// keeps its earlier analyses). Throws InvalidInput when the result has no analysis.
int64_t saveStageResult(Database& db, int64_t scan_id, const StageResult& result, const ProcessingParams& params);

}  // namespace sailshape::viewer
