#include "viewer/processing.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/params_io.hpp"
#include "database/import.hpp"
#include "viewer/unit_camera.hpp"

namespace sailshape::viewer {
namespace {

std::string count(const char* what, size_t n) { return std::string(what) + ": " + std::to_string(n) + " points"; }

}  // namespace

const char* stageName(ProcessingStage stage) {
  static const char* const names[] = {"ROI", "Filters", "Transform", "Normals", "Segmentation", "Surface", "Sections"};
  return names[static_cast<int>(stage)];
}

const std::vector<ProcessingStage>& allStages() {
  static const std::vector<ProcessingStage> stages = {
      ProcessingStage::Roi,     ProcessingStage::Filters,      ProcessingStage::Transform, ProcessingStage::Normals,
      ProcessingStage::Segmentation, ProcessingStage::Surface, ProcessingStage::Sections};
  return stages;
}

bool CloudTransform::identity() const {
  return roll_deg == 0 && pitch_deg == 0 && yaw_deg == 0 && translation_m.isZero();
}

Cloud cropToBox(const Cloud& cloud, const RoiBox& roi) {
  for (int a = 0; a < 3; ++a)
    if (!(roi.min_m[a] <= roi.max_m[a]))
      throw InvalidInput("[cropToBox] min must not exceed max on axis " + std::string(1, "xyz"[a]) + " (got " +
                         std::to_string(roi.min_m[a]) + " > " + std::to_string(roi.max_m[a]) + ")");
  if (!roi.enabled) return cloud;
  std::vector<uint32_t> keep;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    if ((p.array() >= roi.min_m.array()).all() && (p.array() <= roi.max_m.array()).all())
      keep.push_back(static_cast<uint32_t>(i));
  }
  if (keep.empty()) throw AnalysisError("[cropToBox] no point of the " + std::to_string(cloud.size()) + " lies in the box");
  return selectPoints(cloud, keep);
}

Cloud transformCloud(const Cloud& cloud, const CloudTransform& t) {
  const double k = kRadPerDeg;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(t.yaw_deg * k, Vec3::UnitZ()) *
                             Eigen::AngleAxisd(t.pitch_deg * k, Vec3::UnitY()) *
                             Eigen::AngleAxisd(t.roll_deg * k, Vec3::UnitX()))
                                .toRotationMatrix();
  Cloud out = cloud;
  for (Vec3& p : out.points) p = r * p + t.translation_m;
  if (out.viewpoint) *out.viewpoint = r * *out.viewpoint + t.translation_m;
  return out;
}

StageResult runStages(const Cloud& input, const ProcessingParams& params, ProcessingStage stage,
                      const Progress& progress) {
  if (input.empty()) throw InvalidInput("[runStages] empty cloud");
  StageResult r;
  r.stage = stage;
  const AnalysisParams& ap = params.analysis;

  Cloud cloud = cropToBox(input, params.roi);
  r.summary.push_back(count("after ROI", cloud.size()));
  // The surface and sections stages leave the filters to analyzeSail, whose cleaning
  // gives back the surface points they removed and lets the corners test the rest,
  // as `sailshape analyze` does: filtered here, the statistical test would take a
  // corner's lone samples and cut a narrow head short. The filters measure
  // distances only, so running them after the transform changes nothing.
  const bool analyse = stage >= ProcessingStage::Surface;
  if (stage >= ProcessingStage::Filters && !analyse) {
    if (ap.statistical_outliers) {
      const Cleaning c = removeStatisticalOutliers(cloud, ap.statistical, progress);
      cloud = selectPoints(cloud, c.kept);
      r.warnings.insert(r.warnings.end(), c.warnings.begin(), c.warnings.end());
    }
    if (ap.radius_outliers) {
      const Cleaning c = removeRadiusOutliers(cloud, ap.radius, progress);
      cloud = selectPoints(cloud, c.kept);
      r.warnings.insert(r.warnings.end(), c.warnings.begin(), c.warnings.end());
    }
    r.summary.push_back(count("after filters", cloud.size()));
  }
  if (stage >= ProcessingStage::Transform && !params.transform.identity()) {
    cloud = transformCloud(cloud, params.transform);
    r.summary.push_back("transformed to the boat frame");
  }
  if (stage == ProcessingStage::Normals || stage == ProcessingStage::Segmentation) {
    const NormalEstimation n = estimateNormals(cloud, ap.normals, progress);
    r.warnings.insert(r.warnings.end(), n.warnings.begin(), n.warnings.end());
    if (stage == ProcessingStage::Normals) {
      r.scalar = n.normals.curvature;
      r.scalar_name = "curvature";
      r.summary.push_back("normals oriented: " + n.orientation + ", " + std::to_string(n.flipped) + " flipped");
    } else {
      const Segmentation seg = growRegions(cloud, n.normals, ap.region_growing, progress);
      r.warnings.insert(r.warnings.end(), seg.warnings.begin(), seg.warnings.end());
      r.scalar.assign(cloud.size(), -1.0);
      for (size_t c = 0; c < seg.clusters.size(); ++c)
        for (uint32_t i : seg.clusters[c]) r.scalar[i] = static_cast<double>(c);
      r.scalar_name = "cluster";
      r.summary.push_back(std::to_string(seg.clusters.size()) + " clusters, " + std::to_string(seg.unassigned.size()) +
                          " points unassigned");
      const SailPick pick = pickSailCluster(cloud, seg, ap.sail_pick);
      r.warnings.insert(r.warnings.end(), pick.warnings.begin(), pick.warnings.end());
      r.summary.push_back("sail: cluster " + std::to_string(pick.cluster) + " (" +
                          std::to_string(seg.clusters[pick.cluster].size()) + " points)");
    }
  }
  if (analyse) {
    SailAnalysis a = analyzeSail(cloud, ap, progress);
    const StageReport* cleaned = nullptr;
    for (const StageReport& s : a.stages)
      if (s.name == "statistical outliers" || s.name == "radius outliers" || s.name == "readmit surface points")
        cleaned = &s;
    if (cleaned) r.summary.push_back(count("after filters", cleaned->points_out));
    r.summary.push_back(count("sail", a.sail_points));
    char area[96];
    std::snprintf(area, sizeof area, "%zu triangles, area %.2f m²", a.mesh.triangles.size(), a.outline.area_m2);
    r.summary.push_back(area);
    if (a.outline.footprint_reach_m > 0) {
      char moved[96];
      std::snprintf(moved, sizeof moved, "edges moved out by the beam's footprint, %.1f cm", 100 * a.outline.footprint_reach_m);
      r.summary.push_back(moved);
    }
    r.summary.push_back(std::to_string(a.sections.sections.size()) + " sections");
    r.warnings.insert(r.warnings.end(), a.warnings.begin(), a.warnings.end());
    cloud = a.sail_cloud;
    r.analysis = std::move(a);
  }
  r.cloud = std::move(cloud);
  return r;
}

std::string useScanBeam(ProcessingParams& params, const ScanRecord& record) {
  if (!record.cloud) return {};
  const std::optional<UnitConfig> unit = scanUnit(record);
  if (!unit || !useScannerBeamUnlessGiven(params.analysis.outline, unit->model, *record.cloud)) return {};
  return scannerModelName(unit->model);
}

int64_t saveStageResult(Database& db, int64_t scan_id, const StageResult& result, const ProcessingParams& params) {
  if (!result.analysis)
    throw InvalidInput(std::string("[saveStageResult] the ") + stageName(result.stage) +
                       " stage has no analysis to save (run Surface or Sections)");
  nlohmann::json doc = analysisToJson(*result.analysis);
  nlohmann::json p = paramsToJson(params.analysis);
  if (params.roi.enabled)
    p["viewer_roi_m"] = {{"min", {params.roi.min_m.x(), params.roi.min_m.y(), params.roi.min_m.z()}},
                         {"max", {params.roi.max_m.x(), params.roi.max_m.y(), params.roi.max_m.z()}}};
  if (!params.transform.identity())
    p["viewer_transform"] = {{"roll_deg", params.transform.roll_deg},
                             {"pitch_deg", params.transform.pitch_deg},
                             {"yaw_deg", params.transform.yaw_deg},
                             {"translation_m",
                              {params.transform.translation_m.x(), params.transform.translation_m.y(),
                               params.transform.translation_m.z()}}};
  doc["parameters"] = p;
  return addAnalysis(db, scan_id, doc, "0.1.0", &result.analysis->mesh);
}

}  // namespace sailshape::viewer
