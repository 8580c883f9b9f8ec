#pragma once
// Decoding a capture again (`sailshape replay`): every LMDscandata frame with its time stamp, plus what else
// the capture holds, and the frames as JSON (counters, frequencies, channels with the raw values as sent).
#include <cstddef>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "acquisition/capture.hpp"
#include "acquisition/scan_data.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

struct ReplayFrame {
  double time_s = 0;  // time stamp of the record that completed the frame (see CaptureRecord::time_s)
  ScanData scan;
};

struct ReplayResult {
  std::string format;  // "sscap" or "pcapng-json"
  ColaDialect dialect = ColaDialect::kBinary;
  std::vector<ReplayFrame> frames;                  // sSN and sRA LMDscandata, in capture order
  std::map<std::string, size_t> other_telegrams;    // "sRN FirmwareVersion" -> count, both directions
  size_t undecodable = 0;                           // LMDscandata frames with a good checksum that did not decode
  ColaStreamStats to_device, from_device;
  // From reading the capture, one line for the damaged frames and bytes skipped (the decoders resume at
  // the next frame start, so every good frame is kept), and from undecodable frames.
  std::vector<std::string> warnings;
};

// Reads and decodes `path` (either capture format). Throws FileError as readCapture does; bad frames are
// counted, not thrown.
ReplayResult replayCapture(const std::string& path, const Progress& progress = {});

struct ReplayCloud {
  Cloud cloud;            // unit's pose applied: boat/scene frame; alpha_rad, beta_rad, intensity (RSSI1) filled
  size_t scans_used = 0;  // frames with DIST1 and an encoder block
  size_t beams = 0;       // beams in those frames, echoes or not
  std::vector<std::string> warnings;
};

// The frames of `replay` as a cloud by SPEC §2 with the unit's p and θ, then its pose. β comes from each
// frame's encoder block (turntable counts, acquisition/turntable_protocol.hpp), advancing linearly over the
// mirror turn towards the next frame's reading; a DIST1 value of 0 (no echo) gives no point. A scanner
// capture holds no turntable positions, so frames without an encoder block are skipped with a warning.
// Throws InvalidInput when no frame has both DIST1 and an encoder block.
ReplayCloud replayToCloud(const ReplayResult& replay, const UnitConfig& unit);

// One frame: every field of ScanData (angles in 1/10000 degree and Hz fields as sent, plus *_hz and *_deg).
nlohmann::json scanDataJson(const ScanData& scan);
// The whole replay: source, statistics, other telegrams and "frames" (each scanDataJson + "time_s").
nlohmann::json replayJson(const ReplayResult& replay);

}  // namespace sailshape
