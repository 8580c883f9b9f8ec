#pragma once
// What every panel of the window shares: its colours, the fixed-panel window,
// number formatting and the few input widgets with the viewer's own rules.
// Dear ImGui stays in the viewer's .cpp files and this header.
#include <imgui.h>

#include <map>
#include <string>
#include <vector>

#include "viewer/vtk_viewport.hpp"

namespace sailshape::viewer {

// The design's blue and the flying shape's red, as the 3D view draws them.
constexpr ImU32 kDesignColour = IM_COL32(64, 140, 255, 255);
constexpr ImU32 kFlyingColour = IM_COL32(220, 34, 26, 255);
constexpr ImU32 kFittedColour = IM_COL32(26, 166, 166, 255);  // the fitted design layer (vtk_viewport's teal)
constexpr ImU32 kInferredColour = IM_COL32(204, 204, 204, 255);  // its pale, inferred part
inline const ImVec4 kErrorText{1.0f, 0.45f, 0.40f, 1.0f};
inline const ImVec4 kMutedText{0.62f, 0.66f, 0.72f, 1.0f};
inline const ImVec4 kAccentText{1.0f, 0.80f, 0.25f, 1.0f};

ImU32 toU32(const Rgb& c);
ImVec4 toVec4(const Rgb& c);

// `v` through printf's `fmt`; "—" when it is not finite.
std::string format(const char* fmt, double v);
// As format, with the sign always shown (`fmt` starts with '%').
std::string signedFormat(const char* fmt, double v);

// A panel at a fixed place and size in the window (pixels): it cannot be moved,
// resized or collapsed. Call ImGui::End() whatever it returns.
bool beginPanel(const char* name, float x, float y, float w, float h, ImGuiWindowFlags extra = 0);

// A tree node whose label wraps within the panel instead of running out of it:
// the arrow, then the label as wrapped text beside it. `id` must be unique in the
// tree. Returns whether it is open (then call ImGui::TreePop()).
bool wrappedTreeNode(const std::string& id, const std::string& label, ImGuiTreeNodeFlags flags = 0);
// `text` in `colour`, wrapped at the panel's right edge.
void wrappedText(const ImVec4& colour, const std::string& text);
// `text` cut to `width` pixels with "…" when longer (a one-line bar); the whole
// text is the item's tooltip then.
void elidedText(const ImVec4& colour, const std::string& text, float width);
// `text` drawn into `dl` at `at`, wrapped at `width` pixels; returns its height.
float wrappedCaption(ImDrawList* dl, ImVec2 at, ImU32 colour, const std::string& text, float width);

// The windows of the frame just built whose items reach past their content
// region's right edge, by how many pixels: text that neither wraps nor fits, cut off
// at the panel's edge. Keys are ImGui's window names (a child is "Parent/child_…").
// Call between the frame's last End() and the next NewFrame().
std::map<std::string, float> overflowingWindows();

// Puts the next item (`width` px) beside the last one when it still fits inside the
// panel, else on a line of its own: pairs of options stay whole in a narrow window.
void sameLineIfFits(float width);
// The width of a checkbox with `label` (px), for sameLineIfFits.
float checkboxWidth(const char* label);
// The width to give a widget whose `label` is drawn on its right (a slider): `preferred`
// px, less when the panel has not room for both.
float widthBesideLabel(const char* label, float preferred);

// A "(?)" after the last item that shows `text` when hovered.
void helpMarker(const char* text);
// An integer field whose value is kept within [lo, hi].
bool inputInt(const char* label, int* v, int lo, int hi);
// A number field stepping by `step` (by 10 steps with Ctrl).
bool inputDouble(const char* label, double* v, double step, const char* fmt);
// A drop-down of `items` writing the chosen one into `value`.
bool combo(const char* label, std::string* value, const std::vector<const char*>& items);

}  // namespace sailshape::viewer
