// Benchmark: each analysis stage and the whole analysis, ours against PCL's
// stock classes on the same synthetic sails (4 mm range noise, SPEC §3), at
// 50,000, 200,000 and 1,000,000 points. Counters: points per second, peak
// resident memory, and for the whole analysis the section-parameter errors
// against the generator's known answer (stock PCL has no section analysis).
#include <benchmark/benchmark.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>
#include <pcl/surface/gp3.h>
#include <pcl/surface/mls.h>
#include <sys/resource.h>
#include <vtkCellArray.h>
#include <vtkGenericCell.h>
#include <vtkModifiedBSPTree.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <map>
#include <string>

#include "acquisition/ray_caster.hpp"
#include "acquisition/scene.hpp"
#include "acquisition/sensor_model.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/registration/registration.hpp"
#include "tests/support/fit_case.hpp"
#include "analysis/segmentation/cleaning.hpp"
#include "analysis/segmentation/segmentation.hpp"
#include "analysis/spatial/normals.hpp"
#include "analysis/surface/smoothing.hpp"
#include "analysis/surface/surface.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/schema.hpp"
#include "tests/support/tunnel_scene.hpp"

namespace {

using namespace sailshape;

const Cloud& sail(size_t points) {
  static std::map<size_t, Cloud> cache;
  auto it = cache.find(points);
  if (it == cache.end()) {
    ScanSimulation sim;
    sim.points = points;
    sim.noise_sigma_m = 0.004;
    sim.seed = 7;
    it = cache.emplace(points, sampleSail(exampleDesign(SailType::Main), sim)).first;
  }
  return it->second;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const Cloud& c) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  out->reserve(c.size());
  for (const Vec3& p : c.points) out->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                                             static_cast<float>(p.z())));
  return out;
}

double peakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void finish(benchmark::State& state, size_t points) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * points));
  state.counters["peak_MiB"] = peakMemoryMiB();
}

// PCL's stock normals and region growing, configured like our defaults.
pcl::PointCloud<pcl::Normal>::Ptr pclNormals(const pcl::PointCloud<pcl::PointXYZ>::Ptr& pc,
                                             const pcl::search::KdTree<pcl::PointXYZ>::Ptr& tree, int k) {
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(pc);
  ne.setSearchMethod(tree);
  ne.setKSearch(k);
  auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  ne.compute(*normals);
  return normals;
}

std::vector<pcl::PointIndices> pclRegionGrowing(const pcl::PointCloud<pcl::PointXYZ>::Ptr& pc,
                                                const pcl::search::KdTree<pcl::PointXYZ>::Ptr& tree,
                                                const AnalysisParams& p) {
  const auto normals = pclNormals(pc, tree, p.normals.k_neighbours);
  pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
  rg.setInputCloud(pc);
  rg.setInputNormals(normals);
  rg.setSearchMethod(tree);
  rg.setNumberOfNeighbours(p.region_growing.k_neighbours);
  rg.setSmoothnessThreshold(static_cast<float>(p.region_growing.max_normal_angle_deg * kRadPerDeg));
  rg.setCurvatureThreshold(static_cast<float>(p.region_growing.max_curvature));
  rg.setMinClusterSize(static_cast<pcl::uindex_t>(p.region_growing.min_points));
  std::vector<pcl::PointIndices> clusters;
  rg.extract(clusters);
  return clusters;
}

// ---- normals ----
void BM_Ours_Normals(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(estimateNormals(c, NormalParams{}));
  finish(state, c.size());
}
void BM_Pcl_Normals(benchmark::State& state) {
  const auto pc = toPcl(sail(static_cast<size_t>(state.range(0))));
  for (auto _ : state)
    benchmark::DoNotOptimize(
        pclNormals(pc, pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(), NormalParams{}.k_neighbours)->size());
  finish(state, pc->size());
}

// ---- region growing ----
void BM_Ours_RegionGrowing(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  const AnalysisParams p;
  for (auto _ : state) {
    const NeighbourTable table = nearestNeighbours(c.points, static_cast<size_t>(p.region_growing.k_neighbours));
    const NormalEstimation n = estimateNormals(c, table, p.normals);
    benchmark::DoNotOptimize(growRegions(c, n.normals, table, p.region_growing));
  }
  finish(state, c.size());
}
void BM_Pcl_RegionGrowing(benchmark::State& state) {
  const auto pc = toPcl(sail(static_cast<size_t>(state.range(0))));
  for (auto _ : state)
    benchmark::DoNotOptimize(
        pclRegionGrowing(pc, pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(), AnalysisParams{}).size());
  finish(state, pc->size());
}

// ---- statistical outliers ----
void BM_Ours_StatisticalOutliers(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(removeStatisticalOutliers(c));
  finish(state, c.size());
}
void BM_Pcl_StatisticalOutliers(benchmark::State& state) {
  const auto pc = toPcl(sail(static_cast<size_t>(state.range(0))));
  const StatisticalOutlierParams p;
  for (auto _ : state) {
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
    sor.setInputCloud(pc);
    sor.setMeanK(p.k_neighbours);
    sor.setStddevMulThresh(p.std_ratio);
    pcl::PointCloud<pcl::PointXYZ> out;
    sor.filter(out);
    benchmark::DoNotOptimize(out.size());
  }
  finish(state, pc->size());
}

// ---- moving least squares ----
void BM_Ours_Mls(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(smoothMls(c));
  finish(state, c.size());
}
void BM_Pcl_Mls(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  const auto pc = toPcl(c);
  // A radius holding about 60 neighbours at this density.
  const double area = 18.0;  // m², the example mainsail
  const double radius = std::sqrt(60.0 / (M_PI * static_cast<double>(c.size()) / area));
  for (auto _ : state) {
    pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointXYZ> mls;
    mls.setInputCloud(pc);
    mls.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    mls.setSearchRadius(radius);
    mls.setPolynomialOrder(2);
    pcl::PointCloud<pcl::PointXYZ> out;
    mls.process(out);
    benchmark::DoNotOptimize(out.size());
  }
  finish(state, pc->size());
}

// ---- surface ----
void BM_Ours_Surface(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(reconstructSurface(c));
  finish(state, c.size());
}
void BM_Pcl_GreedyProjection(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  const auto pc = toPcl(c);
  for (auto _ : state) {
    const auto normals = pclNormals(pc, pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(), 20);
    auto with_normals = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>();
    pcl::concatenateFields(*pc, *normals, *with_normals);
    pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
    const double spacing = std::sqrt(18.0 / static_cast<double>(c.size()));
    gp3.setSearchRadius(5 * spacing);
    gp3.setMu(2.5);
    gp3.setMaximumNearestNeighbors(100);
    gp3.setInputCloud(with_normals);
    gp3.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointNormal>>());
    pcl::PolygonMesh mesh;
    gp3.reconstruct(mesh);
    benchmark::DoNotOptimize(mesh.polygons.size());
  }
  finish(state, pc->size());
}

// ---- whole analysis ----
// RMS distance, mm, of a chain's smoothed points to the sail the scans were taken
// of (the design's mesh at 400 × 200 cells: its own chords stray under 0.1 mm).
double rmsToTruthMm(const std::vector<Vec3>& points) {
  static const Mesh truth = generateSailMesh(exampleDesign(SailType::Main), 400, 200);
  static const DesignDistance distance(truth);
  if (points.empty()) return std::nan("");
  double sum2 = 0;
  for (double d : signedDistances(distance, points)) sum2 += d * d;
  return 1e3 * std::sqrt(sum2 / static_cast<double>(points.size()));
}

void wholeAnalysis(benchmark::State& state, const AnalysisParams& p) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  const SailSurface truth(exampleDesign(SailType::Main));
  double camber = 0, draft = 0, twist = 0, ends = 0;
  size_t unmeasured = 0;  // sections or end angles the errors above could not include
  std::map<std::string, double> stage_ms;  // summed over iterations
  size_t working_points = 0;
  std::vector<Vec3> smoothed;
  for (auto _ : state) {
    SailAnalysis a = analyzeSail(c, p);
    working_points = a.working_points;
    smoothed = std::move(a.mesh.vertices);  // read after the runs, not timed
    for (const StageReport& r : a.stages) stage_ms[r.name] += 1e3 * r.seconds;
    unmeasured += a.sections.unmeasured.size();
    for (const Section& s : a.sections.sections) {
      unmeasured += !std::isfinite(s.value.entry_deg) + !std::isfinite(s.value.exit_deg);
      const KnownSection k = truth.section(s.fraction);
      camber = std::max(camber, std::abs(s.value.camber_pct - k.camber_pct));
      draft = std::max(draft, std::abs(s.value.draft_pct - k.draft_pct));
      twist = std::max(twist, std::abs(s.value.twist_deg - k.twist_deg));
      ends = std::max({ends, std::abs(s.value.entry_deg - k.entry_deg), std::abs(s.value.exit_deg - k.exit_deg)});
    }
  }
  state.counters["err_camber_pct"] = camber;
  state.counters["err_draft_pct"] = draft;
  state.counters["err_twist_deg"] = twist;
  state.counters["err_entry_exit_deg"] = ends;
  state.counters["unmeasured"] = static_cast<double>(unmeasured);
  state.counters["working_points"] = static_cast<double>(working_points);
  state.counters["surface_rms_mm"] = rmsToTruthMm(smoothed);
  state.counters["scan_rms_mm"] = rmsToTruthMm(c.points);  // the noise the smoothing starts from
  // Each stage's wall time, ms per run ("statistical outliers" -> "ms_statistical_outliers").
  for (const auto& [name, ms] : stage_ms) {
    std::string key = "ms_" + name;
    std::replace(key.begin(), key.end(), ' ', '_');
    state.counters[key] = ms / static_cast<double>(state.iterations());
  }
  finish(state, c.size());
}
// Our defaults: a scan with three samples or more per 2 cm column goes on after
// segmentation as one point per column (AnalysisParams::working_voxel_sigmas).
void BM_Ours_WholeAnalysis(benchmark::State& state) { wholeAnalysis(state, AnalysisParams{}); }
// Every scan point through every stage, as PCL's chain below takes them.
void BM_Ours_WholeAnalysisEveryPoint(benchmark::State& state) {
  AnalysisParams p;
  p.working_voxel_sigmas = 0;
  wholeAnalysis(state, p);
}
// The same chain with PCL's stock classes: normals → region growing → SOR →
// MLS → greedy projection (no outline or section analysis exists in PCL).
void BM_Pcl_WholeAnalysis(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  pcl::PointCloud<pcl::PointNormal>::Ptr smoothed;  // the last run's MLS output, read after the runs
  for (auto _ : state) {
    const auto pc = toPcl(sail(n));
    const AnalysisParams p;
    const std::vector<pcl::PointIndices> clusters =
        pclRegionGrowing(pc, pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(), p);
    auto sail_pts = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    size_t best = 0;
    for (size_t i = 1; i < clusters.size(); ++i)
      if (clusters[i].indices.size() > clusters[best].indices.size()) best = i;
    if (clusters.empty()) {
      // So it is at 1,000,000 points with our parameters (k = 30 neighbours span a
      // patch a few noise σ wide there), and PCL's later classes crash on an empty cloud.
      state.SkipWithError("PCL's region growing found no cluster at this density");
      break;
    }
    for (int i : clusters[best].indices) sail_pts->push_back((*pc)[static_cast<size_t>(i)]);
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
    sor.setInputCloud(sail_pts);
    sor.setMeanK(p.statistical.k_neighbours);
    sor.setStddevMulThresh(p.statistical.std_ratio);
    auto cleaned = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    sor.filter(*cleaned);
    pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointNormal> mls;
    mls.setInputCloud(cleaned);
    mls.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    mls.setSearchRadius(std::sqrt(60.0 / (M_PI * static_cast<double>(n) / 18.0)));
    mls.setPolynomialOrder(2);
    mls.setComputeNormals(true);
    smoothed = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>();
    mls.process(*smoothed);
    pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
    gp3.setSearchRadius(5 * std::sqrt(18.0 / static_cast<double>(n)));
    gp3.setMu(2.5);
    gp3.setMaximumNearestNeighbors(100);
    gp3.setInputCloud(smoothed);
    gp3.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointNormal>>());
    pcl::PolygonMesh mesh;
    gp3.reconstruct(mesh);
    benchmark::DoNotOptimize(mesh.polygons.size());
  }
  if (smoothed && !smoothed->empty()) {
    std::vector<Vec3> points;
    for (const pcl::PointNormal& q : *smoothed) points.emplace_back(q.x, q.y, q.z);
    state.counters["surface_rms_mm"] = rmsToTruthMm(points);
  }
  finish(state, n);
}

// ---- design vs flying: signed distance of the flying points to a ~50,000-triangle design ----
void BM_Ours_SignedDistance(benchmark::State& state) {
  const Cloud& c = sail(static_cast<size_t>(state.range(0)));
  SailDesign design = exampleDesign(SailType::Main);
  design.stations[1].camber_pct -= 2;  // the flying shape differs from its design
  const Mesh mesh = generateSailMesh(design, 250, 100);  // 50,000 triangles
  const DesignDistance distance(mesh);
  for (auto _ : state) benchmark::DoNotOptimize(signedDistances(distance, c.points));
  state.counters["design_triangles"] = static_cast<double>(mesh.triangles.size());
  finish(state, c.size());
}

// ---- the design fitted to a flying scan (issue 37): ~100,000 samples, a 20,100-vertex design ----
// The known-answer case of tests/analysis/fit (a square-top main 3 % deeper and 2° + 10°·f more
// twisted, 4 mm noise, a hole over 20 % of the height, nothing above 88 %) at full size; the
// counters give the fitted vertices' RMS to the true flying surface per region.
void BM_Ours_DesignFit(benchmark::State& state) {
  FitCaseOptions o;
  o.points = static_cast<size_t>(state.range(0));
  o.rows = 200;
  o.columns = 99;  // 201 × 100 vertices
  const FitCase c = makeFitCase(o);
  DesignFit fit;
  for (auto _ : state) fit = fitDesign(c.design_mesh, c.scan.points);
  const auto e = regionErrors(fit.fitted.vertices, c, o, &fit.supported);
  const auto design = regionErrors(c.design_mesh.vertices, c, o);
  state.counters["scan_points"] = static_cast<double>(c.scan.size());
  state.counters["design_vertices"] = static_cast<double>(c.design_mesh.vertices.size());
  state.counters["scanned_rms_mm"] = 1000 * e[0].rms_m;
  state.counters["hole_rms_mm"] = 1000 * e[1].rms_m;
  state.counters["above_rms_mm"] = 1000 * e[2].rms_m;
  state.counters["design_above_rms_mm"] = 1000 * design[2].rms_m;
  state.counters["coverage"] = fit.coverage;
  finish(state, c.scan.size());
}

// ---- registration (issue 5): the two-unit tunnel scene at about 200,000 points per unit ----
// Plane method (detection in both clouds, matching, crossed filter, anchored
// point-to-plane ICP) on 4 mm noise; counters give the errors against the truth.
void BM_Ours_Registration(benchmark::State& state) {
  TunnelSceneParams p;
  p.noise_sigma_m = 0.004;
  p.seed = 5;
  const double scale = static_cast<double>(state.range(0)) / 23'800.0;  // the default scene has ~23,800 points per unit
  p.chamber_density_per_m2 *= scale;
  p.cube_density_per_m2 *= scale;
  p.sail_points = static_cast<size_t>(static_cast<double>(p.sail_points) * scale);
  const TunnelScene scene = makeTunnelScene(p);
  Registration r;
  for (auto _ : state) r = registerClouds(scene.reference, scene.moving);
  state.counters["reference_points"] = static_cast<double>(scene.reference.size());
  state.counters["moving_points"] = static_cast<double>(scene.moving.size());
  state.counters["rotation_error_deg"] = rotationDifferenceDeg(r.rotation, scene.truth.linear());
  state.counters["translation_error_mm"] = (r.translation - scene.truth.translation()).norm() * 1000;
  state.counters["accepted"] = r.accepted ? 1 : 0;
  finish(state, scene.reference.size() + scene.moving.size());
}

// ---- the design-flying database: 10,000 scans, 200,000 sections ----
// 40 sails (10 boats, 4 types, 5 campaigns), 250 scans each in 25 tests of 10
// trim steps; AWA uniform in 30..170°, forces and two control settings random
// (seed 11); 20 sections per scan. Built once in a temp file, removed at exit.
struct BenchDatabase {
  std::string path = "/tmp/sailshape-bench-" + std::to_string(getpid()) + ".db";
  std::unique_ptr<Database> db;
  double build_seconds = 0;
  BenchDatabase() {
    const auto start = std::chrono::steady_clock::now();
    db = std::make_unique<Database>(openSailDatabase(path));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> awa(30, 170), force(50, 500), control(0, 1), camber(5, 20);
    const char* types[] = {"mainsail", "genoa", "gennaker", "spinnaker"};
    nlohmann::json doc;
    doc["sections"] = nlohmann::json::array();
    for (int k = 0; k < 20; ++k) doc["sections"].push_back({{"fraction", (k + 1) / 21.0}});
    for (int scan = 0; scan < 10'000; ++scan) {
      const int sail = scan / 250, test = (scan % 250) / 10, step = scan % 10;
      ImportMetadata m;
      m.campaign = "campaign-" + std::to_string(sail % 5);
      m.boat = "boat-" + std::to_string(sail % 10);
      m.sail = "sail-" + std::to_string(sail);
      m.sail_type = types[sail % 4];
      m.test = "test-" + std::to_string(test);
      m.trim_step = step;
      m.awa_deg = awa(rng);
      m.drive_n = force(rng);
      m.side_n = force(rng);
      m.controls = {{"sheet", control(rng)}, {"tack_height", control(rng)}};
      for (auto& sec : doc["sections"]) {
        sec["camber_pct"] = camber(rng);
        sec["draft_pct"] = 40.0;
        sec["twist_deg"] = 10.0;
        sec["uncertainty"] = {{"camber_pct", 0.2}};
        sec["curve"] = {{0.0, 0.0, 1.0}, {1.0, 0.1, 1.0}, {2.0, 0.0, 1.0}};
      }
      importScan(*db, m, &doc);
    }
    build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  ~BenchDatabase() {
    db.reset();
    for (const char* tail : {"", "-wal", "-shm"}) std::remove((path + tail).c_str());
  }
};

BenchDatabase& benchDatabase() {
  static BenchDatabase b;
  return b;
}

template <typename Query>
void runQuery(benchmark::State& state, Query query) {
  BenchDatabase& b = benchDatabase();
  size_t rows = 0;
  for (auto _ : state) rows = query(*b.db).rows.size();
  state.counters["rows"] = static_cast<double>(rows);
  state.counters["build_s"] = b.build_seconds;
}

void BM_Db_ScansBySailAndAwa(benchmark::State& state) {
  ScanFilter f;
  f.sail = "sail-7";
  f.awa_min_deg = 90;
  f.awa_max_deg = 100;
  runQuery(state, [&](Database& db) { return findScans(db, f); });
}
void BM_Db_ScansBySailTypeAndControl(benchmark::State& state) {
  ScanFilter f;
  f.sail_type = "genoa";
  f.control = "sheet";
  f.control_min = 0.4;
  f.control_max = 0.5;
  runQuery(state, [&](Database& db) { return findScans(db, f); });
}
void BM_Db_ScansByCampaign(benchmark::State& state) {
  ScanFilter f;
  f.campaign = "campaign-3";
  runQuery(state, [&](Database& db) { return findScans(db, f); });
}
void BM_Db_SectionsByAwa(benchmark::State& state) {
  ScanFilter f;
  f.awa_min_deg = 94;
  f.awa_max_deg = 96;
  runQuery(state, [&](Database& db) { return findSections(db, f); });
}
void BM_Db_ParameterEvolution(benchmark::State& state) {
  ScanFilter f;
  f.sail = "sail-12";
  runQuery(state, [&](Database& db) { return parameterEvolution(db, "test-3", "camber_pct", 0.5, f); });
}
void BM_Db_CompareSails(benchmark::State& state) {
  runQuery(state, [&](Database& db) { return compareSails(db, "sail-3", "sail-17", 95.0, 5.0); });
}
void BM_Db_BestTrimStep(benchmark::State& state) {
  runQuery(state, [&](Database& db) { return bestTrimSteps(db, 85, 105, TrimCriterion::DriveOverSide, 5); });
}

// ---- the emulator's ray casting: the built-in tunnel scene, ours against VTK's vtkModifiedBSPTree ----
// The rays of an LMS511 sweep over the main from the demo's main unit: vertical scan planes at 1/6°
// beam steps over the 190° fan, turned about the vertical shaft through 60° in `lines` scan lines
// (the demo's 300-line sweep is 342,000 beams). Each beam is cast as the sensor model casts it: the
// axis ray and four rim rays (at the exit radius, half the divergence out), five rays a beam; the
// fan, steps, divergence, exit window and range are the LMS511's data-sheet facts (scannerSpec).
// Counters: build_ms (the hierarchy or locator), and on VTK's side the largest range difference
// and the count of rays one caster hits and the other misses (grazing triangle edges).
struct SweepRays {
  std::vector<Vec3> origins, directions;  // five per beam: axis, then the four rim rays
};

const SweepRays& sweepRays(int lines) {
  static std::map<int, SweepRays> cache;
  auto it = cache.find(lines);
  if (it != cache.end()) return it->second;
  SweepRays r;
  const ScannerSpec lms511 = scannerSpec(ScannerModel::Lms511);
  const Vec3 unit(-0.5, -3.0, 1.1), up = Vec3::UnitZ();
  const double deg = M_PI / 180.0, step = lms511.default_resolution_deg * deg;
  for (int l = 0; l < lines; ++l) {
    const double yaw = (60.0 + 60.0 * l / std::max(1, lines - 1)) * deg;
    const Vec3 across(std::cos(yaw), std::sin(yaw), 0.0);
    for (double a = lms511.first_angle_deg * deg; a <= lms511.last_angle_deg * deg + 1e-9; a += step) {
      const Vec3 d = std::cos(a) * across + std::sin(a) * up;
      const BeamFootprint beam = beamFootprint(lms511, unit, d);
      for (int k = 0; k < 5; ++k) {
        r.origins.push_back(beam.origins[k]);
        r.directions.push_back(beam.directions[k].normalized());
      }
    }
  }
  return cache.emplace(lines, std::move(r)).first->second;
}

const double kLmsMaxRangeM = scannerSpec(ScannerModel::Lms511).max_range_m;

double millisecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void BM_Ours_RayCast(benchmark::State& state) {
  const Scene scene = builtInTunnelScene();
  const auto t0 = std::chrono::steady_clock::now();
  const RayCaster caster(scene);
  const double build_ms = millisecondsSince(t0);
  const SweepRays& r = sweepRays(static_cast<int>(state.range(0)));
  size_t hits = 0;
  for (auto _ : state)
    for (size_t i = 0; i < r.origins.size(); ++i)
      hits += caster.cast(r.origins[i], r.directions[i], 1e-6, kLmsMaxRangeM).hit;
  benchmark::DoNotOptimize(hits);
  state.counters["build_ms"] = build_ms;
  state.counters["triangles"] = static_cast<double>(caster.triangleCount());
  finish(state, r.origins.size());
}

// The same rays a beam at a time, as the emulator casts them: one traversal for its five rays.
void BM_Ours_RayCastFootprint(benchmark::State& state) {
  const RayCaster caster(builtInTunnelScene());
  const SweepRays& r = sweepRays(static_cast<int>(state.range(0)));
  size_t hits = 0;
  RayHit out[5];
  for (auto _ : state)
    for (size_t i = 0; i < r.origins.size(); i += 5) {
      caster.castBundle(&r.origins[i], &r.directions[i], 5, out, 1e-6, kLmsMaxRangeM);
      for (const RayHit& h : out) hits += h.hit;
    }
  benchmark::DoNotOptimize(hits);
  finish(state, r.origins.size());
}

void BM_Vtk_RayCast(benchmark::State& state) {
  const Scene scene = builtInTunnelScene();
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> cells;
  for (const SceneObject& o : scene.objects) {
    const vtkIdType base = points->GetNumberOfPoints();
    for (const Vec3& v : o.mesh.vertices) points->InsertNextPoint(v.x(), v.y(), v.z());
    for (const auto& t : o.mesh.triangles) {
      const vtkIdType ids[3] = {base + t[0], base + t[1], base + t[2]};
      cells->InsertNextCell(3, ids);
    }
  }
  vtkNew<vtkPolyData> mesh;
  mesh->SetPoints(points);
  mesh->SetPolys(cells);
  const auto t0 = std::chrono::steady_clock::now();
  vtkNew<vtkModifiedBSPTree> tree;
  tree->SetDataSet(mesh);
  tree->LazyEvaluationOff();  // built here, not on the first query
  tree->BuildLocator();
  vtkNew<vtkGenericCell> scratch;  // one cell reused by every query
  const double build_ms = millisecondsSince(t0);
  const SweepRays& r = sweepRays(static_cast<int>(state.range(0)));
  std::vector<double> range(r.origins.size());
  for (auto _ : state)
    for (size_t i = 0; i < r.origins.size(); ++i) {
      const Vec3 far = r.origins[i] + kLmsMaxRangeM * r.directions[i];
      double t = 0, x[3], pcoords[3];
      int sub = 0;
      vtkIdType cell = -1;
      const bool hit = tree->IntersectWithLine(r.origins[i].data(), far.data(), 0.0, t, x, pcoords, sub, cell, scratch);
      range[i] = hit ? t * kLmsMaxRangeM : -1;
    }
  // Agreement with ours, outside the timing.
  const RayCaster caster(scene);
  double max_diff_mm = 0;
  size_t disagree = 0;
  for (size_t i = 0; i < r.origins.size(); ++i) {
    const RayHit h = caster.cast(r.origins[i], r.directions[i], 1e-6, kLmsMaxRangeM);
    if (h.hit != (range[i] >= 0))
      ++disagree;
    else if (h.hit)
      max_diff_mm = std::max(max_diff_mm, 1e3 * std::abs(h.distance_m - range[i]));
  }
  state.counters["build_ms"] = build_ms;
  state.counters["max_range_diff_mm"] = max_diff_mm;
  state.counters["hit_miss_disagreements"] = static_cast<double>(disagree);
  finish(state, r.origins.size());
}

#define SIZES Arg(50'000)->Arg(200'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->Iterations(1)
BENCHMARK(BM_Ours_Normals)->SIZES;
BENCHMARK(BM_Pcl_Normals)->SIZES;
BENCHMARK(BM_Ours_RegionGrowing)->SIZES;
BENCHMARK(BM_Pcl_RegionGrowing)->SIZES;
BENCHMARK(BM_Ours_StatisticalOutliers)->SIZES;
BENCHMARK(BM_Pcl_StatisticalOutliers)->SIZES;
BENCHMARK(BM_Ours_Mls)->SIZES;
BENCHMARK(BM_Pcl_Mls)->SIZES;
BENCHMARK(BM_Ours_Surface)->SIZES;
BENCHMARK(BM_Pcl_GreedyProjection)->SIZES;
BENCHMARK(BM_Ours_WholeAnalysis)->SIZES;
BENCHMARK(BM_Ours_WholeAnalysisEveryPoint)->SIZES;
BENCHMARK(BM_Pcl_WholeAnalysis)->SIZES;
BENCHMARK(BM_Ours_SignedDistance)->SIZES;
BENCHMARK(BM_Ours_DesignFit)->Arg(122'000)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Ours_Registration)->Arg(50'000)->Arg(200'000)->Unit(benchmark::kMillisecond)->Iterations(1);
#define RAYS Arg(30)->Arg(300)->Unit(benchmark::kMillisecond)->Iterations(1)
BENCHMARK(BM_Ours_RayCast)->RAYS;
BENCHMARK(BM_Ours_RayCastFootprint)->RAYS;
BENCHMARK(BM_Vtk_RayCast)->RAYS;
#define QUERY Unit(benchmark::kMillisecond)
BENCHMARK(BM_Db_ScansBySailAndAwa)->QUERY;
BENCHMARK(BM_Db_ScansBySailTypeAndControl)->QUERY;
BENCHMARK(BM_Db_ScansByCampaign)->QUERY;
BENCHMARK(BM_Db_SectionsByAwa)->QUERY;
BENCHMARK(BM_Db_ParameterEvolution)->QUERY;
BENCHMARK(BM_Db_CompareSails)->QUERY;
BENCHMARK(BM_Db_BestTrimStep)->QUERY;

}  // namespace

BENCHMARK_MAIN();
