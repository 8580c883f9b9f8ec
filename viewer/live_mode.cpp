#include "viewer/live_mode.hpp"

#include <chrono>
#include <filesystem>

#include "acquisition/sensor_model.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "database/schema.hpp"
#include "viewer/worker.hpp"

namespace sailshape::viewer {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

RoiBox sailRoi(const Mesh& design, double margin_m, double min_z_m) {
  if (design.vertices.empty()) throw InvalidInput("[sailRoi] the design mesh has no vertex");
  if (!(margin_m >= 0)) throw InvalidInput("[sailRoi] margin_m must be >= 0 (got " + std::to_string(margin_m) + ")");
  RoiBox roi;
  roi.enabled = true;
  roi.min_m = roi.max_m = design.vertices.front();
  for (const Vec3& v : design.vertices) {
    roi.min_m = roi.min_m.cwiseMin(v);
    roi.max_m = roi.max_m.cwiseMax(v);
  }
  roi.min_m.array() -= margin_m;
  roi.max_m.array() += margin_m;
  roi.min_m.z() = std::max(roi.min_m.z(), min_z_m);
  if (roi.min_m.z() > roi.max_m.z())
    throw InvalidInput("[sailRoi] min_z_m " + std::to_string(min_z_m) + " m lies above the sail's head");
  return roi;
}

AnalysisParams designedSailParams(const Mesh& design, int sections, AnalysisParams base) {
  if (sections < 1 || sections > 20)
    throw InvalidInput("[designedSailParams] sections must be in 1..20 (got " + std::to_string(sections) + ")");
  base.sections.count = sections;
  base.sections.fractions.clear();
  const MeshSections d = analyzeMeshSections(design, {}, base.sections);
  base.outline.design_lengths_m = {d.outline.luff_length_m, d.outline.leech_length_m, d.outline.foot_length_m};
  return base;
}

LiveMode::~LiveMode() { stop(); }

void LiveMode::start(const ScannerSession& session, LiveParams params) {
  if (session.units().empty())
    throw InvalidInput("[LiveMode::start] no scanner unit: load a unit file or add an emulated unit");
  if (params.max_sweeps < 0)
    throw InvalidInput("[LiveMode::start] max_sweeps must be >= 0 (got " + std::to_string(params.max_sweeps) + ")");
  if (!params.save_to.empty() && !isPostgresUrl(params.save_to) && !std::filesystem::exists(params.save_to))
    throw InvalidInput("[LiveMode::start] database file not found: " + params.save_to);
  parseControls(params.form.controls);  // a bad entry is refused now, not at the first store
  if (running()) throw std::logic_error("[LiveMode::start] live mode is already running");
  stop();  // joins the threads of a run that ended by itself
  std::lock_guard<std::mutex> lock(mutex_);
  session_ = session;
  params_ = std::move(params);
  stop_ = false;
  sweeping_done_ = false;
  running_ = true;
  pending_.reset();
  results_.clear();
  status_ = LiveStatus{};
  status_.running = true;
  status_.stage = "starting";
  sweeper_ = std::thread(&LiveMode::sweepLoop, this);
  analyser_ = std::thread(&LiveMode::analysisLoop, this);
}

void LiveMode::setSceneOptions(const SceneOptions& options) {
  std::lock_guard<std::mutex> lock(mutex_);
  params_.scene = options;
}

void LiveMode::requestStop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stop_ = true;
  if (running_) status_.stage = "stopping";
  wake_.notify_all();
}

void LiveMode::stop() {
  requestStop();
  if (sweeper_.joinable()) sweeper_.join();
  if (analyser_.joinable()) analyser_.join();
}

bool LiveMode::running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_;
}

LiveStatus LiveMode::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

std::vector<LiveSweep> LiveMode::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<LiveSweep> out(std::make_move_iterator(results_.begin()), std::make_move_iterator(results_.end()));
  results_.clear();
  return out;
}

void LiveMode::sweepLoop() {
  SweepOptions options;
  int max_sweeps = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    options = params_.sweep;
    max_sweeps = params_.max_sweeps;
  }
  // Stopping cancels the sweep under way at its next progress report.
  const Progress progress{[this](std::string_view, double) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) throw Cancelled();
  }};
  for (int index = 1; max_sweeps == 0 || index <= max_sweeps; ++index) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) break;
      status_.stage = "sweep " + std::to_string(index);
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      Acquisition a = session_.scan(options, progress);
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) break;      // a synchronised scan reports a cancelled unit as its error
      if (a.cloud.empty()) {
        std::string why;
        for (size_t u = 0; u < a.errors.size(); ++u)
          if (!a.errors[u].empty()) why += (why.empty() ? "" : "; ") + ("unit " + std::to_string(u + 1) + ": " + a.errors[u]);
        status_.error = "sweep " + std::to_string(index) + " brought no point" + (why.empty() ? "" : " (" + why + ")");
        break;
      }
      ++status_.swept;
      if (pending_) ++status_.skipped;  // the analysis fell behind: the newer sweep wins
      pending_ = std::make_pair(index, std::move(a));
      pending_sweep_s_ = secondsSince(t0);
      wake_.notify_all();
    } catch (const Cancelled&) {
      try {
        session_.stopTurntables();
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        status_.error = std::string("stopping the sweep: ") + e.what();
      }
      break;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!stop_) status_.error = "sweep " + std::to_string(index) + ": " + e.what();
      break;
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  sweeping_done_ = true;
  wake_.notify_all();
}

void LiveMode::analysisLoop() {
  std::optional<Database> db;  // this thread's own connection, opened at the first store
  for (;;) {
    std::pair<int, Acquisition> job;
    double sweep_s = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return pending_.has_value() || sweeping_done_; });
      if (!pending_) break;
      job = std::move(*pending_);
      pending_.reset();
      sweep_s = pending_sweep_s_;
    }
    LiveSweep r = analyse(job.first, std::move(job.second), sweep_s, db);
    std::lock_guard<std::mutex> lock(mutex_);
    ++(r.scene ? status_.analysed : status_.failed);
    results_.push_back(std::move(r));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  running_ = false;
  status_.running = false;
  status_.stage = status_.error.empty() ? "stopped" : "ended";
}

LiveSweep LiveMode::analyse(int index, Acquisition a, double sweep_s, std::optional<Database>& db) {
  SceneOptions options;
  std::optional<Mesh> design;
  TrimStepForm form;
  std::string save_to;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    options = params_.scene;
    design = params_.design;
    form = params_.form;
    save_to = params_.save_to;
  }
  // A single unit's sweep: its beam's footprint trims every edge (SPEC §3), unless
  // the parameters already name a beam.
  if (a.model) useScannerBeamUnlessGiven(options.analysis.outline, *a.model, a.cloud);
  LiveSweep r;
  r.index = index;
  r.points = a.cloud.size();
  r.sweep_s = sweep_s;
  r.warnings = a.warnings;
  for (size_t u = 0; u < a.errors.size(); ++u)
    if (!a.errors[u].empty()) r.warnings.push_back("unit " + std::to_string(u + 1) + " did not sweep: " + a.errors[u]);

  const auto t0 = std::chrono::steady_clock::now();
  ScanRecord record;
  record.campaign = form.campaign;
  record.test = form.test;
  record.sail = form.sail;
  record.step = form.step;
  record.awa_deg = form.awa_deg;
  record.has_design = design.has_value();
  record.cloud = a.cloud;
  ScanScene scene = buildScanScene(std::move(record), std::move(design), options);
  r.analysis_s = secondsSince(t0);
  if (scene.analysis) {
    for (const auto& w : scene.analysis->warnings) r.warnings.push_back(w);
  } else {
    r.error = scene.analysis_error.empty() ? "the analysis gave no result" : scene.analysis_error;
  }

  if (!save_to.empty()) {
    try {
      if (!db) {
        OpenOptions open;
        open.create = false;
        db = openSailDatabase(save_to, open);
      }
      const ImportResult stored = saveAcquisition(*db, a, form);
      r.scan_id = scene.record.scan_id = stored.scan_id;
      if (scene.analysis) {
        StageResult result;
        result.stage = ProcessingStage::Sections;
        result.analysis = *scene.analysis;
        ProcessingParams pp;
        pp.roi = options.roi;
        pp.analysis = options.analysis;
        saveStageResult(*db, stored.scan_id, result, pp);
      }
    } catch (const std::exception& e) {
      r.store_error = e.what();
    }
  }
  if (scene.analysis) r.scene = std::move(scene);
  return r;
}

}  // namespace sailshape::viewer
