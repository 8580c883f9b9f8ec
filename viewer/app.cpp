// The frame: owns the state, runs the jobs (loading, processing, scanning,
// reports, live mode) and lays the panels out; each panel is drawn by its own
// *_panel.cpp file (README.md lists them).
#include "viewer/app.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "database/catalog.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {

Rgb overlayColour(size_t k) {
  static const Rgb palette[] = {{1.0f, 0.60f, 0.10f}, {0.30f, 0.85f, 0.35f}, {0.85f, 0.35f, 0.95f},
                                {0.20f, 0.90f, 0.90f}, {0.95f, 0.95f, 0.30f}, {1.0f, 0.55f, 0.70f}};
  return palette[k % (sizeof palette / sizeof palette[0])];
}

void MessageLog::info(const std::string& text) { lines.push_back(text); }

void MessageLog::error(const std::string& text) {
  lines.push_back("error: " + text);
  std::cerr << "sailshape-viewer: " << text << "\n";
}

App::App(std::optional<std::string> database_path) : viewport_(std::make_unique<VtkViewport>()) {
  load_.options.max_cloud_points = 300'000;
  if (database_path) openDatabase(*database_path);
}

App::~App() {
  live_.mode.stop();
  load_.task.cancel();
  processing_.task.cancel();
  report_.task.cancel();
  scanner_.scan_task.cancel();
  scanner_.home_task.cancel();
  scanner_.scan_task.wait();
  scanner_.home_task.wait();
  load_.task.wait();
  processing_.task.wait();
  report_.task.wait();
}

bool App::busy() const {
  return load_.task.busy() || processing_.task.busy() || report_.task.busy() || scanner_.scan_task.busy() ||
         scanner_.home_task.busy() || live_.mode.running();
}

bool App::settled() const {
  return initial_load_done_ && !busy() && load_.pending_scan == 0 && load_.loading_scan == 0 &&
         load_.overlay_queue.empty();
}

void App::openDatabase(const std::string& path) {
  load_.task.cancel();
  load_.task.wait();
  database_ = DatabaseState{};
  database_.path = path;
  std::snprintf(database_.path_input, sizeof database_.path_input, "%s", path.c_str());
  browser_ = BrowserState{};
  load_.scene.reset();
  load_.overlays.clear();
  load_.overlay_queue.clear();
  load_.pending_scan = load_.loading_scan = 0;
  processing_.result.reset();
  pick_ = PickState{};
  view_.rebuild = true;
  if (!isPostgresUrl(path) && !std::filesystem::exists(path)) {
    database_.error = "database file not found: " + path;
    log_.error(database_.error);
    initial_load_done_ = true;
    return;
  }
  try {
    OpenOptions options;
    options.create = false;
    database_.db = openSailDatabase(path, options);
    browser_.tree = loadCatalogTree(*database_.db);
    log_.info("opened " + path + ": " + std::to_string(browser_.tree.scan_count) + " scans");
    const auto ids = browser_.tree.scanIds();
    if (!ids.empty()) selectScan(ids.front());
    else initial_load_done_ = true;
  } catch (const std::exception& e) {
    database_.db.reset();
    database_.error = e.what();
    log_.error(database_.error);
    initial_load_done_ = true;
  }
}

void App::selectScan(int64_t scan_id) {
  if (browser_.selected_scan == scan_id && (load_.scene || load_.pending_scan == scan_id)) return;
  browser_.selected_scan = scan_id;
  browser_.overlays.erase(scan_id);
  load_.pending_scan = scan_id;
  live_.shown_sweep = 0;
  if (load_.task.busy()) load_.task.cancel();  // the selection wins over an overlay still loading
  pick_.info.reset();
}

void App::startNextLoad() {
  if (!database_.db || load_.task.busy()) return;
  int64_t id = 0;
  bool overlay = false;
  if (load_.pending_scan) {
    id = load_.pending_scan;
    load_.pending_scan = 0;
  } else {
    while (!load_.overlay_queue.empty() && !id) {
      const int64_t next = load_.overlay_queue.front();
      load_.overlay_queue.pop_front();
      if (browser_.overlays.count(next) && !load_.overlays.count(next)) id = next;
    }
    overlay = true;
  }
  if (!id) return;
  try {
    ScanRecord record = loadScanRecord(*database_.db, id);
    std::optional<Mesh> design;
    if (record.has_design && !overlay) design = sailDesignMesh(*database_.db, record.sail);
    SceneOptions options = load_.options;
    if (overlay) options.design_sections = false;
    load_.loading_scan = id;
    load_.loading_overlay = overlay;
    load_.task.start((overlay ? "loading overlay scan " : "loading scan ") + std::to_string(id),
                     [record = std::move(record), design = std::move(design), options](const Progress& p) {
                       return buildScanScene(record, design, options, p);
                     });
  } catch (const std::exception& e) {
    log_.error(e.what());
    if (!overlay) initial_load_done_ = true;
  }
}

void App::pollJobs() {
  const JobStatus st = load_.task.status();
  if (load_.loading_scan && st.state != JobState::Running) {
    const int64_t id = load_.loading_scan;
    load_.loading_scan = 0;
    if (auto scene = load_.task.take()) {
      for (const auto& w : scene->warnings) log_.info("scan " + std::to_string(id) + ": " + w);
      if (load_.loading_overlay) {
        if (browser_.overlays.count(id)) load_.overlays.emplace(id, std::move(*scene));
      } else if (id == browser_.selected_scan) {
        load_.scene = std::move(*scene);
        initial_load_done_ = true;
      }
      view_.rebuild = true;
    } else if (st.state == JobState::Failed) {
      log_.error(st.name + ": " + st.error);
      if (!load_.loading_overlay) initial_load_done_ = true;
    }
  }
  startNextLoad();
  takeLiveResults();

  const JobStatus rs = report_.task.status();
  if (rs.state != JobState::Running && rs.state != JobState::Idle && report_.note.empty()) {
    if (auto written = report_.task.take()) {
      report_.note = *written;
      log_.info(*written);
    } else if (rs.state == JobState::Failed) {
      report_.note = rs.error;
      log_.error("report: " + rs.error);
    } else {
      report_.note = "report cancelled";
    }
  }

  const JobStatus ss = scanner_.scan_task.status();
  if (ss.state == JobState::Running) {
    // The cloud grows in the 3D view as the scan lines come in.
    constexpr double kArrivingRefreshS = 0.25;
    const double now = ImGui::GetTime();
    if (now - scanner_.arriving_shown_s >= kArrivingRefreshS) {
      if (auto pts = scanner_.arriving->newerThan(scanner_.arriving_seen)) {
        StageResult preview;
        preview.cloud.points = std::move(*pts);
        preview.cloud = thinCloud(preview.cloud, 300'000);
        scanner_.preview = std::move(preview);
        scanner_.arriving_shown_s = now;
        view_.rebuild = true;
      }
    }
  }
  if (ss.state != JobState::Running && ss.state != JobState::Idle) {
    if (auto a = scanner_.scan_task.take()) {
      scanner_.note = std::to_string(a->cloud.size()) + " points from " + std::to_string(a->sweeps.size()) + " unit(s)";
      for (size_t i = 0; i < a->errors.size(); ++i)
        if (!a->errors[i].empty()) log_.error("unit " + std::to_string(i + 1) + ": " + a->errors[i]);
      for (const auto& w : a->warnings) log_.info(w);
      StageResult preview;
      preview.cloud = thinCloud(a->cloud, 300'000);
      scanner_.preview = std::move(preview);
      scanner_.last = std::move(*a);
      view_.rebuild = true;
    } else if (ss.state == JobState::Failed && scanner_.note != ss.error) {
      scanner_.note = ss.error;
      log_.error("scan: " + ss.error);
    } else if (ss.state == JobState::Cancelled && scanner_.note != "scan cancelled") {
      scanner_.note = "scan cancelled";
    }
  }
  const JobStatus hs = scanner_.home_task.status();
  if (hs.state == JobState::Succeeded) {
    if (auto h = scanner_.home_task.take()) scanner_.note = *h;
  } else if (hs.state == JobState::Failed && scanner_.note != hs.error) {
    scanner_.note = hs.error;
    log_.error("home: " + hs.error);
  }

  const JobStatus ps = processing_.task.status();
  if (ps.state != JobState::Running && ps.state != JobState::Idle) {
    if (auto r = processing_.task.take()) {
      processing_.result = std::move(*r);
      processing_.note = std::string(stageName(processing_.result->stage)) + " done";
      view_.rebuild = true;
    } else if (ps.state == JobState::Failed && processing_.note != ps.error) {
      processing_.note = ps.error;
      log_.error(ps.name + ": " + ps.error);
    } else if (ps.state == JobState::Cancelled) {
      processing_.note = "cancelled";
    }
  }
}

std::vector<Overlay> App::overlayList() const {
  std::vector<Overlay> out;
  size_t k = 0;
  for (int64_t id : browser_.overlays) {
    auto it = load_.overlays.find(id);
    if (it != load_.overlays.end()) out.push_back({&it->second, overlayColour(k)});
    ++k;
  }
  return out;
}

void App::frame(float width, float height) {
  pollJobs();
  if (width < 1 || height < 1) return;  // minimised
  const float bar = 40, status = 28;
  const float left = std::min(300.0f, width * 0.25f), right = std::min(440.0f, width * 0.32f);
  const float mid_w = std::max(0.0f, width - left - right);
  const float mid_h = std::max(0.0f, height - bar - status);
  const float view_h = std::floor(mid_h * 0.64f);
  drawToolbar(0, 0, width, bar);
  drawBrowser(0, bar, left, mid_h);
  drawView(left, bar, mid_w, view_h);
  drawPlots(left, bar + view_h, mid_w, mid_h - view_h);
  drawRightPanel(left + mid_w, bar, right, mid_h);
  drawStatus(0, height - status, width, status);
}

void App::drawRightPanel(float x, float y, float w, float h) {
  if (beginPanel("Analysis", x, y, w, h)) {
    if (ImGui::BeginTabBar("right")) {
      if (ImGui::BeginTabItem("Sections")) {
        drawSectionTable();
        ImGui::EndTabItem();
      }
      if (ImGui::BeginTabItem("Trim steps")) {
        drawTrimComparison();
        ImGui::EndTabItem();
      }
      if (ImGui::BeginTabItem("Processing")) {
        drawProcessing();
        ImGui::EndTabItem();
      }
      const ImGuiTabItemFlags scanner_flags = select_scanner_tab_ ? ImGuiTabItemFlags_SetSelected : 0;
      select_scanner_tab_ = false;
      if (ImGui::BeginTabItem("Scanners", nullptr, scanner_flags)) {
        drawScanner();
        ImGui::EndTabItem();
      }
      if (ImGui::BeginTabItem("Messages")) {
        drawMessages();
        ImGui::EndTabItem();
      }
      ImGui::EndTabBar();
    }
  }
  ImGui::End();
}

}  // namespace sailshape::viewer
