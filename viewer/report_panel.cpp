// The Report button's dialog and the report it writes on the worker.
#include "viewer/app.hpp"

#include "reports/trim_report.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {

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

}  // namespace sailshape::viewer
