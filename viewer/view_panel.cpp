// The 3D view: VTK's picture, the mouse forwarded to it, and the captions drawn over it.
#include "viewer/app.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "viewer/widgets.hpp"

namespace sailshape::viewer {

std::string App::viewTitle() const {
  if (!load_.scene) return "";
  const ScanRecord& r = load_.scene->record;
  std::string title = r.campaign + " · " + (r.test.empty() ? "" : r.test + " · ") + "step " + std::to_string(r.step) +
                      " · " + r.sail;
  if (live_.shown_sweep) title = "LIVE sweep " + std::to_string(live_.shown_sweep) + " · " + title;
  if (r.awa_deg) title += " · AWA " + format("%.0f°", *r.awa_deg);
  return title;
}

std::string deviationCaption(const DistanceStats& d) {
  return "deviation from design (+ to leeward): mean " + format("%+.0f", 1000 * d.mean_m) + " mm, rms " +
         format("%.0f", 1000 * d.rms_m) + " mm, max |" + format("%.0f", 1000 * d.max_abs_m) + "| mm";
}

void App::drawView(float x, float y, float w, float h) {
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  // The mouse hint rides in the title bar, where it never covers the sail (in live mode the
  // unit's view puts the sail anywhere in the picture).
  if (beginPanel("3D view      drag: rotate · right/wheel: zoom · middle: pan · click: pick###3D view", x, y, w, h,
                 ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse)) {
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const int vw = static_cast<int>(avail.x), vh = static_cast<int>(avail.y);
    if (view_.rebuild) {
      const StageResult* proc = scanner_.preview                                          ? &*scanner_.preview
                                : processing_.show_result && processing_.result &&
                                          processing_.result_scan == browser_.selected_scan
                                    ? &*processing_.result
                                    : nullptr;
      viewport_->setScene(load_.scene ? &*load_.scene : nullptr, overlayList(), view_.options, proc);
      view_.rebuild = false;
    }
    if (view_.camera) {
      viewport_->setCamera(*view_.camera);
      view_.camera.reset();
    }
    if (view_.placement) {
      viewport_->setCamera(*view_.placement);
      view_.placement.reset();
    }
    view_.hovered = false;
    // A zero-size view (tiny window, minimised) renders nothing and keeps VTK's last framebuffer.
    if (vw > 0 && vh > 0) {
      const unsigned tex = viewport_->render(vw, vh);
      view_.width = vw;
      view_.height = vh;
      const ImVec2 origin = ImGui::GetCursorScreenPos();
      if (tex) {
        ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(tex)), avail, ImVec2(0, 1), ImVec2(1, 0));
      } else {
        ImGui::Dummy(avail);
      }
      view_.hovered = ImGui::IsItemHovered();
      forwardViewInput(origin.x, origin.y);
      if (pick_.pending) {
        pick_.info = viewport_->pick((*pick_.pending)[0] * avail.x, (*pick_.pending)[1] * avail.y);
        pick_.pending.reset();
      }
      drawViewCaptions(origin.x, origin.y, avail.x, avail.y);
    }
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

// Mouse and keys to VTK, origin: the view's top-left corner on screen (pixels); a click
// (press and release within 3 px) picks.
void App::forwardViewInput(float origin_x, float origin_y) {
  ImGuiIO& io = ImGui::GetIO();
  const float mx = io.MousePos.x - origin_x, my = io.MousePos.y - origin_y;
  // Events go to VTK only while the view is hovered; releases also when a drag began here.
  if (view_.hovered || pick_.pressed_in_view) {
    ViewportInput in;
    in.x = mx;
    in.y = my;
    in.ctrl = io.KeyCtrl;
    in.shift = io.KeyShift;
    for (int b = 0; b < 3; ++b) {
      in.pressed[b] = view_.hovered && io.MouseClicked[b];
      in.released[b] = io.MouseReleased[b] && pick_.pressed_in_view;
    }
    if (view_.hovered) {
      in.wheel = io.MouseWheel;
      if (!io.InputQueueCharacters.empty()) in.key_char = io.InputQueueCharacters[0];
    }
    if (in.pressed[0]) {
      pick_.press_x = mx;
      pick_.press_y = my;
    }
    const bool click = in.released[0] && std::hypot(mx - pick_.press_x, my - pick_.press_y) < 3.0f;
    if (in.pressed[0] || in.pressed[1] || in.pressed[2]) pick_.pressed_in_view = true;
    viewport_->forward(in);
    if (click) pick_.info = viewport_->pick(mx, my);
    if (!io.MouseDown[0] && !io.MouseDown[1] && !io.MouseDown[2]) pick_.pressed_in_view = false;
  }
}

// The scan's title, the legend, the deviation summary, the last pick and the mouse hint,
// over the view at (origin_x, origin_y), w × h pixels.
void App::drawViewCaptions(float origin_x, float origin_y, float w, float h) {
  const ImVec2 origin(origin_x, origin_y), avail(w, h);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  float ty = origin.y + 10;
  auto legend = [&](ImU32 col, const std::string& text) {
    dl->AddRectFilled(ImVec2(origin.x + 12, ty + 3), ImVec2(origin.x + 26, ty + 13), col, 2.0f);
    dl->AddText(ImVec2(origin.x + 32, ty), IM_COL32(235, 235, 240, 255), text.c_str());
    ty += 18;
  };
  // Captions wrap within the view rather than run out of it.
  const float wrap = std::max(avail.x - 24, 40.0f);
  if (load_.scene) {
    ty += wrappedCaption(dl, ImVec2(origin.x + 12, ty), IM_COL32(255, 210, 90, 255), viewTitle(), wrap) + 4;
    if (!load_.scene->design.empty()) legend(kDesignColour, "design");
    if (!load_.scene->surface.empty() || !load_.scene->raw_cloud.empty())
      legend(kFlyingColour, load_.scene->record.scan_id ? "flying, scan " + std::to_string(load_.scene->record.scan_id)
                                                        : std::string("flying, not stored"));
    if (view_.options.fitted && load_.scene->fitted) {
      const DesignFit& f = *load_.scene->fitted;
      legend(kFittedColour, "design fitted to the scan");
      if (f.coverage < 1)
        legend(kInferredColour, "pale: inferred, no sample (" + std::to_string(static_cast<int>(std::lround(100 * (1 - f.coverage)))) +
                                    " % of the area)");
    }
    for (const auto& ov : overlayList())
      legend(toU32(ov.colour), "step " + std::to_string(ov.scene->record.step) + ", scan " +
                                   std::to_string(ov.scene->record.scan_id));
    if (load_.scene->deviation)
      ty += wrappedCaption(dl, ImVec2(origin.x + 12, ty + 4), IM_COL32(200, 205, 215, 255),
                           deviationCaption(*load_.scene->deviation), wrap) + 8;
  } else {
    const char* msg = !database_.db ? (database_.error.empty() ? "No database open" : database_.error.c_str())
                      : browser_.tree.scan_count == 0 ? "The database has no scans"
                      : load_.task.busy()             ? "Loading scan…"
                                                      : "Select a scan in the database browser";
    const ImVec2 ts = ImGui::CalcTextSize(msg);
    dl->AddText(ImVec2(origin.x + (avail.x - ts.x) / 2, origin.y + (avail.y - ts.y) / 2),
                database_.error.empty() ? IM_COL32(210, 215, 225, 255) : IM_COL32(255, 120, 110, 255), msg);
  }
  if (pick_.info) {
    const PickInfo& p = *pick_.info;
    std::string text = p.what + "  x " + format("%.3f", p.point.x()) + "  y " + format("%.3f", p.point.y()) +
                       "  z " + format("%.3f", p.point.z()) + " m";
    if (p.deviation_m) text += "   deviation " + format("%+.1f", 1000 * *p.deviation_m) + " mm";
    const ImVec2 ts = ImGui::CalcTextSize(text.c_str());
    const ImVec2 at(origin.x + 12, origin.y + avail.y - ts.y - 14);
    dl->AddRectFilled(ImVec2(at.x - 6, at.y - 4), ImVec2(at.x + ts.x + 6, at.y + ts.y + 4), IM_COL32(0, 0, 0, 170), 4);
    dl->AddText(at, IM_COL32(255, 240, 120, 255), text.c_str());
  }
}

}  // namespace sailshape::viewer
