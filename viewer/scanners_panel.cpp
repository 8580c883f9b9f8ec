// The Scanners tab: scanner units (from files or emulated), homing, one scan of
// them all with its trim-step data, and saving it; live mode follows (live_panel.cpp).
#include "viewer/app.hpp"

#include <string>

#include "acquisition/scene.hpp"
#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "viewer/unit_camera.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {

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

std::optional<CameraPlacement> App::unitPlacement() const {
  // A stored scan shown is seen from the unit that took it; otherwise from the Scanners tab's first unit.
  const std::optional<UnitConfig> scan_unit =
      load_.scene && !live_.shown_sweep ? scanUnit(load_.scene->record) : std::nullopt;
  if (scan_unit) return unitCamera(*scan_unit);
  if (!scanner_.session.units().empty()) return unitCamera(scanner_.session.units().front().config);
  return std::nullopt;
}

bool App::setUnitCamera() {
  const std::optional<CameraPlacement> placement = unitPlacement();
  if (!placement) {
    log_.error("camera: no scanner unit: the scan shown stores none, and the Scanners tab has none");
    return false;
  }
  view_.placement = *placement;
  return true;
}

void App::drawScanner() {
  ScannerState& sc = scanner_;
  const bool running = sc.scan_task.busy() || sc.home_task.busy() || live_.mode.running();
  ImGui::BeginDisabled(running);
  drawUnits();
  drawTrimStepFields();
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

// Loading and adding units, and each unit's sweep settings with its Home, Remove
// and View from here buttons.
void App::drawUnits() {
  ScannerState& sc = scanner_;
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
}

// The trim-step data stored with the scan (and with every live sweep).
void App::drawTrimStepFields() {
  ScannerState& sc = scanner_;
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
}

}  // namespace sailshape::viewer
