#pragma once
// The 3D view: VTK renders into the framebuffer of a vtkGenericOpenGLRenderWindow
// living on GLFW's OpenGL context; the colour texture is what ImGui::Image shows.
// VTK headers stay in the .cpp.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "viewer/unit_camera.hpp"

namespace sailshape::viewer {

struct ScanScene;
struct StageResult;

using Rgb = std::array<float, 3>;

struct ViewOptions {
  bool design = true;             // blue wireframe
  bool surface = true;            // flying surface
  bool cloud = false;             // raw stored cloud
  bool cluster = false;           // the sail cluster: the points segmentation picked as the sail (cleaned, smoothed)
  bool sections = true;           // flying section curves
  bool design_sections = true;    // design section curves
  bool section_planes = false;    // translucent planes through each section
  bool fitted = false;            // the design fitted onto the flying surface, the inferred part pale
  bool deviation = false;         // colour the flying shape by signed deviation (scalar bar shown)
  float deviation_range_mm = 0;   // ± limit of the colour map; 0: the 95th percentile of |deviation|
  float point_size = 2.0f;
};

enum class CameraPreset { ThreeQuarter, Side, Top, Astern, Bow };

struct Overlay {
  const ScanScene* scene = nullptr;
  Rgb colour{1, 1, 1};
};

// Mouse and keys in viewport pixels (origin top-left), forwarded to VTK's interactor.
struct ViewportInput {
  float x = 0, y = 0;
  bool ctrl = false, shift = false;
  bool pressed[3] = {false, false, false};   // left, right, middle went down this frame
  bool released[3] = {false, false, false};
  float wheel = 0;
  unsigned key_char = 0;                      // a typed character, 0 when none
};

struct PickInfo {
  Vec3 point = Vec3::Zero();                  // boat frame, metres
  std::optional<double> deviation_m;          // signed, positive to leeward
  std::string what;                           // "flying surface", "cloud", ...
};

class VtkViewport {
 public:
  VtkViewport();  // needs the current OpenGL context (GLFW's)
  ~VtkViewport();
  VtkViewport(const VtkViewport&) = delete;
  VtkViewport& operator=(const VtkViewport&) = delete;

  // Rebuilds the actors; pointers must stay valid until the next call.
  void setScene(const ScanScene* scene, const std::vector<Overlay>& overlays, const ViewOptions& options,
                const StageResult* processing = nullptr);
  void setCamera(CameraPreset preset);
  void setCamera(const CameraPlacement& placement);  // e.g. unitCamera(): the view from a scanner unit
  void resetCamera();

  // Renders at width × height pixels; returns the GL texture to show (owned by
  // VTK, valid until the next render), 0 when either size is 0.
  unsigned render(int width, int height);
  void forward(const ViewportInput& input);
  // Picks the flying shape at viewport pixel (x, y), origin top-left.
  std::optional<PickInfo> pick(float x, float y);
  // The ± deviation limit the colour map uses, mm (0 without deviation colouring).
  double deviationLimitMm() const;

 private:
  // setScene's layers: the scene's own (design, surface, clouds, sections), the
  // overlaid scans', and a processing stage's points.
  void addSceneLayers(const ScanScene& scene, const ViewOptions& options);
  void addOverlays(const std::vector<Overlay>& overlays, const ViewOptions& options);
  void addProcessingLayer(const StageResult& processing, const ViewOptions& options);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sailshape::viewer
