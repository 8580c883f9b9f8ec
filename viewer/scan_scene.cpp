#include "viewer/scan_scene.hpp"

#include <numeric>

#include "analysis/core/errors.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "viewer/worker.hpp"

namespace sailshape::viewer {

Cloud thinCloud(const Cloud& cloud, size_t max_points) {
  if (max_points == 0) throw InvalidInput("[thinCloud] max_points must be > 0");
  if (cloud.size() <= max_points) return cloud;
  const size_t step = (cloud.size() + max_points - 1) / max_points;
  std::vector<uint32_t> keep;
  keep.reserve(cloud.size() / step + 1);
  for (size_t i = 0; i < cloud.size(); i += step) keep.push_back(static_cast<uint32_t>(i));
  return selectPoints(cloud, keep);
}

namespace {

// The stored scan as its sail: within its stored region (where the sail flies) and
// picked by its design when there is one; a scan stored without a region, within the
// options' box.
SailAnalysis analyzeStoredScan(const Cloud& cloud, const std::optional<ScanRegion>& region, const Mesh* design,
                               const SceneOptions& options, const Progress& progress) {
  if (region && design && !design->empty()) return analyzeInRegion(cloud, region->box, *design, options.analysis, progress);
  const Cloud clean = withoutMixedPixels(cloud, options.analysis);
  return analyzeSail(region ? cropToRegion(clean, region->box) : cropToBox(clean, options.roi), options.analysis, progress);
}

}  // namespace

ScanScene buildScanScene(ScanRecord record, std::optional<Mesh> design, const SceneOptions& options,
                         const Progress& progress) {
  ScanScene scene;
  if (record.cloud) {
    progress("load cloud", 0.0);
    scene.raw_cloud = thinCloud(*record.cloud, options.max_cloud_points);
    if (options.analyze_cloud) {
      try {
        scene.analysis = analyzeStoredScan(*record.cloud, record.region, design ? &*design : nullptr, options, progress);
        scene.surface = scene.analysis->mesh;
      } catch (const Cancelled&) {
        throw;
      } catch (const std::exception& e) {
        scene.analysis_error = e.what();
        scene.warnings.push_back(std::string(record.surface ? "sail cluster" : "flying surface") +
                                 ": the pipeline failed on the stored cloud: " + e.what());
      }
    }
    record.cloud.reset();
  } else {
    scene.warnings.push_back("the scan has no stored cloud: sections only");
  }
  // The surface stored with the analysis is the one its sections were cut from (and the
  // report draws): it is shown, and the deviation measured on it, whatever a re-analysis finds.
  if (record.surface && !record.surface->empty()) scene.surface = std::move(*record.surface);
  record.surface.reset();
  scene.sections = record.sections;
  if (scene.sections.sections.empty() && scene.analysis) scene.sections = scene.analysis->sections;
  scene.record = std::move(record);

  if (!design || design->empty()) {
    if (scene.record.has_design) scene.warnings.push_back("the design mesh could not be read");
    return scene;
  }
  scene.design = std::move(*design);
  try {
    const DesignDistance distance(scene.design);
    if (!scene.surface.empty()) {
      scene.surface_deviation_m = signedDistances(distance, scene.surface.vertices, progress);
      scene.deviation = distanceStats(scene.surface_deviation_m);
    }
    if (scene.analysis && !scene.analysis->sail_cloud.empty())
      scene.cluster_deviation_m = signedDistances(distance, scene.analysis->sail_cloud.points, progress);
    if (!scene.raw_cloud.empty()) {
      scene.raw_deviation_m = signedDistances(distance, scene.raw_cloud.points, progress);
      if (!scene.deviation) scene.deviation = distanceStats(scene.raw_deviation_m);
    }
    for (const auto& w : distance.warnings()) scene.warnings.push_back("design: " + w);
    if (options.fit_design && !scene.surface.empty()) {
      progress("fitting the design", 0.0);
      scene.fitted = fitDesign(scene.design, scene.surface.vertices, {}, progress);
      scene.fitted_move_m = vertexMoves(scene.design, *scene.fitted, distance.leeward()).normal_m;
    }
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception& e) {
    scene.warnings.push_back(std::string("deviation from design: ") + e.what());
  }

  if (options.design_sections && !scene.sections.sections.empty()) {
    progress("design sections", 0.0);
    try {
      SectionParams sp;
      for (const auto& s : scene.sections.sections) sp.fractions.push_back(s.fraction);
      for (const auto& u : scene.sections.unmeasured) sp.fractions.push_back(u.fraction);
      const MeshSections ms = analyzeMeshSections(scene.design, OutlineParams{}, sp);
      scene.design_sections = ms.sections;
      scene.deltas = sectionDeltas(scene.design_sections, scene.sections);
      if (scene.analysis && scene.deviation)
        scene.design_mismatch = designMismatch(scene.design, ms, *scene.analysis, *scene.deviation);
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      scene.warnings.push_back(std::string("design sections: ") + e.what());
    }
  }
  progress("done", 1.0);
  return scene;
}

}  // namespace sailshape::viewer
