// LMDscandata decoding against SICK's real recordings (facts from ../shared/sick-recordings/README.md,
// decoded there independently), round trips in both dialects, and malformed telegrams.
#include "acquisition/scan_data.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <string>
#include <vector>

#include "acquisition/capture.hpp"
#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

const std::string kRecordings = std::string(SAILSHAPE_SHARED) + "/sick-recordings/";

std::vector<std::string> scanPayloads(const std::string& file, CaptureTelegrams* all = nullptr) {
  const Capture capture = readCapture(kRecordings + file);
  CaptureTelegrams t = extractTelegrams(capture);
  std::vector<std::string> out;
  for (const auto& tel : t.telegrams)
    if (tel.direction == CaptureDirection::kFromDevice && isScanDataTelegram(tel.payload)) out.push_back(tel.payload);
  if (all != nullptr) *all = std::move(t);
  return out;
}

uint64_t sum(const std::vector<uint16_t>& v) { return std::accumulate(v.begin(), v.end(), uint64_t{0}); }

struct Recording {
  const char* file;
  size_t min_frames;  // README: LMS111 ~175 frames; the LMS511 files stream for a few seconds at 25 Hz
};

class RecordingConformance : public ::testing::TestWithParam<Recording> {};

TEST_P(RecordingConformance, EveryScanFrameHasAGoodChecksumAndDecodes) {
  CaptureTelegrams all;
  const auto payloads = scanPayloads(GetParam().file, &all);
  EXPECT_GE(payloads.size(), GetParam().min_frames);
  // README: "Every frame's checksum in these files is valid" — nothing dropped, nothing skipped.
  EXPECT_EQ(all.from_device.bad_checksum, 0u);
  EXPECT_EQ(all.from_device.garbage_bytes, 0u);
  EXPECT_EQ(all.from_device.bad_length, 0u);
  EXPECT_EQ(all.to_device.bad_checksum, 0u);
  EXPECT_EQ(all.to_device.garbage_bytes, 0u);
  for (const std::string& p : payloads) {
    const ScanData s = decodeScanData(p, ColaDialect::kBinary);
    ASSERT_FALSE(s.channels16.empty());
    const ScanChannel& dist = s.channels16[0];
    EXPECT_EQ(dist.name, "DIST1");
    // The point count the output range implies: (stop - start) / step + 1.
    EXPECT_GT(dist.values.size(), 500u);
    // Re-encoding reproduces the device's bytes exactly.
    EXPECT_EQ(encodeScanData(s, ColaDialect::kBinary), p);
  }
}

INSTANTIATE_TEST_SUITE_P(SickRecordings, RecordingConformance,
                         ::testing::Values(Recording{"20210302_lms111.pcapng.json", 170},
                                           Recording{"20210302_lms511.pcapng.json", 100},
                                           Recording{"20210301_lms511.pcapng.json", 100}));

TEST(ScanDataConformance, Lms111FirstFrameMatchesReadme) {
  const auto payloads = scanPayloads("20210302_lms111.pcapng.json");
  ASSERT_FALSE(payloads.empty());
  const ScanData s = decodeScanData(payloads.front(), ColaDialect::kBinary);
  EXPECT_EQ(s.command_type, "sSN");
  EXPECT_EQ(s.version, 1);
  EXPECT_EQ(s.serial_number, 18090362u);  // README: serial 18090362
  EXPECT_EQ(s.telegram_counter, 63336);
  EXPECT_EQ(s.scan_counter, 4);
  EXPECT_EQ(s.scan_frequency, 5000u);  // 50 Hz
  EXPECT_TRUE(s.encoders.empty());
  ASSERT_EQ(s.channels16.size(), 1u);
  EXPECT_TRUE(s.channels8.empty());  // DIST1 only
  const ScanChannel& d = s.channels16[0];
  EXPECT_EQ(d.name, "DIST1");
  EXPECT_EQ(d.start_angle, -450000);
  EXPECT_EQ(d.angular_step, 5000);
  ASSERT_EQ(d.values.size(), 541u);
  EXPECT_EQ(std::vector<uint16_t>(d.values.begin(), d.values.begin() + 5), (std::vector<uint16_t>{93, 80, 86, 89, 82}));
  EXPECT_EQ(sum(d.values), 462019u);
  EXPECT_EQ(d.scale_factor, 1.0f);
  EXPECT_EQ(d.scale_offset, 0.0f);
  EXPECT_DOUBLE_EQ(scanRangeMm(d, 0), 93.0);
  EXPECT_DOUBLE_EQ(scanAngleDeg(d, 0), -45.0);
  EXPECT_DOUBLE_EQ(scanAngleDeg(d, 540), 225.0);  // 270° field of view
  EXPECT_FALSE(s.position.has_value());
  EXPECT_FALSE(s.device_name.has_value());
  EXPECT_FALSE(s.comment.has_value());
  // The LMS111 sends its (unset) real-time clock: bytes 07 B2 01 01 02 37 22 000D90A8 read by hand.
  ASSERT_TRUE(s.time.has_value());
  EXPECT_EQ(s.time->year, 1970);
  EXPECT_EQ(s.time->month, 1);
  EXPECT_EQ(s.time->day, 1);
  EXPECT_EQ(s.time->hour, 2);
  EXPECT_EQ(s.time->minute, 55);
  EXPECT_EQ(s.time->second, 34);
  EXPECT_EQ(s.time->microsecond, 889000u);  // 0x000D90A8
  EXPECT_FALSE(s.event_info.has_value());
}

TEST(ScanDataConformance, Lms511FirstFrameMatchesReadme) {
  const auto payloads = scanPayloads("20210302_lms511.pcapng.json");
  ASSERT_FALSE(payloads.empty());
  const ScanData s = decodeScanData(payloads.front(), ColaDialect::kBinary);
  EXPECT_EQ(s.version, 0);
  EXPECT_EQ(s.serial_number, 18110550u);
  EXPECT_EQ(s.telegram_counter, 54098);
  EXPECT_EQ(s.scan_counter, 54484);
  EXPECT_EQ(s.scan_frequency, 2500u);
  ASSERT_EQ(s.channels16.size(), 1u);
  ASSERT_EQ(s.channels8.size(), 1u);
  const ScanChannel& d = s.channels16[0];
  EXPECT_EQ(d.name, "DIST1");
  EXPECT_EQ(d.start_angle, -50000);
  EXPECT_EQ(d.angular_step, 1667);
  ASSERT_EQ(d.values.size(), 1141u);
  EXPECT_EQ(std::vector<uint16_t>(d.values.begin(), d.values.begin() + 5),
            (std::vector<uint16_t>{1305, 1299, 1307, 1299, 1307}));
  EXPECT_EQ(sum(d.values), 1480058u);
  const ScanChannel& r = s.channels8[0];
  EXPECT_EQ(r.name, "RSSI1");
  EXPECT_EQ(r.start_angle, -50000);
  EXPECT_EQ(r.angular_step, 1667);
  ASSERT_EQ(r.values.size(), 1141u);
  EXPECT_EQ(std::vector<uint16_t>(r.values.begin(), r.values.begin() + 5),
            (std::vector<uint16_t>{254, 254, 254, 254, 254}));
  EXPECT_EQ(sum(r.values), 266142u);
  EXPECT_EQ(s.channel("RSSI1"), &s.channels8[0]);
  EXPECT_EQ(s.channel("DIST2"), nullptr);
}

ScanData fullScan() {
  ScanData s;
  s.command_type = "sRA";
  s.version = 1;
  s.device_number = 7;
  s.serial_number = 0xdeadbeef;
  s.device_status = {0, 1};
  s.telegram_counter = 65535;
  s.scan_counter = 12;
  s.time_since_startup_us = 4000000000u;
  s.time_of_transmission_us = 4000001234u;
  s.digital_inputs = {1, 0};
  s.digital_outputs = {0x38, 0};
  s.layer_angle = 0;
  s.scan_frequency = 2500;
  s.measurement_frequency = 360;
  s.encoders = {{123456789u, 42}};
  ScanChannel dist{"DIST1", 2.0f, 0.5f, -50000, 1667, {0, 1, 65535, 1305}};
  ScanChannel dist2{"DIST2", 1.0f, 0.0f, -50000, 1667, {7, 8, 9, 10}};
  ScanChannel rssi{"RSSI1", 1.0f, 0.0f, -50000, 1667, {0, 128, 255, 254}};
  s.channels16 = {dist, dist2};
  s.channels8 = {rssi};
  s.position = ScanPosition{1.5f, -2.25f, 3.0f, 0.0f, 0.125f, -3.5f, 1, 1};
  s.device_name = "LMS511 port";  // a space inside: the length, not the token, delimits it
  s.comment = "";
  s.time = ScanTime{2026, 11, 22, 3, 4, 5, 678901};
  s.event_info = ScanEventInfo{"FDIN", 99, 4000000100u, -12345};
  return s;
}

void expectEqual(const ScanData& a, const ScanData& b) {
  EXPECT_EQ(a.command_type, b.command_type);
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.device_number, b.device_number);
  EXPECT_EQ(a.serial_number, b.serial_number);
  EXPECT_EQ(a.device_status, b.device_status);
  EXPECT_EQ(a.telegram_counter, b.telegram_counter);
  EXPECT_EQ(a.scan_counter, b.scan_counter);
  EXPECT_EQ(a.time_since_startup_us, b.time_since_startup_us);
  EXPECT_EQ(a.time_of_transmission_us, b.time_of_transmission_us);
  EXPECT_EQ(a.digital_inputs, b.digital_inputs);
  EXPECT_EQ(a.digital_outputs, b.digital_outputs);
  EXPECT_EQ(a.layer_angle, b.layer_angle);
  EXPECT_EQ(a.scan_frequency, b.scan_frequency);
  EXPECT_EQ(a.measurement_frequency, b.measurement_frequency);
  ASSERT_EQ(a.encoders.size(), b.encoders.size());
  for (size_t i = 0; i < a.encoders.size(); ++i) {
    EXPECT_EQ(a.encoders[i].position, b.encoders[i].position);
    EXPECT_EQ(a.encoders[i].speed, b.encoders[i].speed);
  }
  auto channels = [](const std::vector<ScanChannel>& x, const std::vector<ScanChannel>& y) {
    ASSERT_EQ(x.size(), y.size());
    for (size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x[i].name, y[i].name);
      EXPECT_EQ(x[i].scale_factor, y[i].scale_factor);
      EXPECT_EQ(x[i].scale_offset, y[i].scale_offset);
      EXPECT_EQ(x[i].start_angle, y[i].start_angle);
      EXPECT_EQ(x[i].angular_step, y[i].angular_step);
      EXPECT_EQ(x[i].values, y[i].values);
    }
  };
  channels(a.channels16, b.channels16);
  channels(a.channels8, b.channels8);
  ASSERT_EQ(a.position.has_value(), b.position.has_value());
  if (a.position) {
    EXPECT_EQ(a.position->x, b.position->x);
    EXPECT_EQ(a.position->y, b.position->y);
    EXPECT_EQ(a.position->z, b.position->z);
    EXPECT_EQ(a.position->rot_x, b.position->rot_x);
    EXPECT_EQ(a.position->rot_y, b.position->rot_y);
    EXPECT_EQ(a.position->rot_z, b.position->rot_z);
    EXPECT_EQ(a.position->rotation_type, b.position->rotation_type);
    EXPECT_EQ(a.position->transmit_device_name, b.position->transmit_device_name);
  }
  EXPECT_EQ(a.device_name, b.device_name);
  EXPECT_EQ(a.comment, b.comment);
  ASSERT_EQ(a.time.has_value(), b.time.has_value());
  if (a.time) {
    EXPECT_EQ(a.time->year, b.time->year);
    EXPECT_EQ(a.time->month, b.time->month);
    EXPECT_EQ(a.time->day, b.time->day);
    EXPECT_EQ(a.time->hour, b.time->hour);
    EXPECT_EQ(a.time->minute, b.time->minute);
    EXPECT_EQ(a.time->second, b.time->second);
    EXPECT_EQ(a.time->microsecond, b.time->microsecond);
  }
  ASSERT_EQ(a.event_info.has_value(), b.event_info.has_value());
  if (a.event_info) {
    EXPECT_EQ(a.event_info->type, b.event_info->type);
    EXPECT_EQ(a.event_info->encoder_position, b.event_info->encoder_position);
    EXPECT_EQ(a.event_info->time_us, b.event_info->time_us);
    EXPECT_EQ(a.event_info->angle, b.event_info->angle);
  }
}

TEST(ScanDataRoundTrip, EveryBlockInBothDialects) {
  const ScanData s = fullScan();
  for (ColaDialect d : {ColaDialect::kBinary, ColaDialect::kAscii}) {
    const std::string payload = encodeScanData(s, d);
    const ScanData back = decodeScanData(payload, d);
    expectEqual(s, back);
    EXPECT_EQ(encodeScanData(back, d), payload);
    // Framed and run through the stream decoder, the payload comes back whole.
    ColaStreamDecoder dec({d});
    dec.feed(frameCola(d, payload));
    auto p = dec.next();
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(*p, payload);
  }
}

TEST(ScanDataRoundTrip, RecordedFramesThroughAscii) {
  const auto payloads = scanPayloads("20210302_lms511.pcapng.json");
  ASSERT_GE(payloads.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const ScanData s = decodeScanData(payloads[i], ColaDialect::kBinary);
    expectEqual(s, decodeScanData(encodeScanData(s, ColaDialect::kAscii), ColaDialect::kAscii));
  }
}

TEST(ScanDataAscii, HandWrittenTelegramKnownAnswer) {
  // The LMS111 recording's first frame written out in CoLa A by hand (three values only).
  const std::string payload =
      "sSN LMDscandata 1 1 114097A 1 0 F768 4 74287D59 74288993 0 0 1 0 0 1388 168 0 1 "
      "DIST1 3F800000 00000000 FFF92230 1388 3 5D 50 56 0 0 0 0 0 0";
  const ScanData s = decodeScanData(payload, ColaDialect::kAscii);
  EXPECT_EQ(s.serial_number, 18090362u);
  EXPECT_EQ(s.telegram_counter, 63336);
  EXPECT_EQ(s.scan_counter, 4);
  EXPECT_EQ(s.scan_frequency, 5000u);
  EXPECT_EQ(s.measurement_frequency, 360u);
  ASSERT_EQ(s.channels16.size(), 1u);
  EXPECT_EQ(s.channels16[0].start_angle, -450000);
  EXPECT_EQ(s.channels16[0].values, (std::vector<uint16_t>{93, 80, 86}));
  EXPECT_EQ(encodeScanData(s, ColaDialect::kAscii), payload);
}

TEST(ScanDataErrors, MalformedTelegramsNameTheProblem) {
  const std::string good = encodeScanData(fullScan(), ColaDialect::kBinary);
  EXPECT_THROW(decodeScanData("sRN LMDscandata", ColaDialect::kBinary), ColaError);
  EXPECT_THROW(decodeScanData("sSN LIDoutputstate 1", ColaDialect::kBinary), ColaError);
  // Every truncation fails with an error, never a crash or a partial scan.
  for (size_t cut = 16; cut < good.size(); cut += 7)
    EXPECT_THROW(decodeScanData(good.substr(0, cut), ColaDialect::kBinary), ColaError) << "cut at " << cut;
  EXPECT_THROW(decodeScanData(good + "x", ColaDialect::kBinary), ColaError);  // trailing bytes
  try {
    decodeScanData(good.substr(0, 30), ColaDialect::kBinary);
    FAIL() << "no exception";
  } catch (const ColaError& e) {
    EXPECT_NE(std::string(e.what()).find("[LMDscandata]"), std::string::npos) << e.what();
  }
  // A presence flag other than 0/1.
  ScanData bare;
  std::string flags = encodeScanData(bare, ColaDialect::kBinary);
  flags[flags.size() - 1] = 2;  // event info flag
  EXPECT_THROW(decodeScanData(flags, ColaDialect::kBinary), ColaError);

  ScanData bad = fullScan();
  bad.channels16[0].name = "DIST";
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kBinary), ColaError);
  bad.channels16[0].name = "DI T1";  // any 5 bytes in CoLa B, but a CoLa A token cannot hold a space
  EXPECT_NO_THROW(encodeScanData(bad, ColaDialect::kBinary));
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kAscii), ColaError);
  bad = fullScan();
  bad.channels8[0].values[0] = 256;
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kAscii), ColaError);
  bad = fullScan();
  bad.event_info->type = "FD";
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kBinary), ColaError);
  bad = fullScan();
  bad.command_type = "sSA";
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kBinary), ColaError);
  bad = fullScan();
  bad.channels16[0].values.resize(70000);
  EXPECT_THROW(encodeScanData(bad, ColaDialect::kBinary), ColaError);
  EXPECT_THROW(scanRangeMm(fullScan().channels16[0], 4), InvalidInput);
  EXPECT_THROW(scanAngleDeg(fullScan().channels16[0], 4), InvalidInput);
  EXPECT_DOUBLE_EQ(scanRangeMm(fullScan().channels16[0], 3), 1305 * 2.0 + 0.5);
}

}  // namespace
}  // namespace sailshape
