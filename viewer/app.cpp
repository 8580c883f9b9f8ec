#include "viewer/app.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sensor_model.hpp"
#include "analysis/design/sail_generator.hpp"
#include "reports/trim_report.hpp"

namespace sailshape::viewer {
namespace {

constexpr ImU32 kDesignColour = IM_COL32(64, 140, 255, 255);
constexpr ImU32 kFlyingColour = IM_COL32(220, 34, 26, 255);
const ImVec4 kErrorText{1.0f, 0.45f, 0.40f, 1.0f};
const ImVec4 kMutedText{0.62f, 0.66f, 0.72f, 1.0f};
const ImVec4 kAccentText{1.0f, 0.80f, 0.25f, 1.0f};
constexpr ImGuiWindowFlags kPanelFlags =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;

ImU32 toU32(const Rgb& c) { return IM_COL32(int(c[0] * 255), int(c[1] * 255), int(c[2] * 255), 255); }
ImVec4 toVec4(const Rgb& c) { return ImVec4(c[0], c[1], c[2], 1.0f); }

std::string format(const char* fmt, double v) {
  if (!std::isfinite(v)) return "—";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string signedFormat(const char* fmt, double v) {
  if (!std::isfinite(v)) return "—";
  std::string f = std::string("%+") + (fmt + 1);
  char buf[64];
  std::snprintf(buf, sizeof buf, f.c_str(), v);
  return buf;
}

bool begin(const char* name, float x, float y, float w, float h, ImGuiWindowFlags extra = 0) {
  ImGui::SetNextWindowPos(ImVec2(x, y));
  ImGui::SetNextWindowSize(ImVec2(std::max(w, 1.0f), std::max(h, 1.0f)));
  return ImGui::Begin(name, nullptr, kPanelFlags | extra);
}

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

void helpMarker(const char* text) {
  ImGui::SameLine();
  ImGui::TextDisabled("(?)");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

bool inputInt(const char* label, int* v, int lo, int hi) {
  const bool changed = ImGui::InputInt(label, v);
  *v = std::clamp(*v, lo, hi);
  return changed;
}

bool inputDouble(const char* label, double* v, double step, const char* fmt) {
  return ImGui::InputDouble(label, v, step, step * 10, fmt);
}

bool combo(const char* label, std::string* value, const std::vector<const char*>& items) {
  bool changed = false;
  if (ImGui::BeginCombo(label, value->c_str())) {
    for (const char* item : items)
      if (ImGui::Selectable(item, *value == item)) {
        *value = item;
        changed = true;
      }
    ImGui::EndCombo();
  }
  return changed;
}

// One plot: a parameter (horizontal) against height (vertical), as a sail designer reads it.
void drawPlot(const char* title, const std::vector<PlotSeries>& series, const std::vector<ImU32>& colours,
              const char* unit, ImVec2 size) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(title, ImVec2(std::max(size.x, 1.0f), std::max(size.y, 1.0f)));
  const bool hovered = ImGui::IsItemHovered();
  if (size.x < 60 || size.y < 50) return;
  const ImVec2 p1(p0.x + size.x, p0.y + size.y);
  dl->AddRectFilled(p0, p1, IM_COL32(24, 27, 33, 255), 4.0f);
  const float left = 44, right = 10, top = 22, bottom = 22;
  const ImVec2 a(p0.x + left, p0.y + top), b(p1.x - right, p1.y - bottom);
  dl->AddText(ImVec2(p0.x + 8, p0.y + 4), IM_COL32(230, 230, 235, 255), title);
  bool any = false;
  for (const auto& s : series)
    for (double v : s.value)
      if (std::isfinite(v)) any = true;
  if (!any) {
    dl->AddText(ImVec2(a.x + 8, (a.y + b.y) / 2 - 7), IM_COL32(140, 145, 155, 255), "no sections");
    return;
  }
  const AxisRange xr = plotRange(series, true), yr = plotRange(series, false);
  auto map = [&](double v, double z) {
    return ImVec2(a.x + float((v - xr.lo) / (xr.hi - xr.lo)) * (b.x - a.x),
                  b.y - float((z - yr.lo) / (yr.hi - yr.lo)) * (b.y - a.y));
  };
  for (int k = 0; k <= 4; ++k) {
    const float gx = a.x + (b.x - a.x) * k / 4.0f, gy = a.y + (b.y - a.y) * k / 4.0f;
    dl->AddLine(ImVec2(gx, a.y), ImVec2(gx, b.y), IM_COL32(60, 66, 76, 255));
    dl->AddLine(ImVec2(a.x, gy), ImVec2(b.x, gy), IM_COL32(60, 66, 76, 255));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", xr.lo + (xr.hi - xr.lo) * k / 4.0);
    if (k % 2 == 0) {
      const float tw = ImGui::CalcTextSize(buf).x;
      dl->AddText(ImVec2(k == 4 ? gx - tw : gx - tw / 2, b.y + 4), IM_COL32(170, 175, 185, 255), buf);
    }
    std::snprintf(buf, sizeof buf, "%.1f", yr.hi - (yr.hi - yr.lo) * k / 4.0);
    dl->AddText(ImVec2(p0.x + 6, gy - 7), IM_COL32(170, 175, 185, 255), buf);
  }
  dl->AddText(ImVec2(b.x - ImGui::CalcTextSize(unit).x, p0.y + 4), IM_COL32(170, 175, 185, 255), unit);
  dl->PushClipRect(a, b, true);
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  const PlotSeries* near_series = nullptr;
  size_t near_i = 0;
  float near_d = 12.0f;
  for (size_t s = 0; s < series.size(); ++s) {
    const ImU32 col = colours[s % colours.size()];
    ImVec2 prev;
    bool have_prev = false;
    for (size_t i = 0; i < series[s].value.size(); ++i) {
      if (!std::isfinite(series[s].value[i])) {
        have_prev = false;
        continue;
      }
      const ImVec2 q = map(series[s].value[i], series[s].height_m[i]);
      if (have_prev) dl->AddLine(prev, q, col, 2.0f);
      dl->AddCircleFilled(q, 3.5f, col);
      const float d = std::hypot(q.x - mouse.x, q.y - mouse.y);
      if (hovered && d < near_d) {
        near_d = d;
        near_series = &series[s];
        near_i = i;
      }
      prev = q;
      have_prev = true;
    }
  }
  dl->PopClipRect();
  if (near_series)
    ImGui::SetTooltip("%s\n%.2f %s at z = %.2f m", near_series->label.c_str(), near_series->value[near_i], unit,
                      near_series->height_m[near_i]);
}

}  // namespace

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

bool App::startReport(const std::string& out_path, bool whole_test, const std::string& audience) {
  if (!database_.db || !load_.scene) {
    log_.error("report: select a scan first");
    return false;
  }
  if (report_.task.busy()) {
    log_.error("report: a report is still being written");
    return false;
  }
  if (out_path.empty()) {
    log_.error("report: give the PDF's path");
    return false;
  }
  TrimReportParams params;
  params.db_path = database_.path;
  params.out_path = out_path;
  params.audience = audience;
  const ScanRecord& r = load_.scene->record;
  if (whole_test && !r.test.empty()) {
    params.test = r.test;
    params.sail = r.sail;
  } else {
    params.scan_id = r.scan_id;
  }
  report_.note.clear();
  report_.task.start("report " + out_path, [params](const Progress& p) {
    const TrimReport report = writeTrimReport(params, p);
    return "wrote " + report.out_path + " (" + std::to_string(report.pages) + " pages)";
  });
  return true;
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
  if (!std::filesystem::exists(path)) {
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

void App::drawToolbar(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8, 6));
  if (begin("##toolbar", x, y, w, h, ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar)) {
    ImGui::TextColored(kAccentText, "sailshape");
    ImGui::SameLine();
    ImGui::TextColored(kMutedText, "design vs flying");
    ImGui::SameLine(200);
    ImGui::SetNextItemWidth(std::max(120.0f, w * 0.28f));
    const bool enter = ImGui::InputTextWithHint("##dbpath", "database file (.sqlite)", database_.path_input,
                                                sizeof database_.path_input, ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    if (ImGui::Button("Open") || enter) openDatabase(database_.path_input);
    ImGui::SameLine(0, 24);
    ImGui::TextColored(kMutedText, "Camera");
    const std::pair<const char*, CameraPreset> presets[] = {
        {"3/4", CameraPreset::ThreeQuarter}, {"Side", CameraPreset::Side}, {"Top", CameraPreset::Top}, {"Astern", CameraPreset::Astern}, {"Bow", CameraPreset::Bow}};
    for (const auto& [label, preset] : presets) {
      ImGui::SameLine();
      if (ImGui::Button(label)) view_.camera = preset;
    }
    ImGui::SameLine();
    // A stored scan shown is seen from the unit that took it; otherwise from the Scanners tab's first unit.
    const std::optional<UnitConfig> scan_unit =
        load_.scene && !live_.shown_sweep ? scanUnit(load_.scene->record) : std::nullopt;
    ImGui::BeginDisabled(!scan_unit && scanner_.session.units().empty());
    if (ImGui::Button("Unit"))
      view_.placement = unitCamera(scan_unit ? *scan_unit : scanner_.session.units().front().config);
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip(scan_unit ? "from the unit that took this scan (its stored unit settings and registration), "
                                    "looking along its sweep's centre"
                                  : "from the first scanner unit (Scanners tab): at its scanner, looking along its "
                                    "sweep's centre");
    ImGui::SameLine(0, 24);
    // A live sweep that was not stored has no scan to report on.
    ImGui::BeginDisabled(!load_.scene || load_.scene->record.scan_id == 0 || report_.task.busy());
    if (ImGui::Button(report_.task.busy() ? "Writing report…" : "Report (PDF)")) {
      report_.popup = true;
      const ScanRecord& r = load_.scene->record;
      const auto dir = std::filesystem::path(database_.path).parent_path();
      std::snprintf(report_.out_path, sizeof report_.out_path, "%s",
                    (dir / ("report-scan-" + std::to_string(r.scan_id) + ".pdf")).c_str());
      ImGui::OpenPopup("Trim report");
    }
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("PDF trim report of the selected scan or of its test (as `sailshape report`)");
    drawReportPopup();
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

void App::drawBrowser(float x, float y, float w, float h) {
  if (begin("Database", x, y, w, h)) {
    if (!database_.db) {
      if (!database_.error.empty()) {
        ImGui::PushTextWrapPos(0);
        ImGui::TextColored(kErrorText, "%s", database_.error.c_str());
        ImGui::PopTextWrapPos();
      } else {
        ImGui::TextWrapped("No database open. Type a path above and press Open, or start sailshape-viewer DB.");
      }
    } else {
      ImGui::TextColored(kMutedText, "%s", std::filesystem::path(database_.path).filename().c_str());
      ImGui::SameLine();
      ImGui::TextColored(kMutedText, "· %zu scans", browser_.tree.scan_count);
      if (browser_.tree.campaigns.empty()) {
        ImGui::Spacing();
        ImGui::TextWrapped("This database has no scans yet. Import some with `sailshape db import`.");
      }
      const float tree_h = std::max(80.0f, ImGui::GetContentRegionAvail().y - 250.0f);
      ImGui::BeginChild("tree", ImVec2(0, tree_h), true);
      for (const auto& c : browser_.tree.campaigns) {
        if (!ImGui::TreeNodeEx(c.name.c_str(), ImGuiTreeNodeFlags_DefaultOpen)) continue;
        for (const auto& t : c.tests) {
          if (!ImGui::TreeNodeEx((t.label() + "##" + c.name).c_str(), ImGuiTreeNodeFlags_DefaultOpen)) continue;
          for (const auto& s : t.steps) {
            const std::string id = s.label() + "##" + c.name + t.name + s.sail + std::to_string(s.step);
            const bool open = ImGui::TreeNodeEx(id.c_str(), ImGuiTreeNodeFlags_DefaultOpen);
            if (ImGui::IsItemHovered() && !s.controls.empty())
              ImGui::SetTooltip("controls: %s%s", s.controls.c_str(),
                                s.drive_n ? ("\ndrive " + format("%.0f N", *s.drive_n)).c_str() : "");
            if (!open) continue;
            for (const auto& scan : s.scans) {
              ImGui::PushID(static_cast<int>(scan.scan_id));
              bool overlay = browser_.overlays.count(scan.scan_id) > 0;
              if (ImGui::Checkbox("##ov", &overlay)) {
                if (overlay && scan.scan_id != browser_.selected_scan) {
                  browser_.overlays.insert(scan.scan_id);
                  load_.overlay_queue.push_back(scan.scan_id);
                } else {
                  browser_.overlays.erase(scan.scan_id);
                  load_.overlays.erase(scan.scan_id);
                }
                view_.rebuild = true;
              }
              if (ImGui::IsItemHovered()) ImGui::SetTooltip("overlay this trim step on the selected scan");
              ImGui::SameLine();
              const std::string label = "scan " + std::to_string(scan.scan_id) + "  " +
                                        (scan.point_count ? std::to_string(scan.point_count) + " pts" : std::string());
              if (ImGui::Selectable(label.c_str(), browser_.selected_scan == scan.scan_id)) selectScan(scan.scan_id);
              ImGui::PopID();
            }
            ImGui::TreePop();
          }
          ImGui::TreePop();
        }
        ImGui::TreePop();
      }
      ImGui::EndChild();
    }
    drawDisplayOptions();
  }
  ImGui::End();
}

void App::drawDisplayOptions() {
  ImGui::Spacing();
  ImGui::TextColored(kAccentText, "Display");
  ViewOptions& o = view_.options;
  bool changed = false;
  changed |= ImGui::Checkbox("design (blue wireframe)", &o.design);
  changed |= ImGui::Checkbox("flying surface", &o.surface);
  ImGui::SameLine();
  changed |= ImGui::Checkbox("raw cloud", &o.cloud);
  changed |= ImGui::Checkbox("sail cluster", &o.cluster);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the points segmentation took for the sail, cleaned and smoothed");
  changed |= ImGui::Checkbox("sections", &o.sections);
  ImGui::SameLine();
  changed |= ImGui::Checkbox("design sections", &o.design_sections);
  changed |= ImGui::Checkbox("section planes", &o.section_planes);
  changed |= ImGui::Checkbox("deviation colours", &o.deviation);
  if (o.deviation) {
    ImGui::SetNextItemWidth(140);
    changed |= ImGui::SliderFloat("± mm", &o.deviation_range_mm, 0.0f, 300.0f, o.deviation_range_mm > 0 ? "%.0f" : "auto");
  }
  ImGui::SetNextItemWidth(140);
  changed |= ImGui::SliderFloat("point size", &o.point_size, 1.0f, 6.0f, "%.0f");
  if (changed) view_.rebuild = true;
}

void App::drawView(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  if (begin("3D view", x, y, w, h, ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse)) {
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const int vw = static_cast<int>(avail.x), vh = static_cast<int>(avail.y);
    if (view_.rebuild) {
      const StageResult* proc = scanner_.preview                                          ? &*scanner_.preview
                                : processing_.show_result && processing_.result &&
                                          processing_.result_scan == browser_.selected_scan
                                    ? &*processing_.result
                                    : nullptr;
      viewport_->setScene(load_.scene ? &*load_.scene : nullptr, overlayList(), view_.options, proc);
      view_.rebuild = false;
    }
    if (view_.camera) {
      viewport_->setCamera(*view_.camera);
      view_.camera.reset();
    }
    if (view_.placement) {
      viewport_->setCamera(*view_.placement);
      view_.placement.reset();
    }
    view_.hovered = false;
    // A zero-size view (tiny window, minimised) renders nothing and keeps VTK's last framebuffer.
    if (vw > 0 && vh > 0) {
      const unsigned tex = viewport_->render(vw, vh);
      view_.width = vw;
      view_.height = vh;
      const ImVec2 origin = ImGui::GetCursorScreenPos();
      if (tex) {
        ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(tex)), avail, ImVec2(0, 1), ImVec2(1, 0));
      } else {
        ImGui::Dummy(avail);
      }
      view_.hovered = ImGui::IsItemHovered();
      ImGuiIO& io = ImGui::GetIO();
      const float mx = io.MousePos.x - origin.x, my = io.MousePos.y - origin.y;
      // Events go to VTK only while the view is hovered; releases also when a drag began here.
      if (view_.hovered || pick_.pressed_in_view) {
        ViewportInput in;
        in.x = mx;
        in.y = my;
        in.ctrl = io.KeyCtrl;
        in.shift = io.KeyShift;
        for (int b = 0; b < 3; ++b) {
          in.pressed[b] = view_.hovered && io.MouseClicked[b];
          in.released[b] = io.MouseReleased[b] && pick_.pressed_in_view;
        }
        if (view_.hovered) {
          in.wheel = io.MouseWheel;
          if (!io.InputQueueCharacters.empty()) in.key_char = io.InputQueueCharacters[0];
        }
        if (in.pressed[0]) {
          pick_.press_x = mx;
          pick_.press_y = my;
        }
        const bool click = in.released[0] && std::hypot(mx - pick_.press_x, my - pick_.press_y) < 3.0f;
        if (in.pressed[0] || in.pressed[1] || in.pressed[2]) pick_.pressed_in_view = true;
        viewport_->forward(in);
        if (click) pick_.info = viewport_->pick(mx, my);
        if (!io.MouseDown[0] && !io.MouseDown[1] && !io.MouseDown[2]) pick_.pressed_in_view = false;
      }

      if (pick_.pending) {
        pick_.info = viewport_->pick((*pick_.pending)[0] * avail.x, (*pick_.pending)[1] * avail.y);
        pick_.pending.reset();
      }

      ImDrawList* dl = ImGui::GetWindowDrawList();
      float ty = origin.y + 10;
      auto legend = [&](ImU32 col, const std::string& text) {
        dl->AddRectFilled(ImVec2(origin.x + 12, ty + 3), ImVec2(origin.x + 26, ty + 13), col, 2.0f);
        dl->AddText(ImVec2(origin.x + 32, ty), IM_COL32(235, 235, 240, 255), text.c_str());
        ty += 18;
      };
      if (load_.scene) {
        const ScanRecord& r = load_.scene->record;
        std::string title = r.campaign + " · " + (r.test.empty() ? "" : r.test + " · ") + "step " +
                            std::to_string(r.step) + " · " + r.sail;
        if (live_.shown_sweep) title = "LIVE sweep " + std::to_string(live_.shown_sweep) + " · " + title;
        if (r.awa_deg) title += " · AWA " + format("%.0f°", *r.awa_deg);
        dl->AddText(ImVec2(origin.x + 12, ty), IM_COL32(255, 210, 90, 255), title.c_str());
        ty += 22;
        if (!load_.scene->design.empty()) legend(kDesignColour, "design");
        if (!load_.scene->surface.empty() || !load_.scene->raw_cloud.empty())
          legend(kFlyingColour, r.scan_id ? "flying, scan " + std::to_string(r.scan_id) : std::string("flying, not stored"));
        for (const auto& ov : overlayList())
          legend(toU32(ov.colour), "step " + std::to_string(ov.scene->record.step) + ", scan " +
                                       std::to_string(ov.scene->record.scan_id));
        if (load_.scene->deviation) {
          const DistanceStats& d = *load_.scene->deviation;
          const std::string line = "deviation from design (+ to leeward): mean " + format("%+.0f", 1000 * d.mean_m) + " mm, rms " +
                                   format("%.0f", 1000 * d.rms_m) + " mm, max |" + format("%.0f", 1000 * d.max_abs_m) + "| mm";
          dl->AddText(ImVec2(origin.x + 12, ty + 4), IM_COL32(200, 205, 215, 255), line.c_str());
          ty += 22;
        }
      } else {
        const char* msg = !database_.db ? (database_.error.empty() ? "No database open" : database_.error.c_str())
                          : browser_.tree.scan_count == 0 ? "The database has no scans"
                          : load_.task.busy()             ? "Loading scan…"
                                                          : "Select a scan in the database browser";
        const ImVec2 ts = ImGui::CalcTextSize(msg);
        dl->AddText(ImVec2(origin.x + (avail.x - ts.x) / 2, origin.y + (avail.y - ts.y) / 2),
                    database_.error.empty() ? IM_COL32(210, 215, 225, 255) : IM_COL32(255, 120, 110, 255), msg);
      }
      if (pick_.info) {
        const PickInfo& p = *pick_.info;
        std::string text = p.what + "  x " + format("%.3f", p.point.x()) + "  y " + format("%.3f", p.point.y()) +
                           "  z " + format("%.3f", p.point.z()) + " m";
        if (p.deviation_m) text += "   deviation " + format("%+.1f", 1000 * *p.deviation_m) + " mm";
        const ImVec2 ts = ImGui::CalcTextSize(text.c_str());
        const ImVec2 at(origin.x + 12, origin.y + avail.y - ts.y - 14);
        dl->AddRectFilled(ImVec2(at.x - 6, at.y - 4), ImVec2(at.x + ts.x + 6, at.y + ts.y + 4), IM_COL32(0, 0, 0, 170), 4);
        dl->AddText(at, IM_COL32(255, 240, 120, 255), text.c_str());
      }
      const char* hint = "drag: rotate · right/wheel: zoom · middle: pan · click: pick";
      dl->AddText(ImVec2(origin.x + avail.x - ImGui::CalcTextSize(hint).x - 10, origin.y + avail.y - 20),
                  IM_COL32(150, 155, 165, 255), hint);
    }
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

void App::drawPlots(float x, float y, float w, float h) {
  if (begin("Sections against height", x, y, w, h, ImGuiWindowFlags_NoScrollbar)) {
    const float pw = (ImGui::GetContentRegionAvail().x - 2 * 8) / 3.0f;
    std::vector<PlotSeries> series;
    std::vector<ImU32> colours;
    for (int k = 0; k < 3; ++k) {
      if (k) ImGui::SameLine(0, 8);
      ImGui::BeginGroup();
      ImGui::PushID(k);
      ImGui::SetNextItemWidth(std::max(40.0f, pw));
      const FieldInfo& info = fieldInfo(plots_.fields[k]);
      if (ImGui::BeginCombo("##field", info.name)) {
        for (SectionField f : allFields())
          if (ImGui::Selectable(fieldInfo(f).name, f == plots_.fields[k])) plots_.fields[k] = f;
        ImGui::EndCombo();
      }
      series.clear();
      colours.clear();
      if (load_.scene) {
        if (!load_.scene->design_sections.sections.empty()) {
          series.push_back(parameterVsHeight(load_.scene->design_sections, plots_.fields[k], "design"));
          colours.push_back(kDesignColour);
        }
        series.push_back(parameterVsHeight(load_.scene->sections, plots_.fields[k],
                                           "flying, scan " + std::to_string(load_.scene->record.scan_id)));
        colours.push_back(kFlyingColour);
        for (const auto& ov : overlayList()) {
          series.push_back(parameterVsHeight(ov.scene->sections, plots_.fields[k],
                                             "step " + std::to_string(ov.scene->record.step) + ", scan " +
                                                 std::to_string(ov.scene->record.scan_id)));
          colours.push_back(toU32(ov.colour));
        }
      }
      const std::string title = std::string(fieldInfo(plots_.fields[k]).name) + " vs height (m)";
      drawPlot(title.c_str(), series, colours, fieldInfo(plots_.fields[k]).unit,
               ImVec2(std::max(1.0f, pw), std::max(1.0f, ImGui::GetContentRegionAvail().y)));
      ImGui::PopID();
      ImGui::EndGroup();
    }
  }
  ImGui::End();
}

void App::drawRightPanel(float x, float y, float w, float h) {
  if (begin("Analysis", x, y, w, h)) {
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
        for (const auto& line : log_.lines) {
          const bool err = line.rfind("error:", 0) == 0;
          if (err) ImGui::PushStyleColor(ImGuiCol_Text, kErrorText);
          ImGui::TextWrapped("%s", line.c_str());
          if (err) ImGui::PopStyleColor();
        }
        ImGui::EndTabItem();
      }
      ImGui::EndTabBar();
    }
  }
  ImGui::End();
}

void App::drawSectionTable() {
  if (!load_.scene) {
    ImGui::TextColored(kMutedText, "No scan shown.");
    return;
  }
  const ScanScene& s = *load_.scene;
  if (s.deviation) {
    const DistanceStats& d = s.deviation.value();
    ImGui::Text("Flying − design, signed (+ leeward), %zu points", d.count);
    ImGui::TextColored(kMutedText, "mean %+.0f  rms %.0f  p5 %+.0f  p50 %+.0f  p95 %+.0f  max|%.0f| mm", 1000 * d.mean_m,
                       1000 * d.rms_m, 1000 * d.p5_m, 1000 * d.p50_m, 1000 * d.p95_m, 1000 * d.max_abs_m);
  } else if (s.design.empty()) {
    ImGui::TextColored(kMutedText, "The sail has no design in the database: flying values only.");
  }
  const auto rows = sectionRows(s.sections, s.deltas);
  if (rows.empty()) {
    ImGui::TextColored(kMutedText, "This scan has no sections.");
    return;
  }
  const SectionField fields[] = {SectionField::Camber, SectionField::Draft, SectionField::Twist,
                                 SectionField::Entry,  SectionField::Exit,  SectionField::Chord};
  for (size_t i = 0; i < rows.size(); ++i) {
    const SectionRow& r = rows[i];
    ImGui::Spacing();
    ImGui::TextColored(kAccentText, "Section %zu   f = %.2f   z = %.2f m", i + 1, r.fraction, r.height_m);
    const ImGuiTableFlags flags = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingStretchSame;
    if (ImGui::BeginTable(("sec" + std::to_string(i)).c_str(), 5, flags)) {
      ImGui::TableSetupColumn("");
      ImGui::TableSetupColumn("design");
      ImGui::TableSetupColumn("flying");
      ImGui::TableSetupColumn("Δ");
      ImGui::TableSetupColumn("±1σ");
      ImGui::TableHeadersRow();
      for (SectionField f : fields) {
        const FieldInfo& info = fieldInfo(f);
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::Text("%s %s", info.name, info.unit);
        ImGui::TableNextColumn();
        if (r.design) ImGui::TextColored(ImVec4(0.55f, 0.75f, 1.0f, 1.0f), "%s", format(info.format, fieldValue(*r.design, f)).c_str());
        else ImGui::TextDisabled("—");
        ImGui::TableNextColumn();
        ImGui::TextColored(ImVec4(1.0f, 0.55f, 0.50f, 1.0f), "%s", format(info.format, fieldValue(r.flying, f)).c_str());
        ImGui::TableNextColumn();
        const double sigma = fieldValue(r.uncertainty, f);
        if (r.delta) {
          const double d = fieldValue(*r.delta, f);
          // A difference beyond 2σ of the measurement is a real change of shape.
          const bool significant = std::isfinite(d) && std::isfinite(sigma) && std::abs(d) > 2 * sigma;
          ImGui::TextColored(significant ? kAccentText : kMutedText, "%s", signedFormat(info.format, d).c_str());
        } else {
          ImGui::TextDisabled("—");
        }
        ImGui::TableNextColumn();
        ImGui::TextColored(kMutedText, "%s", format(info.format, sigma).c_str());
      }
      ImGui::EndTable();
    }
  }
  for (const UnmeasuredSection& u : s.sections.unmeasured) {
    ImGui::Spacing();
    ImGui::TextColored(kAccentText, "Section at f = %.2f: not measured", u.fraction);
    ImGui::PushStyleColor(ImGuiCol_Text, kMutedText);
    ImGui::TextWrapped("%s", u.reason.c_str());
    ImGui::PopStyleColor();
  }
  if (!s.warnings.empty()) {
    ImGui::Spacing();
    for (const auto& wmsg : s.warnings) ImGui::TextColored(kMutedText, "· %s", wmsg.c_str());
  }
}

void App::drawTrimComparison() {
  if (!load_.scene) {
    ImGui::TextColored(kMutedText, "No scan shown.");
    return;
  }
  ImGui::TextWrapped("Tick trim steps in the database browser to overlay them; they are drawn in their colour in the "
                     "3D view and the plots.");
  ImGui::SetNextItemWidth(160);
  if (ImGui::BeginCombo("parameter", fieldInfo(plots_.compare_field).name)) {
    for (SectionField f : allFields())
      if (ImGui::Selectable(fieldInfo(f).name, f == plots_.compare_field)) plots_.compare_field = f;
    ImGui::EndCombo();
  }
  struct Row {
    const ScanScene* scene;
    ImVec4 colour;
  };
  std::vector<Row> rows{{&*load_.scene, ImVec4(0.86f, 0.13f, 0.10f, 1.0f)}};
  for (const auto& ov : overlayList()) rows.push_back({ov.scene, toVec4(ov.colour)});
  // A column for every section height any row measured or was asked for (one step
  // may have left a section unmeasured that another measured).
  std::vector<const SectionAnalysis*> steps;
  for (const Row& row : rows) steps.push_back(&row.scene->sections);
  const std::vector<double> base = sectionColumns(steps);
  const int cols = 3 + static_cast<int>(base.size());
  if (ImGui::BeginTable("trim", cols, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_ScrollX)) {
    ImGui::TableSetupColumn("step");
    ImGui::TableSetupColumn("AWA");
    ImGui::TableSetupColumn("controls");
    for (double f : base) ImGui::TableSetupColumn(format("f %.2f", f).c_str());
    ImGui::TableHeadersRow();
    const FieldInfo& info = fieldInfo(plots_.compare_field);
    for (const Row& row : rows) {
      const ScanRecord& r = row.scene->record;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextColored(row.colour, "■ %d", r.step);
      ImGui::TableNextColumn();
      ImGui::Text("%s", r.awa_deg ? format("%.0f°", *r.awa_deg).c_str() : "—");
      ImGui::TableNextColumn();
      const TrimStepEntry* step = browser_.tree.stepOf(r.scan_id);
      ImGui::TextUnformatted(step && !step->controls.empty() ? step->controls.c_str() : "—");
      for (double f : base) {
        ImGui::TableNextColumn();
        const Section* match = nullptr;
        for (const auto& o : row.scene->sections.sections)
          if (std::abs(o.fraction - f) < 0.02) match = &o;
        ImGui::Text("%s", match ? format(info.format, fieldValue(match->value, plots_.compare_field)).c_str() : "—");
      }
    }
    ImGui::EndTable();
  }
}

void App::drawProcessing() {
  ProcessingParams& pp = processing_.params;
  AnalysisParams& ap = pp.analysis;
  const bool running = processing_.task.busy();
  std::optional<ProcessingStage> run;
  ImGui::BeginDisabled(running);
  if (ImGui::BeginTabBar("stages", ImGuiTabBarFlags_FittingPolicyScroll)) {
    for (ProcessingStage stage : allStages()) {
      if (!ImGui::BeginTabItem(stageName(stage))) continue;
      ImGui::PushItemWidth(150);
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
      ImGui::PopItemWidth();
      ImGui::Spacing();
      if (ImGui::Button((std::string("Run ") + stageName(stage)).c_str(), ImVec2(160, 0))) run = stage;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("runs every stage up to this one on the selected scan's stored cloud");
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
  ImGui::EndDisabled();

  if (run) {
    if (!database_.db || !browser_.selected_scan) {
      processing_.note = "select a scan first";
    } else {
      try {
        ScanRecord record = loadScanRecord(*database_.db, browser_.selected_scan);
        if (!record.cloud) throw InvalidInput("scan " + std::to_string(record.scan_id) + " has no stored cloud to process");
        processing_.result_scan = record.scan_id;
        ProcessingParams params = pp;
        const std::string beam = useScanBeam(params, record);
        processing_.note = beam.empty() ? "" : "scanner beam from the scan's unit (" + beam + "): its footprint is corrected at the edges";
        processing_.result_params = params;
        processing_.task.start(std::string(stageName(*run)) + " on scan " + std::to_string(record.scan_id),
                               [cloud = std::move(*record.cloud), params = std::move(params), stage = *run](const Progress& p) {
                                 return runStages(cloud, params, stage, p);
                               });
      } catch (const std::exception& e) {
        processing_.note = e.what();
        log_.error(e.what());
      }
    }
  }
  const JobStatus st = processing_.task.status();
  if (running) {
    ImGui::ProgressBar(static_cast<float>(st.fraction), ImVec2(-80, 0), st.stage.empty() ? "starting" : st.stage.c_str());
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) processing_.task.cancel();
  }
  if (!processing_.note.empty()) ImGui::TextWrapped("%s", processing_.note.c_str());
  if (processing_.result) {
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
}

TrimStepForm App::trimStepForm() const {
  const ScannerState& sc = scanner_;
  TrimStepForm form;
  form.campaign = sc.campaign;
  form.session = sc.session_name;
  form.sail = sc.sail;
  form.test = sc.test;
  form.step = sc.step;
  if (sc.has_awa) form.awa_deg = sc.awa_deg;
  if (sc.has_aws) form.aws_m_s = sc.aws_m_s;
  if (sc.has_forces) {
    form.drive_n = sc.drive_n;
    form.side_n = sc.side_n;
  }
  form.controls = sc.controls;
  return form;
}

bool App::addEmulatedDeckUnit() {
  ScannerState& sc = scanner_;
  try {
    sc.session.addEmulatedUnit(builtInDeckScene(), "deck", deckUnit());
    sc.note = "emulated unit on " + sc.session.units().back().config.serial_device + " and port " +
              std::to_string(sc.session.units().back().config.port);
    select_scanner_tab_ = true;
    return true;
  } catch (const std::exception& e) {
    sc.note = e.what();
    log_.error(e.what());
    return false;
  }
}

bool App::setUnitCamera(size_t index) {
  if (index >= scanner_.session.units().size()) {
    log_.error("camera: no scanner unit " + std::to_string(index + 1));
    return false;
  }
  view_.placement = unitCamera(scanner_.session.units()[index].config);
  return true;
}

bool App::startLive() {
  const ScannerState& sc = scanner_;
  if (sc.scan_task.busy() || sc.home_task.busy()) {
    log_.error("live mode: wait until the scan or the homing has ended");
    return false;
  }
  try {
    LiveParams params;
    params.form = trimStepForm();
    SceneOptions options = load_.options;
    options.analysis = processing_.params.analysis;
    std::string source;
    std::optional<Mesh> design;
    if (database_.db) {
      try {
        design = sailDesignMesh(*database_.db, params.form.sail);
        source = "the design of " + params.form.sail + " in the database";
      } catch (const std::exception&) {
        design.reset();  // no stored design for this sail
      }
    }
    const bool all_deck = std::all_of(sc.session.units().begin(), sc.session.units().end(),
                                      [](const ScannerUnitSlot& u) { return u.origin == "emulated (deck)"; });
    if (!design && all_deck && !sc.session.units().empty()) {
      design = generateSailMesh(exampleDesign(SailType::Main));
      source = "the emulated deck's mainsail (no design of '" + params.form.sail + "' in the database)";
    }
    if (design) {
      options.roi = sailRoi(*design, live_.roi_margin_m);
      options.analysis = designedSailParams(*design, live_.sections, options.analysis);
    } else {
      options.roi = processing_.params.roi;
      options.analysis.sections.count = live_.sections;
      source = "no design: the Processing tab's ROI, flying values only";
    }
    // The emulated deck stands in the open: only sky lies behind the main's leech and
    // head, so a beam straddling them returns from the sail and the unit's footprint
    // trims nothing there (OutlineParams::edges_against_sky).
    if (all_deck && !sc.session.units().empty() && !options.analysis.outline.edges_against_sky) {
      options.analysis.outline.edges_against_sky = true;
      source += "; edges against the sky (the emulated deck)";
    }
    params.design = std::move(design);
    params.scene = options;
    if (live_.save_each) {
      if (!database_.db) throw InvalidInput("open a database to store the sweeps in");
      params.save_to = database_.path;
    }
    live_.mode.start(sc.session, std::move(params));
    live_.design_source = source;
    live_.messages.clear();
    live_.note = "live mode: sweeping";
    log_.info("live mode started; ROI and comparison: " + source);
    return true;
  } catch (const std::exception& e) {
    live_.note = e.what();
    log_.error(std::string("live mode: ") + e.what());
    return false;
  }
}

void App::takeLiveResults() {
  bool stored = false;
  for (LiveSweep& s : live_.mode.take()) {
    const std::string tag = "live sweep " + std::to_string(s.index);
    if (!s.store_error.empty()) {
      live_.messages.push_back(tag + " not stored: " + s.store_error);
      log_.error(live_.messages.back());
    }
    stored |= s.scan_id > 0;
    if (!s.scene) {
      live_.messages.push_back(tag + ": analysis failed: " + s.error);
      log_.error(live_.messages.back());
      continue;
    }
    char line[160];
    std::snprintf(line, sizeof line, "%s: %zu points, %zu sections; swept in %.1f s, analysed in %.1f s", tag.c_str(),
                  s.points, s.scene->sections.sections.size(), s.sweep_s, s.analysis_s);
    live_.note = line;
    log_.info(line);
    load_.scene = std::move(*s.scene);
    load_.pending_scan = 0;
    browser_.selected_scan = s.scan_id;
    live_.shown_sweep = s.index;
    pick_.info.reset();
    view_.rebuild = true;
  }
  if (stored && database_.db) {
    try {
      browser_.tree = loadCatalogTree(*database_.db);
    } catch (const std::exception& e) {
      log_.error(e.what());
    }
  }
}

void App::drawLive() {
  ImGui::Separator();
  ImGui::TextColored(kAccentText, "Live mode");
  helpMarker("the units sweep again and again; each sweep is analysed while the next one runs and the section table, "
             "plots and 3D view follow");
  const bool live = live_.mode.running();
  ImGui::BeginDisabled(live);
  ImGui::PushItemWidth(110);
  inputInt("sections##live", &live_.sections, 1, 20);
  ImGui::SameLine();
  inputDouble("ROI margin m", &live_.roi_margin_m, 0.05, "%.2f");
  live_.roi_margin_m = std::max(0.0, live_.roi_margin_m);
  ImGui::PopItemWidth();
  ImGui::Checkbox("store every sweep in the database", &live_.save_each);
  ImGui::EndDisabled();
  if (!live) {
    ImGui::BeginDisabled(scanner_.session.units().empty() || scanner_.scan_task.busy() || scanner_.home_task.busy());
    if (ImGui::Button("Start live", ImVec2(120, 0))) startLive();
    ImGui::EndDisabled();
  } else if (ImGui::Button("Stop live", ImVec2(120, 0))) {
    live_.mode.requestStop();
  }
  const LiveStatus st = live_.mode.status();
  if (st.running || st.swept > 0) {
    ImGui::SameLine();
    ImGui::Text("%s · %d swept · %d analysed · %d failed%s", st.stage.c_str(), st.swept, st.analysed, st.failed,
                st.skipped ? (" · " + std::to_string(st.skipped) + " skipped").c_str() : "");
  }
  if (!live_.design_source.empty()) ImGui::TextColored(kMutedText, "ROI and design: %s", live_.design_source.c_str());
  if (!live_.note.empty()) ImGui::TextWrapped("%s", live_.note.c_str());
  if (!st.error.empty()) ImGui::TextColored(kErrorText, "%s", st.error.c_str());
  const size_t first = live_.messages.size() > 4 ? live_.messages.size() - 4 : 0;
  ImGui::PushTextWrapPos(0);
  for (size_t i = first; i < live_.messages.size(); ++i) ImGui::TextColored(kErrorText, "%s", live_.messages[i].c_str());
  ImGui::PopTextWrapPos();
}

void App::drawScanner() {
  ScannerState& sc = scanner_;
  const bool running = sc.scan_task.busy() || sc.home_task.busy() || live_.mode.running();
  ImGui::BeginDisabled(running);
  ImGui::SetNextItemWidth(-90);
  ImGui::InputTextWithHint("##unit", "UNIT.json", sc.unit_path, sizeof sc.unit_path);
  ImGui::SameLine();
  if (ImGui::Button("Load unit")) {
    try {
      sc.session.addUnitFile(sc.unit_path);
      sc.note = "loaded " + std::string(sc.unit_path);
    } catch (const std::exception& e) {
      sc.note = e.what();
      log_.error(e.what());
    }
  }
  if (ImGui::Button("Add emulated unit (deck scene)")) addEmulatedDeckUnit();
  std::optional<size_t> remove, home;
  for (size_t i = 0; i < sc.session.units().size(); ++i) {
    ScannerUnitSlot& u = sc.session.units()[i];
    ImGui::PushID(static_cast<int>(i));
    ImGui::Separator();
    ImGui::TextColored(kAccentText, "%s", u.config.name.c_str());
    ImGui::SameLine();
    ImGui::TextColored(kMutedText, "%s · %s:%u · %s", u.origin.c_str(), u.config.host.c_str(), u.config.port,
                       u.config.serial_device.c_str());
    ImGui::PushItemWidth(110);
    inputDouble("speed °/s", &u.config.speed_deg_s, 1, "%.1f");
    ImGui::SameLine();
    inputDouble("accel. °/s²", &u.config.acceleration_deg_s2, 10, "%.0f");
    inputDouble("start °", &u.config.start_angle_deg, 1, "%.1f");
    ImGui::SameLine();
    inputDouble("sweep °", &u.config.sweep_angle_deg, 1, "%.1f");
    ImGui::PopItemWidth();
    if (ImGui::Button("Home")) home = i;
    ImGui::SameLine();
    if (ImGui::Button("Remove")) remove = i;
    ImGui::SameLine();
    if (ImGui::Button("View from here")) view_.placement = unitCamera(u.config);
    ImGui::PopID();
  }
  if (remove) sc.session.removeUnit(*remove);
  if (home) {
    const size_t index = *home;
    const ScannerSession* session = &sc.session;
    sc.home_task.start("home unit " + std::to_string(index + 1), [session, index](const Progress&) {
      session->home(index);
      return std::string("unit ") + std::to_string(index + 1) + " homed";
    });
  }
  ImGui::Separator();
  ImGui::TextColored(kAccentText, "Trim step");
  ImGui::PushItemWidth(170);
  ImGui::InputText("campaign", sc.campaign, sizeof sc.campaign);
  ImGui::InputText("session", sc.session_name, sizeof sc.session_name);
  ImGui::InputText("sail", sc.sail, sizeof sc.sail);
  ImGui::InputText("test", sc.test, sizeof sc.test);
  inputInt("step", &sc.step, 0, 100000);
  ImGui::Checkbox("##awa", &sc.has_awa);
  ImGui::SameLine();
  inputDouble("AWA °", &sc.awa_deg, 1, "%.1f");
  ImGui::Checkbox("##aws", &sc.has_aws);
  ImGui::SameLine();
  inputDouble("AWS m/s", &sc.aws_m_s, 0.5, "%.1f");
  ImGui::Checkbox("##forces", &sc.has_forces);
  ImGui::SameLine();
  inputDouble("drive N", &sc.drive_n, 10, "%.0f");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  inputDouble("side N", &sc.side_n, 10, "%.0f");
  ImGui::InputTextWithHint("controls", "sheet=0.42; traveller=-0.1", sc.controls, sizeof sc.controls);
  ImGui::PopItemWidth();
  ImGui::BeginDisabled(sc.session.units().empty());
  if (ImGui::Button("Scan", ImVec2(120, 0))) {
    sc.last.reset();
    sc.preview.reset();
    view_.rebuild = true;
    const ScannerSession* session = &sc.session;
    sc.arriving->clear();
    std::shared_ptr<ArrivingPoints> arriving = sc.arriving;
    sc.scan_task.start("scan", [session, arriving](const Progress& p) {
      try {
        return session->scan(arriving->feeding(), p);
      } catch (const Cancelled&) {
        session->stopTurntables();  // the drives would refuse the next scan's homing while they still move
        throw;
      }
    });
  }
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(!sc.last || !database_.db);
  if (ImGui::Button("Save to database", ImVec2(160, 0))) {
    try {
      const ImportResult saved = saveAcquisition(*database_.db, *sc.last, trimStepForm());
      sc.note = "saved as scan " + std::to_string(saved.scan_id);
      log_.info(sc.note);
      sc.last.reset();
      sc.preview.reset();
      browser_.tree = loadCatalogTree(*database_.db);
      selectScan(saved.scan_id);
      view_.rebuild = true;
    } catch (const std::exception& e) {
      sc.note = e.what();
      log_.error(e.what());
    }
  }
  ImGui::EndDisabled();
  ImGui::EndDisabled();
  if (sc.scan_task.busy() || sc.home_task.busy()) {
    const JobStatus st = sc.scan_task.busy() ? sc.scan_task.status() : sc.home_task.status();
    ImGui::ProgressBar(static_cast<float>(st.fraction), ImVec2(-80, 0), st.stage.empty() ? st.name.c_str() : st.stage.c_str());
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
      sc.scan_task.cancel();
      sc.home_task.cancel();
    }
  }
  if (!sc.note.empty()) ImGui::TextWrapped("%s", sc.note.c_str());
  if (sc.preview) {
    if (ImGui::Button("Hide the scan from the 3D view")) {
      sc.preview.reset();
      view_.rebuild = true;
    }
  }
  drawLive();
}

void App::drawReportPopup() {
  if (!ImGui::BeginPopupModal("Trim report", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  ImGui::Text("PDF trim report");
  ImGui::RadioButton("this scan", !report_.whole_test);
  if (ImGui::IsItemClicked()) report_.whole_test = false;
  ImGui::SameLine();
  ImGui::RadioButton("every trim step of its test", report_.whole_test);
  if (ImGui::IsItemClicked()) report_.whole_test = true;
  ImGui::RadioButton("for the crew", report_.audience == 0);
  if (ImGui::IsItemClicked()) report_.audience = 0;
  ImGui::SameLine();
  ImGui::RadioButton("for the designer", report_.audience == 1);
  if (ImGui::IsItemClicked()) report_.audience = 1;
  ImGui::SetNextItemWidth(420);
  ImGui::InputText("file", report_.out_path, sizeof report_.out_path);
  if (ImGui::Button("Write", ImVec2(120, 0))) {
    startReport(report_.out_path, report_.whole_test, report_.audience == 0 ? "crew" : "designer");
    ImGui::CloseCurrentPopup();
  }
  ImGui::SameLine();
  if (ImGui::Button("Close", ImVec2(120, 0))) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

void App::drawStatus(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8, 4));
  if (begin("##status", x, y, w, h, ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar)) {
    const JobStatus st = load_.task.status();
    const JobStatus rs = report_.task.status();
    if (rs.state == JobState::Running) {
      ImGui::Text("writing %s", rs.name.c_str() + 7);
      ImGui::SameLine();
      ImGui::ProgressBar(static_cast<float>(rs.fraction), ImVec2(220, 0), rs.stage.c_str());
    } else if (st.state == JobState::Running) {
      ImGui::Text("%s", st.name.c_str());
      ImGui::SameLine();
      ImGui::ProgressBar(static_cast<float>(st.fraction), ImVec2(220, 0), st.stage.c_str());
      ImGui::SameLine();
      if (ImGui::SmallButton("Cancel")) {
        load_.task.cancel();
        load_.overlay_queue.clear();
      }
    } else if (!log_.lines.empty()) {
      const std::string& last = log_.lines.back();
      ImGui::TextColored(last.rfind("error:", 0) == 0 ? kErrorText : kMutedText, "%s", last.c_str());
    } else {
      ImGui::TextColored(kMutedText, "ready");
    }
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

}  // namespace sailshape::viewer
