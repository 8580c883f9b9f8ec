// Live mode, at the foot of the Scanners tab: sweep after sweep, each analysed
// while the next runs, the panels following the latest.
#include "viewer/app.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "database/catalog.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {

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

}  // namespace sailshape::viewer
