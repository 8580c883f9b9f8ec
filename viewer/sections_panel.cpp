// The Sections tab: the deviation from the design and, per section, design,
// flying, their difference and its uncertainty.
#include "viewer/app.hpp"

#include <cmath>
#include <string>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {

std::string deviationSummary(const DistanceStats& d) {
  return "mean " + signedFormat("%.0f", 1000 * d.mean_m) + "  rms " + format("%.0f", 1000 * d.rms_m) + "  p5 " +
         signedFormat("%.0f", 1000 * d.p5_m) + "  p50 " + signedFormat("%.0f", 1000 * d.p50_m) + "  p95 " +
         signedFormat("%.0f", 1000 * d.p95_m) + "  max |" + format("%.0f", 1000 * d.max_abs_m) + "| mm";
}

void App::drawSectionTable() {
  if (!load_.scene) {
    ImGui::TextColored(kMutedText, "No scan shown.");
    return;
  }
  const ScanScene& s = *load_.scene;
  if (s.deviation) {
    const DistanceStats& d = s.deviation.value();
    wrappedText(ImGui::GetStyleColorVec4(ImGuiCol_Text), "Flying − design, signed (+ leeward), " + std::to_string(d.count) + " points");
    wrappedText(kMutedText, deviationSummary(d));
    // Far from its design beyond any plausible trim: most likely another sail, or the wrong design.
    if (!s.design_mismatch.empty()) wrappedText(kErrorText, s.design_mismatch);
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
      ImGui::TableSetupColumn("", ImGuiTableColumnFlags_WidthFixed);  // the names whole; the numbers share the rest
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
    for (const auto& wmsg : s.warnings) wrappedText(kMutedText, "· " + wmsg);
  }
}

}  // namespace sailshape::viewer
