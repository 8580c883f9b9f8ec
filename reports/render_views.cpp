#include "reports/render_views.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "analysis/core/errors.hpp"

// LeakSanitizer's switch, present only in sanitizer builds (weak: null otherwise).
extern "C" void __lsan_disable() __attribute__((weak));
extern "C" void __lsan_enable() __attribute__((weak));

namespace sailshape {
namespace {

// Mesa's GL driver, which VTK's render window loads, leaks a few hundred bytes
// per window and is unloaded before LeakSanitizer looks, so its leaks cannot be
// suppressed by module name: allocations made during the renders are exempted.
struct LeakCheckPause {
  LeakCheckPause() {
    if (__lsan_disable) __lsan_disable();
  }
  ~LeakCheckPause() {
    if (__lsan_enable) __lsan_enable();
  }
  LeakCheckPause(const LeakCheckPause&) = delete;
  LeakCheckPause& operator=(const LeakCheckPause&) = delete;
};

enum class View { Side, Top, Astern };

vtkNew<vtkPoints> toPoints(const Mesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), mesh.vertices[i].data());
  return points;
}

vtkNew<vtkPolyData> surfaceOf(const Mesh& mesh) {
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(toPoints(mesh));
  vtkNew<vtkCellArray> cells;
  for (const auto& t : mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    cells->InsertNextCell(3, ids);
  }
  poly->SetPolys(cells);
  return poly;
}

vtkNew<vtkPolyData> gridOf(const Mesh& mesh) {
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(toPoints(mesh));
  vtkNew<vtkCellArray> lines;
  for (const auto& e : gridEdges(mesh)) {
    const vtkIdType ids[2] = {e[0], e[1]};
    lines->InsertNextCell(2, ids);
  }
  poly->SetLines(lines);
  return poly;
}

// Smooth-shaded actor of a surface; with colours when `colours` is given.
vtkNew<vtkActor> surfaceActor(vtkPolyData* poly) {
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(poly);
  normals->SplittingOff();
  normals->ConsistencyOn();
  normals->Update();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(normals->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  // Mostly ambient: a sail seen edge-on (from above, from astern) stays red, not black.
  actor->GetProperty()->SetAmbient(0.55);
  actor->GetProperty()->SetDiffuse(0.45);
  actor->GetProperty()->SetSpecular(0.1);
  return actor;
}

// Parallel projection along `view`, framed on the extent of `points` across
// the picture (the bounding sphere would leave a thin sail small).
void placeCamera(vtkCamera* camera, View view, const std::vector<Vec3>& points, const PictureSize& size) {
  Vec3 toward, up;  // camera position relative to the focal point; picture up
  switch (view) {
    case View::Side: toward = -Vec3::UnitY(), up = Vec3::UnitZ(); break;    // from starboard: +X (bow) to the right
    case View::Top: toward = Vec3::UnitZ(), up = Vec3::UnitX(); break;      // from above, bow up
    case View::Astern: toward = -Vec3::UnitX(), up = Vec3::UnitZ(); break;  // from behind, looking forward
  }
  const Vec3 right = up.cross(toward);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : points) {
    const Vec3 q(p.dot(right), p.dot(up), p.dot(toward));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Vec3 mid = 0.5 * (lo + hi);
  const Vec3 centre = mid.x() * right + mid.y() * up + mid.z() * toward;
  const double depth = std::max(hi.z() - lo.z(), 1.0);
  const Vec3 eye = centre + 4 * depth * toward;
  camera->SetFocalPoint(centre.data());
  camera->SetPosition(eye.data());
  camera->SetViewUp(up.data());
  camera->ParallelProjectionOn();
  const double aspect = double(size.width_px) / size.height_px;
  camera->SetParallelScale(1.06 * std::max(0.5 * (hi.y() - lo.y()), 0.5 * (hi.x() - lo.x()) / aspect));
  camera->SetClippingRange(depth, 7 * depth);
}

// A smooth surface of `mesh` in per-vertex colours: `values` through deviationColour over
// ±range, the vertices flagged in `muted` (when given) pale. Mostly ambient, so the colours
// read as their legend with little shading. The actor's pipeline holds the surface.
vtkNew<vtkActor> colouredActor(const Mesh& mesh, const std::vector<double>& values, double range,
                               const std::vector<char>* muted) {
  vtkNew<vtkPolyData> poly = surfaceOf(mesh);
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  colours->SetName("values");
  colours->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) {
    Rgb c = deviationColour(values[i], range);
    if (muted && (*muted)[i]) c = mutedColour(c);
    for (int k = 0; k < 3; ++k) colours->SetComponent(static_cast<vtkIdType>(i), k, std::round(255 * c[k]));
  }
  poly->GetPointData()->SetScalars(colours);
  vtkNew<vtkActor> actor = surfaceActor(poly);
  actor->GetProperty()->SetAmbient(0.6);
  actor->GetProperty()->SetDiffuse(0.4);
  actor->GetProperty()->SetSpecular(0.0);
  actor->GetMapper()->SetScalarModeToUsePointData();
  actor->GetMapper()->SetColorModeToDirectScalars();
  actor->GetMapper()->ScalarVisibilityOn();
  return actor;
}

RgbImage capture(vtkRenderWindow* window) {
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkImageData* image = grab->GetOutput();
  int dims[3] = {0, 0, 0};
  image->GetDimensions(dims);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(image->GetPointData()->GetScalars());
  if (!scalars || dims[0] <= 0 || dims[1] <= 0 || scalars->GetNumberOfComponents() != 3)
    throw RenderError("[renderSailViews] VTK returned no RGB picture (is the X display usable for OpenGL?)");
  RgbImage out;
  out.width = dims[0];
  out.height = dims[1];
  out.rgb.resize(size_t(out.width) * out.height * 3);
  const unsigned char* src = scalars->GetPointer(0);
  const size_t row = size_t(out.width) * 3;
  for (int y = 0; y < out.height; ++y)  // VTK's rows run bottom-up
    std::copy_n(src + size_t(out.height - 1 - y) * row, row, out.rgb.data() + size_t(y) * row);
  return out;
}

}  // namespace

Rgb deviationColour(double distance_m, double range_m) {
  const double t = range_m > 0 ? std::clamp(distance_m / range_m, -1.0, 1.0) : 0.0;
  // Moreland's cool-warm endpoints; white in the middle so small deviations fade out.
  const Rgb cold{0.230, 0.299, 0.754}, warm{0.706, 0.016, 0.150}, mid{0.97, 0.97, 0.97};
  const Rgb& end = t < 0 ? cold : warm;
  const double a = std::abs(t);
  return {mid[0] + a * (end[0] - mid[0]), mid[1] + a * (end[1] - mid[1]), mid[2] + a * (end[2] - mid[2])};
}

std::vector<std::array<uint32_t, 2>> gridEdges(const Mesh& mesh) {
  auto len2 = [&](uint32_t a, uint32_t b) { return (mesh.vertices[a] - mesh.vertices[b]).squaredNorm(); };
  // Per undirected edge: how many triangles use it and how many of them have it as their longest edge.
  std::map<std::pair<uint32_t, uint32_t>, std::pair<int, int>> edges;
  for (const auto& t : mesh.triangles) {
    int longest = 0;
    double best = -1;
    for (int k = 0; k < 3; ++k) {
      const double l = len2(t[k], t[(k + 1) % 3]);
      if (l > best) best = l, longest = k;
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      auto& e = edges[{std::min(a, b), std::max(a, b)}];
      ++e.first;
      if (k == longest) ++e.second;
    }
  }
  std::vector<std::array<uint32_t, 2>> out;
  out.reserve(edges.size());
  for (const auto& [key, use] : edges)
    if (!(use.first == 2 && use.second == 2)) out.push_back({key.first, key.second});
  return out;
}

SailViews renderSailViews(const Mesh& design, const Mesh& flying, const std::vector<double>& deviation_m,
                          const RenderParams& p) {
  if (design.empty()) throw InvalidInput("[renderSailViews] the design mesh has no triangles");
  if (flying.empty()) throw InvalidInput("[renderSailViews] the flying mesh has no triangles");
  if (deviation_m.size() != flying.vertices.size())
    throw InvalidInput("[renderSailViews] " + std::to_string(deviation_m.size()) + " deviations for " +
                       std::to_string(flying.vertices.size()) + " flying vertices");
  for (const PictureSize* size : {&p.side, &p.top, &p.astern, &p.deviation})
    if (size->width_px < 16 || size->height_px < 16 || size->width_px > 4096 || size->height_px > 4096)
      throw InvalidInput("[renderSailViews] picture size must be 16..4096 px (got " + std::to_string(size->width_px) +
                         "×" + std::to_string(size->height_px) + ")");

  const LeakCheckPause pause;  // first, so it outlives every VTK object below
  vtkNew<vtkPolyData> flying_poly = surfaceOf(flying);
  vtkNew<vtkActor> flying_actor = surfaceActor(flying_poly);
  flying_actor->GetProperty()->SetColor(kFlyingRed[0], kFlyingRed[1], kFlyingRed[2]);

  vtkNew<vtkPolyData> grid = gridOf(design);
  vtkNew<vtkPolyDataMapper> grid_mapper;
  grid_mapper->SetInputData(grid);
  // Lines drawn slightly in front so the grid stays visible where it meets the surface.
  grid_mapper->SetResolveCoincidentTopologyToPolygonOffset();
  vtkNew<vtkActor> grid_actor;
  grid_actor->SetMapper(grid_mapper);
  grid_actor->GetProperty()->SetColor(kDesignBlue[0], kDesignBlue[1], kDesignBlue[2]);
  grid_actor->GetProperty()->SetLineWidth(1.0);
  grid_actor->GetProperty()->LightingOff();

  vtkNew<vtkActor> deviation_actor = colouredActor(flying, deviation_m, p.deviation_range_m, nullptr);

  std::vector<Vec3> all = design.vertices;
  all.insert(all.end(), flying.vertices.begin(), flying.vertices.end());
  // The design grid is drawn in a layer above the flying surface, so the grid
  // stays visible where the flying shape lies to the viewer's side of it.
  vtkNew<vtkRenderer> renderer, grid_layer;
  renderer->SetBackground(1, 1, 1);
  grid_layer->SetLayer(1);
  grid_layer->InteractiveOff();
  grid_layer->SetActiveCamera(renderer->GetActiveCamera());
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetNumberOfLayers(2);
  window->AddRenderer(renderer);
  window->AddRenderer(grid_layer);

  auto shoot = [&](View view, const PictureSize& size, const std::vector<Vec3>& frame_on) {
    window->SetSize(size.width_px, size.height_px);
    placeCamera(renderer->GetActiveCamera(), view, frame_on, size);
    return capture(window);
  };
  SailViews views;
  renderer->AddActor(flying_actor);
  grid_layer->AddActor(grid_actor);
  views.side = shoot(View::Side, p.side, all);
  views.top = shoot(View::Top, p.top, all);
  views.astern = shoot(View::Astern, p.astern, all);
  renderer->RemoveAllViewProps();
  grid_layer->RemoveAllViewProps();
  renderer->AddActor(deviation_actor);
  views.deviation = shoot(View::Side, p.deviation, all);
  return views;
}

Rgb mutedColour(const Rgb& c) {
  constexpr double kGrey = 0.86, kShare = 0.75;
  return {kShare * kGrey + (1 - kShare) * c[0], kShare * kGrey + (1 - kShare) * c[1], kShare * kGrey + (1 - kShare) * c[2]};
}

RgbImage renderColouredSide(const Mesh& mesh, const std::vector<double>& values, double range,
                            const std::vector<char>& muted, const PictureSize& size) {
  if (mesh.empty()) throw InvalidInput("[renderColouredSide] the mesh has no triangles");
  if (values.size() != mesh.vertices.size() || muted.size() != mesh.vertices.size())
    throw InvalidInput("[renderColouredSide] " + std::to_string(values.size()) + " values and " +
                       std::to_string(muted.size()) + " flags for " + std::to_string(mesh.vertices.size()) + " vertices");
  if (size.width_px < 16 || size.height_px < 16 || size.width_px > 4096 || size.height_px > 4096)
    throw InvalidInput("[renderColouredSide] picture size must be 16..4096 px");
  const LeakCheckPause pause;
  vtkNew<vtkActor> actor = colouredActor(mesh, values, range, &muted);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  renderer->AddActor(actor);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->AddRenderer(renderer);
  window->SetSize(size.width_px, size.height_px);
  placeCamera(renderer->GetActiveCamera(), View::Side, mesh.vertices, size);
  return capture(window);
}

}  // namespace sailshape
