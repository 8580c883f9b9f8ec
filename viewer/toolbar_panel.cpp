// The toolbar: the database path, the camera presets and the Report button.
#include "viewer/app.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "viewer/unit_camera.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {

void App::drawToolbar(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8, 6));
  if (beginPanel("##toolbar", x, y, w, h, ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar)) {
    constexpr float kGroupGap = 24;  // px between the path, camera and report groups
    const std::pair<const char*, CameraPreset> presets[] = {
        {"3/4", CameraPreset::ThreeQuarter}, {"Side", CameraPreset::Side}, {"Top", CameraPreset::Top}, {"Astern", CameraPreset::Astern}, {"Bow", CameraPreset::Bow}};
    // The path field takes what the buttons after it leave, up to 28 % of the window; in a
    // narrow window the subtitle goes first, then the field shrinks to 120 px.
    const ImGuiStyle& st = ImGui::GetStyle();
    const auto button = [&](const char* label) { return ImGui::CalcTextSize(label).x + 2 * st.FramePadding.x; };
    float buttons = st.ItemSpacing.x + button("Open") + kGroupGap + ImGui::CalcTextSize("Camera").x;
    for (const auto& [label, preset] : presets) buttons += st.ItemSpacing.x + button(label);
    buttons += st.ItemSpacing.x + button("Unit") + kGroupGap + std::max(button("Report (PDF)"), button("Writing report…"));
    const float end = w - st.WindowPadding.x;
    ImGui::TextColored(kAccentText, "sailshape");
    ImGui::SameLine();
    if (end - 200 - buttons >= 120) {
      ImGui::TextColored(kMutedText, "design vs flying");
      ImGui::SameLine(200);
    }
    const float field = end - (ImGui::GetCursorPosX() + buttons);
    ImGui::SetNextItemWidth(std::clamp(field, 120.0f, std::max(120.0f, w * 0.28f)));
    const bool enter = ImGui::InputTextWithHint("##dbpath", "database file (.sqlite)", database_.path_input,
                                                sizeof database_.path_input, ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    if (ImGui::Button("Open") || enter) openDatabase(database_.path_input);
    ImGui::SameLine(0, kGroupGap);
    ImGui::TextColored(kMutedText, "Camera");
    for (const auto& [label, preset] : presets) {
      ImGui::SameLine();
      if (ImGui::Button(label)) view_.camera = preset;
    }
    ImGui::SameLine();
    const std::optional<CameraPlacement> unit_view = unitPlacement();
    const bool scan_unit = load_.scene && !live_.shown_sweep && scanUnit(load_.scene->record);
    ImGui::BeginDisabled(!unit_view);
    if (ImGui::Button("Unit")) view_.placement = unit_view;
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip(scan_unit ? "from the unit that took this scan (its stored unit settings and registration), "
                                    "looking along its sweep's centre"
                                  : "from the first scanner unit (Scanners tab): at its scanner, looking along its "
                                    "sweep's centre");
    ImGui::SameLine(0, kGroupGap);
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

}  // namespace sailshape::viewer
