// The message log as shown: the status bar (running job or last message) and the Messages tab.
#include "viewer/app.hpp"

#include <string>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {

void App::drawStatus(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(8, 4));
  if (beginPanel("##status", x, y, w, h, ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar)) {
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
      // One line: the whole message is in the Messages tab and the tooltip.
      elidedText(last.rfind("error:", 0) == 0 ? kErrorText : kMutedText, last, ImGui::GetContentRegionAvail().x);
    } else {
      ImGui::TextColored(kMutedText, "ready");
    }
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

void App::drawMessages() {
  for (const auto& line : log_.lines) {
    const bool err = line.rfind("error:", 0) == 0;
    if (err) ImGui::PushStyleColor(ImGuiCol_Text, kErrorText);
    ImGui::TextWrapped("%s", line.c_str());
    if (err) ImGui::PopStyleColor();
  }
}

}  // namespace sailshape::viewer
