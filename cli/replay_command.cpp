// `sailshape replay`: decode an archived scanner session again (ours or a pcapng-JSON recording).
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "acquisition/capture_replay.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/io/cloud_io.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

struct ReplayOptions {
  std::string capture;
  std::string json;
  std::string unit;
  std::string cloud;
  bool quiet = false;
};

void printChannel(const ScanChannel& c) {
  std::printf("  %s: %zu values from %.4f deg step %.4f deg, scale %g offset %g\n", c.name.c_str(), c.values.size(),
              c.start_angle / 10000.0, c.angular_step / 10000.0, c.scale_factor, c.scale_offset);
}

void run(const ReplayOptions& o) {
  ProgressBar bar(!o.quiet);
  const ReplayResult r = replayCapture(o.capture, bar.progress());
  bar.finish();
  std::printf("%s: %s capture, CoLa %s, %zu LMDscandata frames", o.capture.c_str(), r.format.c_str(),
              colaDialectName(r.dialect), r.frames.size());
  if (!r.frames.empty()) {
    const ScanData& first = r.frames.front().scan;
    const ScanData& last = r.frames.back().scan;
    std::printf(" (scan counter %u..%u, serial %u, %.2f Hz)\n", first.scan_counter, last.scan_counter,
                first.serial_number, first.scan_frequency / 100.0);
    for (const ScanChannel& c : first.channels16) printChannel(c);
    for (const ScanChannel& c : first.channels8) printChannel(c);
  } else {
    std::printf("\n");
  }
  const ColaStreamStats& s = r.from_device;
  std::printf("from device: %llu frames, %llu bad checksum, %llu bad length, %llu garbage bytes; %zu undecodable scans\n",
              static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.bad_checksum),
              static_cast<unsigned long long>(s.bad_length), static_cast<unsigned long long>(s.garbage_bytes),
              r.undecodable);
  for (const std::string& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!o.json.empty()) {
    writeJsonFile(o.json, replayJson(r));
    std::fprintf(stderr, "wrote %s\n", o.json.c_str());
  }
  if (!o.cloud.empty()) {
    const UnitConfig unit = readUnitFile(o.unit);
    const ReplayCloud c = replayToCloud(r, unit);
    for (const std::string& w : c.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    writeCloud(o.cloud, c.cloud);
    std::fprintf(stderr, "wrote %s: %zu points from %zu scans (%zu beams) of unit %s\n", o.cloud.c_str(),
                 c.cloud.size(), c.scans_used, c.beams, unit.name.c_str());
  }
}

}  // namespace

void addReplayCommand(CLI::App& app) {
  auto opt = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand(
      "replay",
      "Decode an archived scanner capture again: summary, frames or a recalibrated cloud\n\n"
      "Decode an archived scanner session again: a sailshape capture (.sscap, written during scans) or a "
      "pcapng-JSON recording of SICK CoLa traffic. Prints a summary; --json writes every LMDscandata frame; --unit "
      "with --cloud turns the frames into a cloud with a new calibration.");
  cmd->add_option("capture", opt->capture, "Capture file (.sscap or pcapng-JSON)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--json", opt->json,
                  "Write per LMDscandata frame its counters, time stamps, frequencies, encoders, trailer blocks and "
                  "channels (name, scale, offset, start angle, step in 1/10000 deg, raw values as sent) to this JSON file");
  CLI::Option* unit = cmd->add_option(
      "--unit", opt->unit,
      "Unit file (UNIT.json: p, θ, pose) to turn the frames into a cloud with; β comes from each frame's encoder "
      "block (a scanner capture holds no turntable positions)")->check(CLI::ExistingFile);
  CLI::Option* cloud = cmd->add_option("--cloud", opt->cloud,
                                       "Write the cloud (.ply, .pcd, .xyz, .csv) in the unit's pose frame; needs --unit");
  cloud->needs(unit);
  unit->needs(cloud);
  cmd->add_flag("--quiet", opt->quiet, "No progress bar");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace sailshape::cli
