#pragma once
// A scanner unit: where its scanner and turntable are reached, its geometric
// constants p and θ (SPEC §2), its pose in the boat/scene frame, and the sweep
// it runs. Read from and written to UNIT.json (keys in acquisition/README.md).
#include <cstdint>
#include <string>

#include "acquisition/sensor_model.hpp"
#include "analysis/core/cloud.hpp"

namespace sailshape {

enum class BetaSource { Encoder, Timestamp };  // β from LMDscandata's encoder block, or turntable samples

struct UnitConfig {
  std::string name = "unit";
  std::string host = "127.0.0.1";
  uint16_t port = 2112;
  std::string protocol = "cola-b";  // "cola-b" (binary) or "cola-a" (ASCII)
  ScannerModel model = ScannerModel::Lms511;
  std::string serial_device = "/dev/ttyUSB0";
  int baud = 115200;
  double p_m = 0.0;                 // scanner origin's offset from the shaft (SPEC §2)
  double theta_rad = 0.0;           // its angle
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // unit frame → boat/scene frame
  double start_angle_deg = 0;       // turntable β where the sweep starts
  double sweep_angle_deg = 180;     // β travel during the sweep (signed)
  double speed_deg_s = 10;
  double acceleration_deg_s2 = 40;
  double frequency_hz = 25;         // scan frequency
  double resolution_deg = 1.0 / 6.0;
  double output_start_deg = -5;     // scanner output range (device angles α)
  double output_stop_deg = 185;
  BetaSource beta_source = BetaSource::Encoder;
  bool rssi = true;
};

// Throws InvalidInput naming the field (speed ≤ 0, output range outside the model's field of view, ...).
void validateUnit(const UnitConfig& unit);
// Reads UNIT.json; missing keys keep the defaults above (output range defaults to the model's field of view).
// Throws FileError for unreadable/malformed files, InvalidInput naming the key for bad values or unknown keys.
UnitConfig readUnitFile(const std::string& path);
UnitConfig parseUnitJson(const std::string& text, const std::string& origin = "unit");
std::string unitToJson(const UnitConfig& unit);

// Pose from position (metres) and roll, pitch, yaw (radians; R = Rz(yaw)·Ry(pitch)·Rx(roll)).
Eigen::Isometry3d makePose(const Vec3& position_m, double roll_rad, double pitch_rad, double yaw_rad);

// SPEC §2 in the unit frame: X = r cos α, Y = r sin α cos β + p cos(β + θ), Z = r sin α sin β + p sin(β + θ).
Vec3 unitPoint(double r_m, double alpha_rad, double beta_rad, double p_m, double theta_rad);

}  // namespace sailshape
