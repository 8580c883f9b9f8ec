// A listener on SICK's own driver (sick_scan_xd, built without ROS): counts the point clouds the driver
// publishes from `sailshape emulate` for a while and prints their rate and size as one line.
//
//   client LAUNCHFILE_ARGS SECONDS
//
// Built and run by run.sh against the driver's shared library and its public API header (sick_scan_api.h);
// not part of the product build or of CI.
#include <sick_scan_xd_api/sick_scan_api.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace {

std::mutex g_mutex;
std::vector<double> g_arrivals_s;  // host time of each published cloud, seconds since the listener started
std::vector<uint32_t> g_widths;    // points per cloud
const auto g_start = std::chrono::steady_clock::now();

void onCloud(SickScanApiHandle, const SickScanPointCloudMsg* msg) {
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - g_start).count();
  std::lock_guard<std::mutex> lock(g_mutex);
  g_arrivals_s.push_back(t);
  g_widths.push_back(msg->width * msg->height);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s LAUNCHFILE_ARGS SECONDS\n", argv[0]);
    return 2;
  }
  const double seconds = std::atof(argv[2]);
  SickScanApiHandle api = SickScanApiCreate(argc, argv);
  if (!api) {
    std::fprintf(stderr, "SickScanApiCreate failed\n");
    return 1;
  }
  SickScanApiRegisterCartesianPointCloudMsg(api, onCloud);
  const int32_t init = SickScanApiInitByLaunchfile(api, argv[1]);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  SickScanApiDeregisterCartesianPointCloudMsg(api, onCloud);
  std::lock_guard<std::mutex> lock(g_mutex);
  // The rate over the steady part: from the first cloud to the last (the driver's PLL drops the first few).
  double rate_hz = 0;
  if (g_arrivals_s.size() > 1)
    rate_hz = (g_arrivals_s.size() - 1) / (g_arrivals_s.back() - g_arrivals_s.front());
  uint32_t min_w = 0, max_w = 0;
  if (!g_widths.empty()) {
    min_w = max_w = g_widths.front();
    for (uint32_t w : g_widths) min_w = std::min(min_w, w), max_w = std::max(max_w, w);
  }
  std::printf("\nsummary: init %s, clouds %zu, first after %.2f s, rate %.2f Hz, points per cloud %u..%u\n",
              init == SICK_SCAN_API_SUCCESS ? "ok" : "FAILED", g_arrivals_s.size(),
              g_arrivals_s.empty() ? 0.0 : g_arrivals_s.front(), rate_hz, min_w, max_w);
  std::fflush(stdout);
  SickScanApiClose(api);
  SickScanApiRelease(api);
  // The driver's threads do not always end on close; the counts are printed.
  std::_Exit(init == SICK_SCAN_API_SUCCESS && !g_arrivals_s.empty() ? 0 : 1);
}
