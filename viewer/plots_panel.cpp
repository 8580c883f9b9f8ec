// The plots below the 3D view: three section parameters against height.
#include "viewer/app.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {
namespace {

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

void App::drawPlots(float x, float y, float w, float h) {
  if (beginPanel("Sections against height", x, y, w, h, ImGuiWindowFlags_NoScrollbar)) {
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

}  // namespace sailshape::viewer
