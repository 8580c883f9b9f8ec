#pragma once
// The viewer's window content: toolbar, database browser, 3D view, plots, and
// the Sections, Trim steps, Processing, Scanners (with live mode) and Messages
// tabs. All UI state lives in the structs below; drawing happens in App::frame()
// between ImGui::NewFrame and ImGui::Render. App's frame and jobs are in
// app.cpp, each panel in its own *_panel.cpp.
#include <cstdint>
#include <array>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "database/sqlite.hpp"
#include "viewer/catalog_tree.hpp"
#include "viewer/live_mode.hpp"
#include "viewer/processing.hpp"
#include "viewer/scan_scene.hpp"
#include "viewer/scanner_session.hpp"
#include "viewer/section_table.hpp"
#include "viewer/unit_camera.hpp"
#include "viewer/vtk_viewport.hpp"
#include "viewer/worker.hpp"

namespace sailshape::viewer {

struct DatabaseState {
  std::string path;                 // what was asked for
  std::optional<Database> db;
  std::string error;                // why it is not open
  char path_input[1024] = {};
};

struct BrowserState {
  CatalogTree tree;
  int64_t selected_scan = 0;        // 0: none
  std::set<int64_t> overlays;       // scans overlaid on the selected one
};

struct LoadState {
  Task<ScanScene> task;
  int64_t pending_scan = 0;         // the selected scan, waiting for the task to be free
  int64_t loading_scan = 0;         // what the task is building
  bool loading_overlay = false;
  std::deque<int64_t> overlay_queue;
  std::optional<ScanScene> scene;   // the selected scan, once built
  std::map<int64_t, ScanScene> overlays;
  SceneOptions options;
};

struct ProcessingState {
  ProcessingParams params;
  Task<StageResult> task;
  std::optional<StageResult> result;
  int64_t result_scan = 0;
  ProcessingParams result_params;   // what the result ran with (params, plus the scan's beam)
  bool show_result = true;
  std::string note;                 // last save or failure
};

struct PickState {
  std::optional<PickInfo> info;
  float press_x = 0, press_y = 0;
  bool pressed_in_view = false;
  std::optional<std::array<float, 2>> pending;  // scripted pick, fractions of the view
};

struct PlotState {
  SectionField fields[3] = {SectionField::Camber, SectionField::Draft, SectionField::Twist};
  SectionField compare_field = SectionField::Camber;
};

struct ViewState {
  ViewOptions options;
  bool rebuild = true;              // actors must be rebuilt before the next render
  std::optional<CameraPreset> camera;
  std::optional<CameraPlacement> placement;  // the view from a scanner unit, applied on the next frame
  int width = 0, height = 0;        // last rendered size of the 3D view, pixels
  bool hovered = false;
};

// The Report button: a PDF of the selected scan or of its test (reports/trim_report.hpp).
struct ReportState {
  Task<std::string> task;           // result: what was written
  bool popup = false;
  bool whole_test = false;
  int audience = 1;                 // 0 crew, 1 designer
  char out_path[1024] = {};
  std::string note;
};

// The scanner panel: units, one scan of all of them, the trim-step data, saving.
struct ScannerState {
  ScannerSession session;
  char unit_path[1024] = {};
  char campaign[128] = "default", session_name[128] = "default", sail[128] = "default", test[128] = {},
       controls[256] = {};
  int step = 0;
  bool has_awa = false, has_aws = false, has_forces = false;
  double awa_deg = 30, aws_m_s = 5, drive_n = 0, side_n = 0;
  Task<Acquisition> scan_task;
  Task<std::string> home_task;
  std::optional<Acquisition> last;       // the latest scan, not yet saved
  std::optional<StageResult> preview;    // its cloud, shown in the 3D view
  // The cloud as it arrives during a scan; shown at most every kArrivingRefreshS.
  std::shared_ptr<ArrivingPoints> arriving = std::make_shared<ArrivingPoints>();
  uint64_t arriving_seen = 0;
  double arriving_shown_s = 0;
  std::string note;
};

// Live mode (Scanners tab): sweep after sweep, each analysed as it comes and shown.
struct LiveState {
  LiveMode mode;
  int sections = 2;                 // one unit's view of the upper sail holds 2 sections better than 3
  double roi_margin_m = 0.3;
  bool save_each = false;           // store every sweep (with its analysis) in the open database
  std::string design_source;        // where the ROI and the comparison come from
  int shown_sweep = 0;              // the sweep the panels show (0: they show a stored scan)
  std::string note;
  std::vector<std::string> messages;  // failed analyses and stores, newest last
};

struct MessageLog {
  std::vector<std::string> lines;   // newest last
  void info(const std::string& text);
  void error(const std::string& text);  // also written to stderr
};

class App {
 public:
  explicit App(std::optional<std::string> database_path);
  ~App();

  // Draws the whole window for one frame (display size in pixels).
  void frame(float width, float height);
  // True while a scan or processing job runs (the screenshot mode waits for it).
  bool busy() const;
  // Set once the viewer has nothing left to load (initial scan shown or none to show).
  bool settled() const;
  const MessageLog& log() const { return log_; }
  bool databaseOpen() const { return database_.db.has_value(); }
  // Picks at (fx, fy), fractions of the 3D view (origin top-left), on the next drawn frame, as a click does.
  void requestPick(float fx, float fy) { pick_.pending = std::array<float, 2>{fx, fy}; }
  bool pickPending() const { return pick_.pending.has_value(); }
  const std::optional<PickInfo>& lastPick() const { return pick_.info; }
  // Writes the PDF report of the selected scan (or its whole test) on the worker; false when
  // there is no scan to report on (the reason goes to the message log).
  bool startReport(const std::string& out_path, bool whole_test, const std::string& audience);
  void setDeviationView(bool on) {
    view_.options.deviation = on;
    view_.rebuild = true;
  }
  const ViewOptions& viewOptions() const { return view_.options; }
  void setViewOptions(const ViewOptions& options) {
    view_.options = options;
    view_.rebuild = true;
  }
  // As the Scanners tab's buttons do; false when it could not (the reason goes to the message log).
  bool addEmulatedDeckUnit();
  bool startLive();
  void storeLiveSweeps(bool on) { live_.save_each = on; }
  void setCamera(CameraPreset preset) { view_.camera = preset; }
  // The view from a scanner unit, as the Unit button gives it: the unit that took the
  // stored scan shown, else the Scanners tab's first; false when there is neither.
  bool setUnitCamera();
  // What the panels show, as JSON (state.cpp): the scan, the view's captions, the
  // deviation from the design in mm, the section table, the browser and the messages.
  nlohmann::json state() const;
  void stopLive() { live_.mode.stop(); }
  LiveStatus liveStatus() const { return live_.mode.status(); }

 private:
  // The frame's own work (app.cpp): the database, the scan loads and every job's results.
  void openDatabase(const std::string& path);
  void selectScan(int64_t scan_id);
  void pollJobs();
  void startNextLoad();
  std::vector<Overlay> overlayList() const;

  // The panels, each in the file named after it.
  void drawToolbar(float x, float y, float w, float h);      // toolbar_panel.cpp
  void drawReportPopup();                                     // report_panel.cpp
  void drawBrowser(float x, float y, float w, float h);      // browser_panel.cpp
  void drawDisplayOptions();
  void drawView(float x, float y, float w, float h);         // view_panel.cpp
  void forwardViewInput(float origin_x, float origin_y);
  void drawViewCaptions(float origin_x, float origin_y, float w, float h);
  std::string viewTitle() const;                              // the scan shown, as the view's caption says
  std::optional<CameraPlacement> unitPlacement() const;       // scanners_panel.cpp
  void drawPlots(float x, float y, float w, float h);        // plots_panel.cpp
  void drawRightPanel(float x, float y, float w, float h);   // app.cpp: the tabs below
  void drawSectionTable();                                    // sections_panel.cpp
  void drawTrimComparison();                                  // trim_steps_panel.cpp
  void drawProcessing();                                      // processing_panel.cpp
  void startProcessing(ProcessingStage stage);
  void drawProcessingResult(bool running);
  void drawScanner();                                         // scanners_panel.cpp
  void drawUnits();
  void drawTrimStepFields();
  TrimStepForm trimStepForm() const;
  void drawLive();                                            // live_panel.cpp
  void takeLiveResults();
  void drawMessages();                                        // status_panel.cpp
  void drawStatus(float x, float y, float w, float h);

  DatabaseState database_;
  BrowserState browser_;
  LoadState load_;
  ProcessingState processing_;
  PickState pick_;
  PlotState plots_;
  ViewState view_;
  ReportState report_;
  ScannerState scanner_;
  LiveState live_;
  bool select_scanner_tab_ = false;
  MessageLog log_;
  std::unique_ptr<VtkViewport> viewport_;
  bool initial_load_done_ = false;
};

// The deviation line of the 3D view and of the Sections tab (mm).
std::string deviationCaption(const DistanceStats& d);
std::string deviationSummary(const DistanceStats& d);

// The colour of the k-th overlaid trim step.
Rgb overlayColour(size_t k);

}  // namespace sailshape::viewer
