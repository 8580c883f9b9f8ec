#pragma once
// Live mode: the scanner units sweep again and again; each completed sweep is
// analysed on a second thread while the next sweep runs, and the panels take
// the results as they come (trim feedback while the crew trims). A sweep whose
// analysis fails is reported with its reason and the loop goes on; a sweep that
// cannot be taken at all (no unit answers) ends live mode.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "viewer/processing.hpp"
#include "viewer/scan_scene.hpp"
#include "viewer/scanner_session.hpp"

namespace sailshape::viewer {

// The region a crew draws around one sail (study §5.4): its design's bounding box
// grown by `margin_m` on every side, nothing below `min_z_m` (the deck). A unit's
// sweep also holds deck, hull, spars and other sails, which the pipeline's
// segmentation need not sort out when the box leaves them out.
// Throws InvalidInput for an empty design or a negative margin.
RoiBox sailRoi(const Mesh& design, double margin_m = 0.3, double min_z_m = -1e9);

// The pipeline's parameters for a unit's view of a designed sail: `sections`
// sections (SPEC §5 fractions k/(N+1)), and the design's luff, leech and foot
// lengths to check the outline against, so that a view which lost the head or a
// corner fails with that reason instead of cutting sections in the wrong place.
// Throws InvalidInput for sections outside 1..20, AnalysisError when the design
// mesh has no outline.
AnalysisParams designedSailParams(const Mesh& design, int sections, AnalysisParams base = {});

struct LiveParams {
  // Every sweep homes first (sweep.home): a sweep started where the last one ended,
  // without homing, distorts the sail's outline.
  SweepOptions sweep;
  SceneOptions scene;                // the analysis of each sweep (scene.roi: the sail's region)
  std::optional<Mesh> design;        // deviation and design sections; none: flying values only
  std::string save_to;               // database file each sweep is stored in (empty: not stored)
  TrimStepForm form;                 // the trim-step data stored with each sweep
  int max_sweeps = 0;                // stop after this many sweeps (0: until stopped)
};

struct LiveSweep {
  int index = 0;                     // 1, 2, ... in sweep order
  size_t points = 0;                 // every unit's points
  std::optional<ScanScene> scene;    // what the panels show; empty when the analysis failed
  std::string error;                 // why the analysis failed; empty when it worked
  std::string store_error;           // why storing failed (save_to set); empty when stored or not asked
  std::vector<std::string> warnings; // partial sweeps, pipeline warnings
  int64_t scan_id = 0;               // stored as this scan (0: not stored)
  double sweep_s = 0, analysis_s = 0;
};

struct LiveStatus {
  bool running = false;
  int swept = 0, analysed = 0, failed = 0;
  int skipped = 0;                   // sweeps replaced by a newer one before their analysis began
  std::string stage;                 // what the loop does now ("sweep 3", "stopping")
  std::string error;                 // why live mode ended early (a sweep could not be taken)
};

class LiveMode {
 public:
  LiveMode() = default;
  ~LiveMode();  // stops and waits
  LiveMode(const LiveMode&) = delete;
  LiveMode& operator=(const LiveMode&) = delete;

  // Starts sweeping every unit of `session` (copied: the emulators stay alive with it).
  // Throws InvalidInput without units or for a negative max_sweeps, std::logic_error while running.
  void start(const ScannerSession& session, LiveParams params);
  // The analysis of the next sweep on uses these (e.g. the user changed the sections).
  void setSceneOptions(const SceneOptions& options);
  // Returns at once: the sweep under way is cancelled, a sweep already taken is still analysed.
  void requestStop();
  void stop();  // requestStop() and wait until both threads have ended
  bool running() const;
  LiveStatus status() const;
  // The analysed sweeps since the last call, oldest first.
  std::vector<LiveSweep> take();

 private:
  void sweepLoop();
  void analysisLoop();
  LiveSweep analyse(int index, Acquisition acquisition, double sweep_s, std::optional<Database>& db);

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  ScannerSession session_;
  LiveParams params_;
  bool stop_ = false, sweeping_done_ = false, running_ = false;
  std::optional<std::pair<int, Acquisition>> pending_;  // the newest sweep not yet analysed
  double pending_sweep_s_ = 0;
  std::deque<LiveSweep> results_;
  LiveStatus status_;
  std::thread sweeper_, analyser_;
};

}  // namespace sailshape::viewer
