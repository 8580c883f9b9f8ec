// The Trim steps tab: one section parameter of the selected scan and of every
// overlaid trim step, side by side at each section height.
#include "viewer/app.hpp"

#include <cmath>
#include <vector>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {

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

}  // namespace sailshape::viewer
