// sailshape-viewer [DB]: the designer's desk. Dear ImGui on GLFW (OpenGL 3.2
// core), VTK drawing the 3D view into a texture on the same context.
#include <GLFW/glfw3.h>
#include <GL/gl.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "viewer/app.hpp"

namespace {

using namespace sailshape::viewer;

struct Options {
  std::optional<std::string> database;
  std::string screenshot;
  int frames = 0;
  int width = 1600, height = 1000;
  bool exercise_window = false;
  bool deviation = false;
  std::vector<float> pick;  // --pick FX,FY: fractions of the 3D view
  std::string report;  // --report: write this PDF once the first scan is loaded (scripted Report button)
  std::vector<std::string> show;  // --show: what the 3D view draws
  int live = 0;        // --live N: live mode on an emulated deck unit until N sweeps are analysed
  std::string camera;  // --camera: a preset applied before frames are counted
  std::string state;   // --state: the panels' content as JSON, written with the screenshot
};

void writeState(const App& app, const std::string& path) {
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp);
    out << app.state().dump(2) << "\n";
    if (!out.flush()) throw std::runtime_error("cannot write " + path);
  }
  std::filesystem::rename(tmp, path);
}

// --show design,surface,cluster,...: exactly these layers in the 3D view.
ViewOptions shownLayers(ViewOptions o, const std::vector<std::string>& layers) {
  o.design = o.surface = o.cloud = o.cluster = o.sections = o.design_sections = o.section_planes = o.fitted = false;
  for (const std::string& l : layers) {
    if (l == "design") o.design = true;
    else if (l == "surface") o.surface = true;
    else if (l == "cloud") o.cloud = true;
    else if (l == "cluster") o.cluster = true;
    else if (l == "sections") o.sections = true;
    else if (l == "design-sections") o.design_sections = true;
    else if (l == "planes") o.section_planes = true;
    else if (l == "fitted") o.fitted = true;
    else throw CLI::ValidationError("--show", "unknown layer '" + l + "' (design, surface, cloud, cluster, sections, design-sections, planes, fitted)");
  }
  return o;
}

// GLFW for the process: initialised once, terminated on scope exit.
struct GlfwLibrary {
  GlfwLibrary() {
    glfwSetErrorCallback([](int code, const char* text) { std::cerr << "sailshape-viewer: GLFW error " << code << ": " << text << "\n"; });
    if (!glfwInit()) throw std::runtime_error("[sailshape-viewer] cannot initialise GLFW (no display? set DISPLAY or run under xvfb-run)");
  }
  ~GlfwLibrary() { glfwTerminate(); }
  GlfwLibrary(const GlfwLibrary&) = delete;
  GlfwLibrary& operator=(const GlfwLibrary&) = delete;
};

struct GlfwWindow {
  GLFWwindow* handle = nullptr;
  GlfwWindow(int width, int height, const char* title) {
    // VTK's OpenGL2 backend needs a 3.2 core context.
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 2);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    handle = glfwCreateWindow(width, height, title, nullptr, nullptr);
    if (!handle) throw std::runtime_error("[sailshape-viewer] cannot create a " + std::to_string(width) + "×" +
                                          std::to_string(height) + " OpenGL 3.2 window");
    glfwMakeContextCurrent(handle);
  }
  ~GlfwWindow() { glfwDestroyWindow(handle); }
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;
};

struct ImGuiContextScope {
  explicit ImGuiContextScope(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // the layout is fixed; nothing to remember
    if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 150"))
      throw std::runtime_error("[sailshape-viewer] cannot initialise Dear ImGui's GLFW/OpenGL3 backends");
  }
  ~ImGuiContextScope() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiContextScope(const ImGuiContextScope&) = delete;
  ImGuiContextScope& operator=(const ImGuiContextScope&) = delete;
};

void setStyle() {
  ImGuiIO& io = ImGui::GetIO();
  // Latin-1 (°, ², ·), Greek (σ), dashes and the minus sign.
  static const ImWchar ranges[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2010, 0x2027, 0x2212, 0x2212, 0x25A0, 0x25A0, 0};
  const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  if (std::filesystem::exists(font)) io.Fonts->AddFontFromFileTTF(font, 15.0f, nullptr, ranges);
  ImGui::StyleColorsDark();
  ImGuiStyle& s = ImGui::GetStyle();
  s.WindowRounding = 0;
  s.FrameRounding = 3;
  s.GrabRounding = 3;
  s.TabRounding = 3;
  s.WindowBorderSize = 1;
  s.FramePadding = ImVec2(6, 3);
  s.ItemSpacing = ImVec2(8, 5);
  ImVec4* c = s.Colors;
  c[ImGuiCol_WindowBg] = ImVec4(0.105f, 0.115f, 0.135f, 1.0f);
  c[ImGuiCol_ChildBg] = ImVec4(0.085f, 0.095f, 0.110f, 1.0f);
  c[ImGuiCol_TitleBg] = ImVec4(0.13f, 0.16f, 0.21f, 1.0f);
  c[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.22f, 0.32f, 1.0f);
  c[ImGuiCol_Header] = ImVec4(0.20f, 0.32f, 0.50f, 0.70f);
  c[ImGuiCol_HeaderHovered] = ImVec4(0.26f, 0.42f, 0.65f, 0.80f);
  c[ImGuiCol_Button] = ImVec4(0.20f, 0.30f, 0.45f, 1.0f);
  c[ImGuiCol_ButtonHovered] = ImVec4(0.27f, 0.42f, 0.62f, 1.0f);
  c[ImGuiCol_FrameBg] = ImVec4(0.16f, 0.18f, 0.22f, 1.0f);
  c[ImGuiCol_Tab] = ImVec4(0.15f, 0.20f, 0.28f, 1.0f);
  c[ImGuiCol_TabActive] = ImVec4(0.22f, 0.34f, 0.52f, 1.0f);
  c[ImGuiCol_TableRowBgAlt] = ImVec4(1, 1, 1, 0.03f);
}

// Reads the back buffer (what the frame just drew) and writes it as PNG, top row first.
void saveScreenshot(const std::string& path, int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::runtime_error("[saveScreenshot] the window has no pixels (" + std::to_string(width) + "×" +
                             std::to_string(height) + ")");
  std::vector<unsigned char> rgba(static_cast<size_t>(width) * height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  const size_t row = static_cast<size_t>(width) * 4;
  std::vector<unsigned char> flipped(rgba.size());
  for (int y = 0; y < height; ++y)
    std::copy_n(rgba.data() + row * (height - 1 - y), row, flipped.data() + row * y);
  for (size_t i = 3; i < flipped.size(); i += 4) flipped[i] = 255;
  if (!stbi_write_png(path.c_str(), width, height, 4, flipped.data(), static_cast<int>(row)))
    throw std::runtime_error("[saveScreenshot] cannot write " + path);
}

// --exercise-window: what a user does to a window, scripted over counted frames
// (shrink until the 3D view has no pixels, minimise, restore, grow back).
void exerciseWindow(GLFWwindow* window, int frame, const Options& o) {
  switch (frame) {
    case 1: glfwSetWindowSize(window, 640, 400); break;
    case 4: glfwSetWindowSize(window, 160, 90); break;
    case 7: glfwIconifyWindow(window); break;
    case 10: glfwRestoreWindow(window); break;
    case 13: glfwSetWindowSize(window, o.width, o.height); break;
    default: break;
  }
}

int run(const Options& o) {
  GlfwLibrary glfw;
  GlfwWindow window(o.width, o.height, "sailshape viewer");
  glfwSwapInterval(o.screenshot.empty() ? 1 : 0);
  ImGuiContextScope imgui(window.handle);
  setStyle();
  using BindFramebuffer = void (*)(GLenum, GLuint);
  const auto bind_framebuffer = reinterpret_cast<BindFramebuffer>(glfwGetProcAddress("glBindFramebuffer"));

  App app(o.database);
  if (o.deviation) app.setDeviationView(true);
  if (!o.show.empty()) app.setViewOptions(shownLayers(app.viewOptions(), o.show));
  const bool shooting = !o.screenshot.empty();
  int counted = 0;
  bool report_started = o.report.empty();
  bool live_started = o.live == 0, live_printed = o.live == 0;
  bool camera_set = o.camera.empty();
  bool pick_requested = o.pick.empty(), pick_printed = o.pick.empty();
  const auto started = std::chrono::steady_clock::now();
  bool timed_out = false;
  while (!glfwWindowShouldClose(window.handle)) {
    if (shooting) glfwPollEvents();
    else glfwWaitEventsTimeout(app.busy() ? 0.03 : 0.25);
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window.handle, &fb_w, &fb_h);

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    app.frame(display.x, display.y);
    ImGui::Render();

    if (bind_framebuffer) bind_framebuffer(GL_FRAMEBUFFER, 0);  // VTK drew into its own
    if (fb_w > 0 && fb_h > 0) {
      glViewport(0, 0, fb_w, fb_h);
      glClearColor(0.08f, 0.09f, 0.10f, 1.0f);
      glClear(GL_COLOR_BUFFER_BIT);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }

    if (shooting) {
      // Frames count once the scan on screen has finished loading, so N frames
      // always show the same thing however fast the machine is.
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      if (!app.settled() && waited > 300) timed_out = true;
      if (!pick_requested && app.settled()) {
        app.requestPick(o.pick[0], o.pick[1]);
        pick_requested = true;
      } else if (pick_requested && !pick_printed && !app.pickPending()) {
        pick_printed = true;
        if (const auto& p = app.lastPick()) {
          std::printf("picked %s at %.4f %.4f %.4f m", p->what.c_str(), p->point.x(), p->point.y(), p->point.z());
          if (p->deviation_m) std::printf(", deviation %+.1f mm", 1000 * *p->deviation_m);
          std::printf("\n");
        } else {
          std::printf("picked nothing\n");
        }
        std::fflush(stdout);
      }
      if (!live_started && app.settled()) {
        live_started = true;
        app.storeLiveSweeps(app.databaseOpen());
        if (!app.addEmulatedDeckUnit() || !app.startLive()) return 1;
        continue;  // count frames once live mode has ended
      }
      if (live_started && !live_printed) {
        const LiveStatus st = app.liveStatus();
        // Sweeps whose analysis fails do not count: live mode runs on until N are analysed (at most 10·N sweeps).
        if (st.running && (st.analysed >= o.live || st.swept >= 10 * o.live)) app.stopLive();
        if (!st.running && app.settled()) {
          live_printed = true;
          std::printf("live: %d swept, %d analysed, %d failed%s%s\n", st.swept, st.analysed, st.failed,
                      st.error.empty() ? "" : ", ended: ", st.error.c_str());
          std::fflush(stdout);
        }
        if (!live_printed) continue;
      }
      if (!camera_set && app.settled()) {
        camera_set = true;
        const std::pair<const char*, CameraPreset> presets[] = {{"3/4", CameraPreset::ThreeQuarter},
                                                                {"side", CameraPreset::Side},
                                                                {"top", CameraPreset::Top},
                                                                {"astern", CameraPreset::Astern},
                                                                {"bow", CameraPreset::Bow}};
        for (const auto& [name, preset] : presets)
          if (o.camera == name) app.setCamera(preset);
        if (o.camera == "unit" && !app.setUnitCamera()) return 1;
      }
      if (!report_started && app.settled()) {
        report_started = true;
        if (!app.startReport(o.report, false, "designer")) return 1;
        continue;  // count frames once the report is written
      }
      if (app.settled() || timed_out) {
        ++counted;
        if (o.exercise_window) exerciseWindow(window.handle, counted, o);
      }
      if (counted >= o.frames) {
        saveScreenshot(o.screenshot, fb_w, fb_h);
        std::cout << "sailshape-viewer: wrote " << o.screenshot << " (" << fb_w << "×" << fb_h << ", " << counted
                  << " frames)\n";
        if (!o.state.empty()) writeState(app, o.state);
        glfwSwapBuffers(window.handle);
        // The screenshot shows the panels' message; the exit status tells a script (the one line on
        // stderr was written when the open failed).
        if (o.database && !app.databaseOpen()) return 1;
        if (timed_out) {
          std::cerr << "sailshape-viewer: the scan was still loading after 300 s; the screenshot shows the state then\n";
          return 1;
        }
        return 0;
      }
    }
    glfwSwapBuffers(window.handle);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App cli("sailshape-viewer: design against flying sail shapes from a sailshape database");
  cli.add_option("database", o.database, "sailshape database file (.sqlite) to open; a missing file is reported, not created");
  cli.add_option("--screenshot", o.screenshot, "render --frames frames, save a PNG of the whole window to this file and exit");
  cli.add_option("--frames", o.frames, "frames to render before the screenshot, counted once the first scan has loaded")
      ->check(CLI::Range(1, 100000));
  cli.add_option("--width", o.width, "window width in pixels")->check(CLI::Range(160, 8192));
  cli.add_option("--height", o.height, "window height in pixels")->check(CLI::Range(90, 8192));
  cli.add_flag("--exercise-window", o.exercise_window,
               "with --screenshot: resize the window down to a zero-size 3D view, minimise and restore it during the "
               "frames (needs --frames >= 16)");
  cli.add_option("--report", o.report,
                 "with --screenshot: once the first scan is loaded, write its PDF trim report (designer) here, as the "
                 "Report button does, before counting frames");
  cli.add_option("--pick", o.pick,
                 "with --screenshot: once the first scan is loaded, pick as a click at FX,FY (fractions of the 3D "
                 "view, from its top left) and print the point and its deviation")
      ->expected(2)
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1.0));
  cli.add_option("--show", o.show,
                 "what the 3D view draws, comma-separated: design, surface, cloud, cluster (the sail points "
                 "segmentation picked), sections, design-sections, planes, fitted (the design fitted to the scan, "
                 "pale where inferred) (default: design, surface, sections, design-sections)")
      ->delimiter(',');
  cli.add_option("--live", o.live,
                 "with --screenshot: add an emulated deck unit and run live mode (every sweep stored in the open "
                 "database) until N sweeps are analysed (a sweep already taken then is analysed too), then count frames")
      ->check(CLI::Range(1, 20));
  cli.add_option("--camera", o.camera,
                 "with --screenshot: once loaded, view from this preset: 3/4, side, top, astern, bow, or unit (from "
                 "the first scanner unit, e.g. the one --live adds)")
      ->check(CLI::IsMember({"3/4", "side", "top", "astern", "bow", "unit"}));
  cli.add_option("--state", o.state,
                 "with --screenshot: also write what the panels show as JSON to this file (the scan shown and its "
                 "captions, design-vs-flying statistics in mm, the section table, the browser's labels, messages, and "
                 "overflow_px: any panel whose content runs past its right edge)");
  cli.add_flag("--deviation", o.deviation, "start with the flying shape coloured by signed deviation from the design");
  try {
    cli.parse(argc, argv);
    if (!o.screenshot.empty() && o.frames == 0) throw CLI::ValidationError("--screenshot", "needs --frames N");
    if (o.screenshot.empty() && (o.frames || o.exercise_window || !o.report.empty() || !o.pick.empty() || o.live ||
                                !o.camera.empty() || !o.state.empty()))
      throw CLI::ValidationError("--frames",
                                 "--frames, --exercise-window, --report, --pick, --live, --camera and --state need "
                                 "--screenshot");
    shownLayers(ViewOptions{}, o.show);
    if (o.exercise_window && o.frames < 16) throw CLI::ValidationError("--exercise-window", "needs --frames >= 16");
  } catch (const CLI::ParseError& e) {
    return cli.exit(e);
  }
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::cerr << "sailshape-viewer: " << e.what() << "\n";
    return 1;
  }
}
