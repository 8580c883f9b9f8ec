// The Processing tab: one tab per pipeline stage with its parameters, run on the
// selected scan's stored cloud, its result and saving it.
#include "viewer/app.hpp"

#include <cstdio>
#include <string>

#include "acquisition/sensor_model.hpp"
#include "analysis/core/errors.hpp"
#include "database/scan_record.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {
namespace {

std::string beamHelp() {
  const ScannerSpec a = scannerSpec(ScannerModel::Lms511), b = scannerSpec(ScannerModel::Lms111);
  char text[400];
  std::snprintf(text, sizeof text,
                "the scanner's beam: its footprint keeps the samples short of every edge, and the edges and corners "
                "are moved back out by it. Both 0: taken from the scan's unit when its stored settings name the "
                "model (LMS511: %.3f m, %.4f rad; LMS111: %.3f m, %.4f rad)",
                a.exit_diameter_m, a.beam_divergence_rad, b.exit_diameter_m, b.beam_divergence_rad);
  return text;
}

// The parameters of one stage's tab (the pipeline's, where it has them).
void drawStageParams(ProcessingStage stage, ProcessingParams& pp) {
  AnalysisParams& ap = pp.analysis;
  switch (stage) {
    case ProcessingStage::Roi:
      ImGui::Checkbox("crop to box", &pp.roi.enabled);
      ImGui::InputScalarN("min x y z (m)", ImGuiDataType_Double, pp.roi.min_m.data(), 3, nullptr, nullptr, "%.2f");
      ImGui::InputScalarN("max x y z (m)", ImGuiDataType_Double, pp.roi.max_m.data(), 3, nullptr, nullptr, "%.2f");
      break;
    case ProcessingStage::Filters:
      ImGui::Checkbox("statistical outliers", &ap.statistical_outliers);
      inputInt("k neighbours##sor", &ap.statistical.k_neighbours, 1, 500);
      inputDouble("std ratio", &ap.statistical.std_ratio, 0.5, "%.1f");
      ImGui::Checkbox("radius outliers", &ap.radius_outliers);
      inputDouble("radius (m)", &ap.radius.radius_m, 0.01, "%.3f");
      helpMarker("0: 4 × the median nearest-neighbour spacing");
      inputInt("min neighbours", &ap.radius.min_neighbours, 1, 100);
      break;
    case ProcessingStage::Transform:
      inputDouble("roll (°)", &pp.transform.roll_deg, 1, "%.2f");
      inputDouble("pitch (°)", &pp.transform.pitch_deg, 1, "%.2f");
      inputDouble("yaw (°)", &pp.transform.yaw_deg, 1, "%.2f");
      ImGui::InputScalarN("translation (m)", ImGuiDataType_Double, pp.transform.translation_m.data(), 3, nullptr,
                          nullptr, "%.3f");
      helpMarker("p' = Rz(yaw)·Ry(pitch)·Rx(roll)·p + t, into the boat frame (+X forward, +Y port, +Z up)");
      break;
    case ProcessingStage::Normals:
      inputInt("k neighbours##n", &ap.normals.k_neighbours, 3, 500);
      combo("orientation", &ap.normals.orientation, {"viewpoint", "propagate", "none"});
      ImGui::Checkbox("robust refit", &ap.normals.robust);
      break;
    case ProcessingStage::Segmentation:
      ImGui::Checkbox("segment (off: the cloud is the sail alone)", &ap.segment);
      inputDouble("voxel (σ)", &ap.segmentation_voxel_sigmas, 1, "%.1f");
      inputDouble("working column (σ)", &ap.working_voxel_sigmas, 1, "%.1f");
      helpMarker("0 (default): every scan point. Above 0, after segmentation a scan with two samples or "
                 "more per voxel goes on as one point per voxel this many σ wide (never wider than 1/500 "
                 "of the sail): about 3x faster on dense scans, less accurate along the edges");
      inputInt("k neighbours##rg", &ap.region_growing.k_neighbours, 3, 500);
      inputDouble("max normal angle (°)", &ap.region_growing.max_normal_angle_deg, 0.5, "%.1f");
      inputDouble("max curvature", &ap.region_growing.max_curvature, 0.005, "%.3f");
      combo("sail pick", &ap.sail_pick.method, {"auto", "index"});
      if (ap.sail_pick.method == "index") inputInt("cluster index", &ap.sail_pick.cluster_index, 0, 1000);
      break;
    case ProcessingStage::Surface:
      ImGui::Checkbox("MLS smoothing", &ap.smooth);
      inputInt("MLS k neighbours", &ap.smoothing.k_neighbours, 10, 2000);
      inputDouble("anchor ratio", &ap.smoothing.anchor_ratio, 0.05, "%.2f");
      combo("projection", &ap.surface.projection, {"auto", "plane", "scan_angles"});
      inputDouble("max edge (m)", &ap.surface.max_edge_m, 0.01, "%.3f");
      helpMarker("0: max edge factor × the median Delaunay edge");
      inputDouble("max edge factor", &ap.surface.max_edge_factor, 0.5, "%.1f");
      ImGui::Checkbox("largest component only", &ap.surface.largest_component_only);
      break;
    case ProcessingStage::Sections:
      inputInt("sections", &ap.sections.count, 1, 20);
      combo("plane", &ap.sections.plane, {"normal", "perpendicular", "horizontal"});
      inputDouble("entry/exit window", &ap.sections.end_window, 0.01, "%.2f");
      inputDouble("peak window", &ap.sections.peak_window, 0.01, "%.2f");
      inputDouble("sensor σ (m)", &ap.sensor_sigma_m, 0.001, "%.4f");
      inputDouble("beam exit (m)", &ap.outline.beam_exit_diameter_m, 0.001, "%.4f");
      inputDouble("beam divergence (rad)", &ap.outline.beam_divergence_rad, 0.0005, "%.4f");
      helpMarker(beamHelp().c_str());
      ImGui::Checkbox("edges against the sky", &ap.outline.edges_against_sky);
      helpMarker("nothing but open sky behind the sail's edges (a scan on the water): a beam straddling an edge "
                 "returns from the sail alone while enough of it lies there, so the samples reach the edges and "
                 "the footprint moves nothing. Off in a wind tunnel, whose walls lie behind the sail");
      break;
  }
}

}  // namespace

void App::drawProcessing() {
  const bool running = processing_.task.busy();
  std::optional<ProcessingStage> run;
  ImGui::BeginDisabled(running);
  if (ImGui::BeginTabBar("stages", ImGuiTabBarFlags_FittingPolicyScroll)) {
    for (ProcessingStage stage : allStages()) {
      if (!ImGui::BeginTabItem(stageName(stage))) continue;
      ImGui::PushItemWidth(150);
      drawStageParams(stage, processing_.params);
      ImGui::PopItemWidth();
      ImGui::Spacing();
      if (ImGui::Button((std::string("Run ") + stageName(stage)).c_str(), ImVec2(160, 0))) run = stage;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("runs every stage up to this one on the selected scan's stored cloud");
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
  ImGui::EndDisabled();

  if (run) startProcessing(*run);
  const JobStatus st = processing_.task.status();
  if (running) {
    ImGui::ProgressBar(static_cast<float>(st.fraction), ImVec2(-80, 0), st.stage.empty() ? "starting" : st.stage.c_str());
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) processing_.task.cancel();
  }
  if (!processing_.note.empty()) ImGui::TextWrapped("%s", processing_.note.c_str());
  if (processing_.result) drawProcessingResult(running);
}

// Runs every stage up to `stage` on the selected scan's stored cloud, on the worker.
void App::startProcessing(ProcessingStage stage) {
  if (!database_.db || !browser_.selected_scan) {
    processing_.note = "select a scan first";
    return;
  }
  try {
    ScanRecord record = loadScanRecord(*database_.db, browser_.selected_scan);
    if (!record.cloud) throw InvalidInput("scan " + std::to_string(record.scan_id) + " has no stored cloud to process");
    processing_.result_scan = record.scan_id;
    ProcessingParams params = processing_.params;
    const std::string beam = useScanBeam(params, record);
    processing_.note = beam.empty() ? "" : "scanner beam from the scan's unit (" + beam + "): its footprint is corrected at the edges";
    processing_.result_params = params;
    processing_.task.start(std::string(stageName(stage)) + " on scan " + std::to_string(record.scan_id),
                           [cloud = std::move(*record.cloud), params = std::move(params), stage](const Progress& p) {
                             return runStages(cloud, params, stage, p);
                           });
  } catch (const std::exception& e) {
    processing_.note = e.what();
    log_.error(e.what());
  }
}

// The last result: its summary, showing it in the 3D view, saving its analysis.
void App::drawProcessingResult(bool running) {
  const StageResult& r = *processing_.result;
  ImGui::Separator();
  ImGui::Text("%s result, scan %lld", stageName(r.stage), static_cast<long long>(processing_.result_scan));
  for (const auto& line : r.summary) ImGui::BulletText("%s", line.c_str());
  for (const auto& wmsg : r.warnings) ImGui::TextColored(kMutedText, "· %s", wmsg.c_str());
  if (ImGui::Checkbox("show in 3D view", &processing_.show_result)) view_.rebuild = true;
  ImGui::BeginDisabled(!r.analysis || running || !database_.db);
  if (ImGui::Button("Save analysis to database")) {
    try {
      const int64_t id = saveStageResult(*database_.db, processing_.result_scan, r, processing_.result_params);
      processing_.note = "saved as analysis " + std::to_string(id) + " of scan " + std::to_string(processing_.result_scan);
      log_.info(processing_.note);
      const int64_t scan = processing_.result_scan;
      load_.scene.reset();
      view_.rebuild = true;
      browser_.selected_scan = 0;
      selectScan(scan);  // reload: the saved analysis is now the scan's latest
    } catch (const std::exception& e) {
      processing_.note = e.what();
      log_.error(e.what());
    }
  }
  ImGui::EndDisabled();
}

}  // namespace sailshape::viewer
