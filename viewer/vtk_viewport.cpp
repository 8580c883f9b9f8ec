#include "viewer/vtk_viewport.hpp"

#include <vtkActor.h>
#include <vtkAppendPolyData.h>
#include <vtkCutter.h>
#include <vtkFeatureEdges.h>
#include <vtkPlane.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkColorTransferFunction.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPointPicker.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkSphereSource.h>
#include <vtkTextProperty.h>
#include <vtkTextureObject.h>

#include <algorithm>
#include <cmath>

#include "viewer/processing.hpp"
#include "viewer/scan_scene.hpp"

namespace sailshape::viewer {
namespace {

constexpr Rgb kDesignBlue{0.25f, 0.55f, 1.0f};
constexpr Rgb kFlyingRed{0.86f, 0.13f, 0.10f};
constexpr Rgb kSectionAmber{1.0f, 0.80f, 0.20f};
constexpr Rgb kDesignSectionBlue{0.55f, 0.85f, 1.0f};
constexpr Rgb kClusterGreen{0.20f, 0.90f, 0.50f};
constexpr Rgb kFittedTeal{0.10f, 0.65f, 0.65f};
constexpr double kPaleGrey = 0.80;  // what an inferred vertex of the fitted design is blended towards

vtkSmartPointer<vtkPolyData> meshPoly(const Mesh& mesh) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) pts->SetPoint(static_cast<vtkIdType>(i), mesh.vertices[i].data());
  vtkNew<vtkCellArray> tris;
  for (const auto& t : mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    tris->InsertNextCell(3, ids);
  }
  poly->SetPoints(pts);
  poly->SetPolys(tris);
  return poly;
}

vtkSmartPointer<vtkPolyData> pointPoly(const std::vector<Vec3>& points) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  vtkNew<vtkCellArray> verts;
  for (size_t i = 0; i < points.size(); ++i) {
    pts->SetPoint(static_cast<vtkIdType>(i), points[i].data());
    const vtkIdType id = static_cast<vtkIdType>(i);
    verts->InsertNextCell(1, &id);
  }
  poly->SetPoints(pts);
  poly->SetVerts(verts);
  return poly;
}

vtkSmartPointer<vtkPolyData> curvePoly(const std::vector<const std::vector<Vec3>*>& curves) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  for (const auto* c : curves) {
    if (c->size() < 2) continue;
    std::vector<vtkIdType> ids;
    for (const Vec3& p : *c) ids.push_back(pts->InsertNextPoint(p.data()));
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  poly->SetPoints(pts);
  poly->SetLines(lines);
  return poly;
}

// The design drawn as a grid: the surface cut by horizontal planes (waterlines)
// and by athwartship planes (buttocks), plus its outline.
vtkSmartPointer<vtkPolyData> designGrid(const Mesh& mesh, int levels_z = 14, int levels_x = 9) {
  auto surface = meshPoly(mesh);
  double b[6];
  surface->GetBounds(b);
  vtkNew<vtkAppendPolyData> append;
  const struct {
    double normal[3];
    double lo, hi;
    int n;
  } cuts[2] = {{{0, 0, 1}, b[4], b[5], levels_z}, {{1, 0, 0}, b[0], b[1], levels_x}};
  for (const auto& c : cuts) {
    vtkNew<vtkPlane> plane;
    plane->SetOrigin(0, 0, 0);
    plane->SetNormal(c.normal[0], c.normal[1], c.normal[2]);
    vtkNew<vtkCutter> cutter;
    cutter->SetCutFunction(plane);
    cutter->SetInputData(surface);
    for (int k = 0; k < c.n; ++k) cutter->SetValue(k, c.lo + (c.hi - c.lo) * (k + 0.5) / c.n);
    cutter->Update();
    vtkNew<vtkPolyData> lines;
    lines->DeepCopy(cutter->GetOutput());
    append->AddInputData(lines);
  }
  vtkNew<vtkFeatureEdges> edges;
  edges->SetInputData(surface);
  edges->BoundaryEdgesOn();
  edges->FeatureEdgesOff();
  edges->ManifoldEdgesOff();
  edges->NonManifoldEdgesOff();
  edges->ColoringOff();
  edges->Update();
  vtkNew<vtkPolyData> outline;
  outline->DeepCopy(edges->GetOutput());
  append->AddInputData(outline);
  append->Update();
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->DeepCopy(append->GetOutput());
  return out;
}

// Translucent quads through each section: the chord, widened across it in the section plane.
vtkSmartPointer<vtkPolyData> planePoly(const SectionAnalysis& sections) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> quads;
  for (const Section& s : sections.sections) {
    const Vec3 chord = s.leech_point - s.luff_point;
    const double c = chord.norm();
    if (c <= 0) continue;
    const Vec3 u = chord / c;
    Vec3 v = s.plane_normal.cross(u);
    if (v.norm() < 1e-9) continue;
    v.normalize();
    const Vec3 a = s.luff_point - 0.15 * c * u, b = s.leech_point + 0.15 * c * u;
    const Vec3 corners[4] = {a - 0.3 * c * v, b - 0.3 * c * v, b + 0.3 * c * v, a + 0.3 * c * v};
    vtkIdType ids[4];
    for (int k = 0; k < 4; ++k) ids[k] = pts->InsertNextPoint(corners[k].data());
    quads->InsertNextCell(4, ids);
  }
  poly->SetPoints(pts);
  poly->SetPolys(quads);
  return poly;
}

void attachScalars(vtkPolyData* poly, const std::vector<double>& values, double scale, const char* name) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i] * scale);
  poly->GetPointData()->SetScalars(a);
}

vtkSmartPointer<vtkActor> actorOf(vtkPolyData* poly, const Rgb& colour) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
  return actor;
}

void useScalars(vtkActor* actor, vtkLookupTable* lut, double lo, double hi) {
  auto* mapper = vtkPolyDataMapper::SafeDownCast(actor->GetMapper());
  mapper->ScalarVisibilityOn();
  mapper->SetScalarModeToUsePointData();
  mapper->SetLookupTable(lut);
  mapper->SetScalarRange(lo, hi);
  mapper->UseLookupTableScalarRangeOff();
}

void flat(vtkActor* actor) { actor->GetProperty()->LightingOff(); }

double percentileAbs(const std::vector<double>& v, double q) {
  std::vector<double> a;
  a.reserve(v.size());
  for (double x : v)
    if (std::isfinite(x)) a.push_back(std::abs(x));
  if (a.empty()) return 0;
  const size_t k = std::min(a.size() - 1, static_cast<size_t>(q * static_cast<double>(a.size())));
  std::nth_element(a.begin(), a.begin() + static_cast<long>(k), a.end());
  return a[k];
}

}  // namespace

struct VtkViewport::Impl {
  vtkNew<vtkGenericOpenGLRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkGenericRenderWindowInteractor> interactor;
  vtkNew<vtkInteractorStyleTrackballCamera> style;
  vtkNew<vtkCallbackCommand> is_current;
  vtkNew<vtkPointPicker> picker;
  vtkNew<vtkScalarBarActor> scalar_bar;
  vtkNew<vtkLookupTable> deviation_lut;
  vtkNew<vtkLookupTable> scalar_lut;       // curvature / clusters of a processing result
  vtkSmartPointer<vtkActor> pick_marker;
  std::vector<vtkSmartPointer<vtkProp>> props;
  struct Pickable {
    vtkActor* actor;
    const std::vector<double>* deviation_m;
    std::string what;
  };
  std::vector<Pickable> pickables;
  int width = 0, height = 0;
  bool camera_placed = false;
  double limit_mm = 0;

  void add(const vtkSmartPointer<vtkActor>& a) {
    renderer->AddActor(a);
    props.push_back(a);
  }
};

VtkViewport::VtkViewport() : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  // GLFW owns the context and keeps it current on this thread.
  m.is_current->SetCallback([](vtkObject*, unsigned long, void*, void* call_data) { *static_cast<bool*>(call_data) = true; });
  m.window->AddObserver(vtkCommand::WindowIsCurrentEvent, m.is_current);
  m.window->SetMultiSamples(0);
  m.window->SwapBuffersOn();              // Frame() resolves into the display framebuffer ...
  m.window->SetFrameBlitModeToNoBlit();   // ... and leaves GLFW's framebuffer to ImGui
  m.window->SetOffScreenRendering(true);
  m.window->AddRenderer(m.renderer);
  m.window->SetInteractor(m.interactor);
  m.interactor->SetInteractorStyle(m.style);
  m.interactor->EnableRenderOff();        // the UI loop renders every frame
  m.style->SetDefaultRenderer(m.renderer);
  m.renderer->GradientBackgroundOn();
  m.renderer->SetBackground(0.10, 0.11, 0.13);
  m.renderer->SetBackground2(0.27, 0.31, 0.37);
  m.renderer->UseFXAAOn();
  m.window->InitializeFromCurrentContext();

  vtkNew<vtkColorTransferFunction> ctf;  // Moreland's cool-to-warm diverging map
  ctf->SetColorSpaceToDiverging();
  ctf->AddRGBPoint(0.0, 0.230, 0.299, 0.754);
  ctf->AddRGBPoint(0.5, 0.865, 0.865, 0.865);
  ctf->AddRGBPoint(1.0, 0.706, 0.016, 0.150);
  m.deviation_lut->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    double c[3];
    ctf->GetColor(i / 255.0, c);
    m.deviation_lut->SetTableValue(i, c[0], c[1], c[2], 1.0);
  }
  m.deviation_lut->Build();
  m.scalar_lut->SetHueRange(0.66, 0.0);
  m.scalar_lut->Build();

  m.scalar_bar->SetLookupTable(m.deviation_lut);
  m.scalar_bar->SetTitle("mm");
  m.scalar_bar->SetNumberOfLabels(5);
  m.scalar_bar->SetLabelFormat("%+.0f");
  m.scalar_bar->SetOrientationToVertical();
  m.scalar_bar->SetPosition(0.90, 0.12);
  m.scalar_bar->SetWidth(0.08);
  m.scalar_bar->SetHeight(0.76);
  m.scalar_bar->GetTitleTextProperty()->SetColor(0.95, 0.95, 0.95);
  m.scalar_bar->GetTitleTextProperty()->SetFontSize(12);
  m.scalar_bar->GetTitleTextProperty()->ItalicOff();
  m.scalar_bar->GetLabelTextProperty()->SetColor(0.9, 0.9, 0.9);
  m.scalar_bar->GetLabelTextProperty()->ItalicOff();
  m.scalar_bar->SetVisibility(false);
  m.renderer->AddViewProp(m.scalar_bar);

  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(0.05);
  sphere->SetThetaResolution(16);
  sphere->SetPhiResolution(12);
  vtkNew<vtkPolyDataMapper> sm;
  sm->SetInputConnection(sphere->GetOutputPort());
  m.pick_marker = vtkSmartPointer<vtkActor>::New();
  m.pick_marker->SetMapper(sm);
  m.pick_marker->GetProperty()->SetColor(1.0, 1.0, 0.2);
  m.pick_marker->SetVisibility(false);
  m.pick_marker->PickableOff();
  m.renderer->AddActor(m.pick_marker);

  m.picker->SetTolerance(0.004);
  m.picker->PickFromListOn();
}

VtkViewport::~VtkViewport() {
  // Release VTK's GL objects while GLFW's context is still current.
  impl_->window->Finalize();
}

void VtkViewport::setScene(const ScanScene* scene, const std::vector<Overlay>& overlays, const ViewOptions& o,
                           const StageResult* processing) {
  Impl& m = *impl_;
  for (auto& p : m.props) m.renderer->RemoveViewProp(p);
  m.props.clear();
  m.pickables.clear();
  m.picker->InitializePickList();
  m.pick_marker->SetVisibility(false);
  m.limit_mm = 0;

  if (scene) addSceneLayers(*scene, o);
  else m.scalar_bar->SetVisibility(false);
  addOverlays(overlays, o);
  if (processing && !processing->cloud.empty()) addProcessingLayer(*processing, o);

  if (!m.camera_placed && !m.props.empty()) {
    setCamera(CameraPreset::ThreeQuarter);
    m.camera_placed = true;
  }
  m.renderer->ResetCameraClippingRange();
}

void VtkViewport::addSceneLayers(const ScanScene& scene, const ViewOptions& o) {
  Impl& m = *impl_;
  const bool dev = o.deviation && (!scene.surface_deviation_m.empty() || !scene.raw_deviation_m.empty());
  if (dev) {
    const auto& basis = scene.surface_deviation_m.empty() ? scene.raw_deviation_m : scene.surface_deviation_m;
    m.limit_mm = o.deviation_range_mm > 0 ? o.deviation_range_mm : std::max(1.0, 1000.0 * percentileAbs(basis, 0.95));
  }
  if (o.design && !scene.design.empty()) {
    auto a = actorOf(designGrid(scene.design), kDesignBlue);
    a->GetProperty()->SetLineWidth(1.5f);
    a->GetProperty()->SetOpacity(dev ? 0.5 : 1.0);
    a->PickableOff();
    flat(a);
    m.add(a);
  }
  if (o.surface && !scene.surface.empty()) {
    auto poly = meshPoly(scene.surface);
    auto a = actorOf(poly, kFlyingRed);
    if (dev && scene.surface_deviation_m.size() == scene.surface.vertices.size()) {
      attachScalars(poly, scene.surface_deviation_m, 1000.0, "deviation_mm");
      useScalars(a, m.deviation_lut, -m.limit_mm, m.limit_mm);
    }
    // Pushed back a little so section curves and the design grid lying on it stay visible.
    vtkPolyDataMapper::SafeDownCast(a->GetMapper())->SetRelativeCoincidentTopologyPolygonOffsetParameters(2, 2);
    a->GetProperty()->SetInterpolationToPhong();
    a->GetProperty()->SetSpecular(0.25);
    a->GetProperty()->SetSpecularPower(20);
    a->GetProperty()->SetAmbient(0.25);
    m.add(a);
    m.picker->AddPickList(a);
    m.pickables.push_back({a, &scene.surface_deviation_m, "flying surface"});
  }
  if (o.fitted && scene.fitted && scene.fitted_move_m.size() == scene.fitted->fitted.vertices.size()) {
    // The whole sail as the design fitted to the scan: teal, or its move along the design's normal
    // in the deviation colours; where no sample held it (inferred), pale.
    const DesignFit& f = *scene.fitted;
    auto poly = meshPoly(f.fitted);
    vtkNew<vtkUnsignedCharArray> colours;
    colours->SetNumberOfComponents(3);
    colours->SetName("fitted");
    colours->SetNumberOfTuples(static_cast<vtkIdType>(f.fitted.vertices.size()));
    for (size_t v = 0; v < f.fitted.vertices.size(); ++v) {
      double c[3] = {kFittedTeal[0], kFittedTeal[1], kFittedTeal[2]};
      if (dev) m.deviation_lut->GetColor(std::clamp(1000.0 * scene.fitted_move_m[v], -m.limit_mm, m.limit_mm), c);
      if (!f.supported[v])
        for (double& x : c) x = 0.75 * kPaleGrey + 0.25 * x;
      for (int k = 0; k < 3; ++k) colours->SetComponent(static_cast<vtkIdType>(v), k, std::round(255 * c[k]));
    }
    poly->GetPointData()->SetScalars(colours);
    auto a = actorOf(poly, kFittedTeal);
    a->GetMapper()->SetScalarModeToUsePointData();
    a->GetMapper()->SetColorModeToDirectScalars();
    a->GetMapper()->ScalarVisibilityOn();
    vtkPolyDataMapper::SafeDownCast(a->GetMapper())->SetRelativeCoincidentTopologyPolygonOffsetParameters(3, 3);
    a->GetProperty()->SetAmbient(0.35);
    a->PickableOff();
    m.add(a);
  }
  if (o.cloud && !scene.raw_cloud.empty()) {
    auto poly = pointPoly(scene.raw_cloud.points);
    auto a = actorOf(poly, {1.0f, 0.35f, 0.30f});
    if (dev && scene.raw_deviation_m.size() == scene.raw_cloud.size()) {
      attachScalars(poly, scene.raw_deviation_m, 1000.0, "deviation_mm");
      useScalars(a, m.deviation_lut, -m.limit_mm, m.limit_mm);
    }
    a->GetProperty()->SetPointSize(o.point_size);
    flat(a);
    m.add(a);
    m.picker->AddPickList(a);
    m.pickables.push_back({a, &scene.raw_deviation_m, "stored cloud"});
  }
  if (o.cluster && scene.analysis && !scene.analysis->sail_cloud.empty()) {
    const Cloud& sail = scene.analysis->sail_cloud;
    auto poly = pointPoly(sail.points);
    auto a = actorOf(poly, kClusterGreen);
    if (dev && scene.cluster_deviation_m.size() == sail.size()) {
      attachScalars(poly, scene.cluster_deviation_m, 1000.0, "deviation_mm");
      useScalars(a, m.deviation_lut, -m.limit_mm, m.limit_mm);
    }
    a->GetProperty()->SetPointSize(o.point_size + 1);
    flat(a);
    m.add(a);
    m.picker->AddPickList(a);
    m.pickables.push_back({a, &scene.cluster_deviation_m, "sail cluster"});
  }
  if (o.sections) {
    std::vector<const std::vector<Vec3>*> curves;
    for (const auto& s : scene.sections.sections) curves.push_back(&s.curve);
    auto a = actorOf(curvePoly(curves), kSectionAmber);
    a->GetProperty()->SetLineWidth(3.0f);
    a->PickableOff();
    flat(a);
    m.add(a);
  }
  if (o.design_sections && !scene.design_sections.sections.empty()) {
    std::vector<const std::vector<Vec3>*> curves;
    for (const auto& s : scene.design_sections.sections) curves.push_back(&s.curve);
    auto a = actorOf(curvePoly(curves), kDesignSectionBlue);
    a->GetProperty()->SetLineWidth(2.5f);
    a->PickableOff();
    flat(a);
    m.add(a);
  }
  if (o.section_planes && !scene.sections.sections.empty()) {
    const SectionAnalysis& planes = scene.analysis ? scene.analysis->sections : scene.sections;
    auto a = actorOf(planePoly(planes), {0.9f, 0.9f, 0.95f});
    a->GetProperty()->SetOpacity(0.18);
    a->PickableOff();
    m.add(a);
  }
  m.scalar_bar->SetVisibility(dev);
  if (dev) m.deviation_lut->SetTableRange(-m.limit_mm, m.limit_mm);
}

void VtkViewport::addOverlays(const std::vector<Overlay>& overlays, const ViewOptions& o) {
  Impl& m = *impl_;
  for (const Overlay& ov : overlays) {
    if (!ov.scene) continue;
    if (!ov.scene->surface.empty()) {
      auto a = actorOf(meshPoly(ov.scene->surface), ov.colour);
      a->GetProperty()->SetOpacity(0.45);
      a->PickableOff();
      m.add(a);
    } else if (!ov.scene->raw_cloud.empty()) {
      auto a = actorOf(pointPoly(ov.scene->raw_cloud.points), ov.colour);
      a->GetProperty()->SetPointSize(o.point_size);
      a->PickableOff();
      flat(a);
      m.add(a);
    }
    std::vector<const std::vector<Vec3>*> curves;
    for (const auto& s : ov.scene->sections.sections) curves.push_back(&s.curve);
    auto c = actorOf(curvePoly(curves), ov.colour);
    c->GetProperty()->SetLineWidth(2.5f);
    c->PickableOff();
    flat(c);
    m.add(c);
  }
}

void VtkViewport::addProcessingLayer(const StageResult& processing, const ViewOptions& o) {
  Impl& m = *impl_;
  auto poly = pointPoly(processing.cloud.points);
  auto a = actorOf(poly, {0.85f, 0.85f, 0.85f});
  if (processing.scalar.size() == processing.cloud.size()) {
    attachScalars(poly, processing.scalar, 1.0, processing.scalar_name.c_str());
    double lo = INFINITY, hi = -INFINITY;
    for (double v : processing.scalar) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (processing.scalar_name == "curvature") hi = std::min(hi, 0.05);  // flat sails sit near 0; edges saturate
    useScalars(a, m.scalar_lut, lo, std::max(hi, lo + 1e-9));
  }
  a->GetProperty()->SetPointSize(o.point_size);
  a->PickableOff();
  flat(a);
  m.add(a);
  if (processing.analysis && !processing.analysis->mesh.empty()) {
    auto s = actorOf(meshPoly(processing.analysis->mesh), {0.95f, 0.45f, 0.15f});
    s->GetProperty()->SetOpacity(0.8);
    s->PickableOff();
    m.add(s);
  }
}

void VtkViewport::setCamera(CameraPreset preset) {
  Impl& m = *impl_;
  double b[6];
  m.renderer->ComputeVisiblePropBounds(b);
  if (b[0] > b[1]) return;  // nothing visible
  const Vec3 c((b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2);
  // Boat frame: +X forward, +Y port, +Z up.
  Vec3 dir, up(0, 0, 1);
  switch (preset) {
    case CameraPreset::ThreeQuarter: dir = Vec3(-0.75, -1.0, 0.35); break;  // from astern, windward, above
    case CameraPreset::Side: dir = Vec3(0, -1.0, 0.05); break;             // from starboard
    case CameraPreset::Top: dir = Vec3(0, 0, 1); up = Vec3(1, 0, 0); break;
    case CameraPreset::Astern: dir = Vec3(-1, 0, 0.1); break;
    case CameraPreset::Bow: dir = Vec3(1, 0, 0.1); break;
  }
  vtkCamera* cam = m.renderer->GetActiveCamera();
  cam->SetViewAngle(30.0);  // VTK's default; a unit's view widens it
  cam->SetFocalPoint(c.data());
  const Vec3 pos = c + 10.0 * dir.normalized();
  cam->SetPosition(pos.data());
  cam->SetViewUp(up.data());
  m.renderer->ResetCamera();
  m.renderer->ResetCameraClippingRange();
}

void VtkViewport::setCamera(const CameraPlacement& c) {
  Impl& m = *impl_;
  vtkCamera* cam = m.renderer->GetActiveCamera();
  cam->SetPosition(c.position.data());
  cam->SetFocalPoint(c.focal_point.data());
  cam->SetViewUp(c.view_up.data());
  cam->SetViewAngle(60.0);  // about what a scanner's fan covers at the sweep's centre
  m.camera_placed = true;
  m.renderer->ResetCameraClippingRange();
}

void VtkViewport::resetCamera() {
  impl_->renderer->ResetCamera();
}

unsigned VtkViewport::render(int width, int height) {
  Impl& m = *impl_;
  if (width <= 0 || height <= 0) return 0;  // collapsed panel or minimised window: keep the last size
  if (width != m.width || height != m.height) {
    m.window->SetSize(width, height);
    m.interactor->SetSize(width, height);
    m.width = width;
    m.height = height;
  }
  m.window->Render();
  vtkOpenGLFramebufferObject* fbo = m.window->GetDisplayFramebuffer();
  if (!fbo) return 0;
  vtkTextureObject* tex = fbo->GetColorAttachmentAsTextureObject(0);
  return tex ? tex->GetHandle() : 0;
}

void VtkViewport::forward(const ViewportInput& in) {
  Impl& m = *impl_;
  if (m.width <= 0 || m.height <= 0) return;
  m.interactor->SetEventInformationFlipY(static_cast<int>(in.x), static_cast<int>(in.y), in.ctrl, in.shift);
  m.interactor->InvokeEvent(vtkCommand::MouseMoveEvent, nullptr);
  const unsigned long press[3] = {vtkCommand::LeftButtonPressEvent, vtkCommand::RightButtonPressEvent,
                                  vtkCommand::MiddleButtonPressEvent};
  const unsigned long release[3] = {vtkCommand::LeftButtonReleaseEvent, vtkCommand::RightButtonReleaseEvent,
                                    vtkCommand::MiddleButtonReleaseEvent};
  for (int b = 0; b < 3; ++b) {
    if (in.pressed[b]) m.interactor->InvokeEvent(press[b], nullptr);
    if (in.released[b]) m.interactor->InvokeEvent(release[b], nullptr);
  }
  if (in.wheel > 0) m.interactor->InvokeEvent(vtkCommand::MouseWheelForwardEvent, nullptr);
  if (in.wheel < 0) m.interactor->InvokeEvent(vtkCommand::MouseWheelBackwardEvent, nullptr);
  if (in.key_char > 0 && in.key_char < 128) {
    const char key = static_cast<char>(in.key_char);
    // Keys that would quit or re-style every actor are VTK's, not this viewer's.
    if (key != 'e' && key != 'q' && key != 'w' && key != 's') {
      m.interactor->SetKeyCode(key);
      m.interactor->InvokeEvent(vtkCommand::KeyPressEvent, nullptr);
      m.interactor->InvokeEvent(vtkCommand::CharEvent, nullptr);
    }
  }
}

std::optional<PickInfo> VtkViewport::pick(float x, float y) {
  Impl& m = *impl_;
  if (m.pickables.empty() || m.height <= 0) return std::nullopt;
  if (!m.picker->Pick(x, m.height - 1 - y, 0, m.renderer)) return std::nullopt;
  const vtkIdType id = m.picker->GetPointId();
  vtkActor* actor = m.picker->GetActor();
  if (id < 0 || !actor) return std::nullopt;
  for (const auto& p : m.pickables) {
    if (p.actor != actor) continue;
    PickInfo info;
    double xyz[3];
    m.picker->GetDataSet()->GetPoint(id, xyz);
    info.point = Vec3(xyz[0], xyz[1], xyz[2]);
    if (static_cast<size_t>(id) < p.deviation_m->size()) info.deviation_m = (*p.deviation_m)[id];
    info.what = p.what;
    m.pick_marker->SetPosition(xyz);
    m.pick_marker->SetVisibility(true);
    return info;
  }
  return std::nullopt;
}

double VtkViewport::deviationLimitMm() const { return impl_->limit_mm; }

}  // namespace sailshape::viewer
