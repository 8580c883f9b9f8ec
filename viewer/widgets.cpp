#include "viewer/widgets.hpp"

#include <imgui_internal.h>

#include <algorithm>
#include <cmath>
#include <cfloat>
#include <cstdio>

namespace sailshape::viewer {

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

bool beginPanel(const char* name, float x, float y, float w, float h, ImGuiWindowFlags extra) {
  constexpr ImGuiWindowFlags kPanelFlags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize |
                                           ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;
  ImGui::SetNextWindowPos(ImVec2(x, y));
  ImGui::SetNextWindowSize(ImVec2(std::max(w, 1.0f), std::max(h, 1.0f)));
  return ImGui::Begin(name, nullptr, kPanelFlags | extra);
}

bool wrappedTreeNode(const std::string& id, const std::string& label, ImGuiTreeNodeFlags flags) {
  const bool open = ImGui::TreeNodeEx(("##" + id).c_str(), flags);
  ImGui::SameLine(0, ImGui::GetStyle().ItemInnerSpacing.x);
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextUnformatted(label.c_str());
  ImGui::PopTextWrapPos();
  return open;
}

void wrappedText(const ImVec4& colour, const std::string& text) {
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextUnformatted(text.c_str());
  ImGui::PopTextWrapPos();
  ImGui::PopStyleColor();
}

void elidedText(const ImVec4& colour, const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) {
    ImGui::TextColored(colour, "%s", text.c_str());
    return;
  }
  const char* ellipsis = "…";
  const float room = width - ImGui::CalcTextSize(ellipsis).x;
  size_t keep = text.size();
  while (keep > 0 && ImGui::CalcTextSize(text.c_str(), text.c_str() + keep).x > room) {
    --keep;
    while (keep > 0 && (static_cast<unsigned char>(text[keep]) & 0xC0) == 0x80) --keep;  // whole UTF-8 characters
  }
  ImGui::TextColored(colour, "%s%s", text.substr(0, keep).c_str(), ellipsis);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text.c_str());
}

float wrappedCaption(ImDrawList* dl, ImVec2 at, ImU32 colour, const std::string& text, float width) {
  ImFont* font = ImGui::GetFont();
  const float size = ImGui::GetFontSize();
  dl->AddText(font, size, at, colour, text.c_str(), nullptr, width);
  return font->CalcTextSizeA(size, FLT_MAX, width, text.c_str()).y;
}

void sameLineIfFits(float width) {
  const float right = ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x + width;
  if (right <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) ImGui::SameLine();
}

float checkboxWidth(const char* label) {
  return ImGui::GetFrameHeight() + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(label, nullptr, true).x;
}

float widthBesideLabel(const char* label, float preferred) {
  const float room = ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemInnerSpacing.x -
                     ImGui::CalcTextSize(label, nullptr, true).x;
  return std::max(1.0f, std::min(preferred, room));
}

std::map<std::string, float> overflowingWindows() {
  std::map<std::string, float> out;
  const ImGuiContext* g = ImGui::GetCurrentContext();
  if (!g) return out;
  for (const ImGuiWindow* w : g->Windows) {
    if (!w->Active || w->Hidden || w->Collapsed) continue;
    // CursorMaxPos is the furthest any item of this frame reached (px, screen space);
    // WorkRect is where items may go, inside the padding and any scrollbar. Half a pixel
    // absorbs the rounding of glyph advances.
    const float past = w->DC.CursorMaxPos.x - w->WorkRect.Max.x;
    if (past > 0.5f) out[w->Name] = past;
  }
  return out;
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

}  // namespace sailshape::viewer
