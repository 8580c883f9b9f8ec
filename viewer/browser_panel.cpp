// The Database panel: the catalogue tree (campaign, test, trim step, scan) with
// the overlay ticks, and below it the 3D view's display options.
#include "viewer/app.hpp"

#include <algorithm>
#include <filesystem>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {

void App::drawBrowser(float x, float y, float w, float h) {
  if (beginPanel("Database", x, y, w, h)) {
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
        // Long campaign, test and step names wrap in the panel rather than run out of it.
        if (!wrappedTreeNode("c" + c.name, c.name, ImGuiTreeNodeFlags_DefaultOpen)) continue;
        for (const auto& t : c.tests) {
          if (!wrappedTreeNode("t" + c.name + t.name, t.label(), ImGuiTreeNodeFlags_DefaultOpen)) continue;
          for (const auto& s : t.steps) {
            const std::string id = "s" + c.name + t.name + s.sail + std::to_string(s.step);
            const bool open = wrappedTreeNode(id, s.label(), ImGuiTreeNodeFlags_DefaultOpen);
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
              // The point count when the tree has room for it, else in the tooltip.
              const std::string name = "scan " + std::to_string(scan.scan_id);
              const std::string points = scan.point_count ? std::to_string(scan.point_count) + " pts" : std::string();
              const std::string full = points.empty() ? name : name + "  " + points;
              const bool fits = ImGui::CalcTextSize(full.c_str()).x <= ImGui::GetContentRegionAvail().x;
              if (ImGui::Selectable(fits ? full.c_str() : name.c_str(), browser_.selected_scan == scan.scan_id))
                selectScan(scan.scan_id);
              if (!fits && !points.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", points.c_str());
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
  // The colour key where the panel has room for it.
  const bool key = checkboxWidth("design (blue wireframe)") <= ImGui::GetContentRegionAvail().x;
  changed |= ImGui::Checkbox(key ? "design (blue wireframe)###design" : "design###design", &o.design);
  changed |= ImGui::Checkbox("flying surface", &o.surface);
  sameLineIfFits(checkboxWidth("raw cloud"));
  changed |= ImGui::Checkbox("raw cloud", &o.cloud);
  changed |= ImGui::Checkbox("sail cluster", &o.cluster);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the points segmentation took for the sail, cleaned and smoothed");
  changed |= ImGui::Checkbox("sections", &o.sections);
  sameLineIfFits(checkboxWidth("design sections"));
  changed |= ImGui::Checkbox("design sections", &o.design_sections);
  changed |= ImGui::Checkbox("section planes", &o.section_planes);
  changed |= ImGui::Checkbox("fitted design", &o.fitted);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("the design fitted to the scan: the whole sail, pale where the scan has no samples and the "
                      "fit carried the shape on from around");
  changed |= ImGui::Checkbox("deviation colours", &o.deviation);
  if (o.deviation) {
    ImGui::SetNextItemWidth(widthBesideLabel("± mm", 140));
    changed |= ImGui::SliderFloat("± mm", &o.deviation_range_mm, 0.0f, 300.0f, o.deviation_range_mm > 0 ? "%.0f" : "auto");
  }
  ImGui::SetNextItemWidth(widthBesideLabel("point size", 140));
  changed |= ImGui::SliderFloat("point size", &o.point_size, 1.0f, 6.0f, "%.0f");
  if (changed) view_.rebuild = true;
}

}  // namespace sailshape::viewer
