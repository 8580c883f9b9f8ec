#include "acquisition/unit_config.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

namespace {
using nlohmann::json;

double num(const json& j, const char* key, double fallback, const std::string& at) {
  if (!j.contains(key)) return fallback;
  if (!j.at(key).is_number()) throw InvalidInput(at + ": '" + key + "' must be a number (got " + j.at(key).dump() + ")");
  return j.at(key).get<double>();
}
std::string str(const json& j, const char* key, const std::string& fallback, const std::string& at) {
  if (!j.contains(key)) return fallback;
  if (!j.at(key).is_string()) throw InvalidInput(at + ": '" + key + "' must be a string (got " + j.at(key).dump() + ")");
  return j.at(key).get<std::string>();
}
Vec3 triple(const json& j, const char* key, const std::string& at) {
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw InvalidInput(at + ": '" + key + "' must be three numbers (got " + v.dump() + ")");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}
}  // namespace

Eigen::Isometry3d makePose(const Vec3& position, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
                Eigen::AngleAxisd(roll, Vec3::UnitX()))
                   .toRotationMatrix();
  T.translation() = position;
  return T;
}

Vec3 unitPoint(double r, double alpha, double beta, double p, double theta) {
  return {r * std::cos(alpha), r * std::sin(alpha) * std::cos(beta) + p * std::cos(beta + theta),
          r * std::sin(alpha) * std::sin(beta) + p * std::sin(beta + theta)};
}

void validateUnit(const UnitConfig& u) {
  const auto bad = [&](const std::string& what) { throw InvalidInput("[validateUnit] " + u.name + ": " + what); };
  if (u.host.empty()) bad("host is empty");
  if (u.port == 0) bad("port must be 1..65535");
  if (u.protocol != "cola-b" && u.protocol != "cola-a") bad("protocol must be cola-b or cola-a (got " + u.protocol + ")");
  if (u.serial_device.empty()) bad("serial_device is empty");
  if (!(u.p_m >= 0 && u.p_m < 1.0)) bad("p_m must be in [0, 1) m (got " + std::to_string(u.p_m) + ")");
  if (!std::isfinite(u.theta_rad)) bad("theta is not finite");
  if (!(u.speed_deg_s > 0)) bad("speed_deg_s must be > 0 (got " + std::to_string(u.speed_deg_s) + ")");
  if (!(u.acceleration_deg_s2 > 0)) bad("acceleration_deg_s2 must be > 0 (got " + std::to_string(u.acceleration_deg_s2) + ")");
  if (!(std::abs(u.sweep_angle_deg) > 0 && std::abs(u.start_angle_deg) + std::abs(u.sweep_angle_deg) <= 720))
    bad("sweep_angle_deg must be non-zero and start + sweep within ±720° (got " + std::to_string(u.start_angle_deg) +
        " + " + std::to_string(u.sweep_angle_deg) + ")");
  if (!(u.frequency_hz >= 25 && u.frequency_hz <= 100))
    bad("frequency_hz must be in [25, 100] (got " + std::to_string(u.frequency_hz) + ")");
  if (!(u.resolution_deg >= 0.1666 && u.resolution_deg <= 1.0))
    bad("resolution_deg must be in [0.1667, 1] (got " + std::to_string(u.resolution_deg) + ")");
  const ScannerSpec spec = scannerSpec(u.model);
  if (!(u.output_start_deg >= spec.first_angle_deg - 1e-9 && u.output_stop_deg <= spec.last_angle_deg + 1e-9 &&
        u.output_start_deg < u.output_stop_deg))
    bad("output range [" + std::to_string(u.output_start_deg) + ", " + std::to_string(u.output_stop_deg) +
        "]° must lie within the " + scannerModelName(u.model) + " field of view [" +
        std::to_string(spec.first_angle_deg) + ", " + std::to_string(spec.last_angle_deg) + "]°");
}

UnitConfig parseUnitJson(const std::string& text, const std::string& origin) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw FileError("[readUnit] " + origin + ": not valid JSON (" + e.what() + ")");
  }
  const std::string at = "[readUnit] " + origin;
  if (!j.is_object()) throw FileError(at + ": the top level must be an object");
  static const std::set<std::string> keys{
      "name", "host", "port", "protocol", "model", "serial_device", "baud", "p_m", "theta_deg", "pose",
      "start_angle_deg", "sweep_angle_deg", "speed_deg_s", "acceleration_deg_s2", "frequency_hz", "resolution_deg",
      "output_start_deg", "output_stop_deg", "beta_source", "rssi"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!keys.count(it.key())) throw InvalidInput(at + ": unknown key '" + it.key() + "'");
  UnitConfig u;
  u.name = str(j, "name", u.name, at);
  u.host = str(j, "host", u.host, at);
  const double port = num(j, "port", u.port, at);
  if (!(port >= 1 && port <= 65535 && port == std::floor(port)))
    throw InvalidInput(at + ": 'port' must be an integer in 1..65535 (got " + std::to_string(port) + ")");
  u.port = static_cast<uint16_t>(port);
  u.protocol = str(j, "protocol", u.protocol, at);
  u.model = parseScannerModel(str(j, "model", scannerModelName(u.model), at));
  const ScannerSpec spec = scannerSpec(u.model);
  u.output_start_deg = spec.first_angle_deg;
  u.output_stop_deg = spec.last_angle_deg;
  u.frequency_hz = spec.default_frequency_hz;
  u.resolution_deg = spec.default_resolution_deg;
  u.serial_device = str(j, "serial_device", u.serial_device, at);
  u.baud = static_cast<int>(num(j, "baud", u.baud, at));
  u.p_m = num(j, "p_m", u.p_m, at);
  u.theta_rad = num(j, "theta_deg", 0.0, at) * kRadPerDeg;
  if (j.contains("pose")) {
    const json& p = j.at("pose");
    if (!p.is_object()) throw InvalidInput(at + ": 'pose' must be {\"position_m\": [..], \"rpy_deg\": [..]}");
    for (auto it = p.begin(); it != p.end(); ++it)
      if (it.key() != "position_m" && it.key() != "rpy_deg") throw InvalidInput(at + ": unknown pose key '" + it.key() + "'");
    const Vec3 pos = p.contains("position_m") ? triple(p, "position_m", at) : Vec3::Zero();
    const Vec3 rpy = p.contains("rpy_deg") ? triple(p, "rpy_deg", at) : Vec3::Zero();
    u.pose = makePose(pos, rpy.x() * kRadPerDeg, rpy.y() * kRadPerDeg, rpy.z() * kRadPerDeg);
  }
  u.start_angle_deg = num(j, "start_angle_deg", u.start_angle_deg, at);
  u.sweep_angle_deg = num(j, "sweep_angle_deg", u.sweep_angle_deg, at);
  u.speed_deg_s = num(j, "speed_deg_s", u.speed_deg_s, at);
  u.acceleration_deg_s2 = num(j, "acceleration_deg_s2", u.acceleration_deg_s2, at);
  u.frequency_hz = num(j, "frequency_hz", u.frequency_hz, at);
  u.resolution_deg = num(j, "resolution_deg", u.resolution_deg, at);
  u.output_start_deg = num(j, "output_start_deg", u.output_start_deg, at);
  u.output_stop_deg = num(j, "output_stop_deg", u.output_stop_deg, at);
  const std::string beta = str(j, "beta_source", "encoder", at);
  if (beta == "encoder") u.beta_source = BetaSource::Encoder;
  else if (beta == "timestamp") u.beta_source = BetaSource::Timestamp;
  else throw InvalidInput(at + ": 'beta_source' must be encoder or timestamp (got " + beta + ")");
  if (j.contains("rssi")) {
    if (!j.at("rssi").is_boolean()) throw InvalidInput(at + ": 'rssi' must be true or false");
    u.rssi = j.at("rssi").get<bool>();
  }
  validateUnit(u);
  return u;
}

UnitConfig readUnitFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError("[readUnit] cannot open " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return parseUnitJson(ss.str(), path);
}

std::string unitToJson(const UnitConfig& u) {
  const Eigen::Matrix3d R = u.pose.linear();
  // Inverse of R = Rz(yaw)·Ry(pitch)·Rx(roll).
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  const Vec3 t = u.pose.translation();
  json j{{"name", u.name},
         {"host", u.host},
         {"port", u.port},
         {"protocol", u.protocol},
         {"model", scannerModelName(u.model)},
         {"serial_device", u.serial_device},
         {"baud", u.baud},
         {"p_m", u.p_m},
         {"theta_deg", u.theta_rad / kRadPerDeg},
         {"pose", {{"position_m", {t.x(), t.y(), t.z()}}, {"rpy_deg", {roll / kRadPerDeg, pitch / kRadPerDeg, yaw / kRadPerDeg}}}},
         {"start_angle_deg", u.start_angle_deg},
         {"sweep_angle_deg", u.sweep_angle_deg},
         {"speed_deg_s", u.speed_deg_s},
         {"acceleration_deg_s2", u.acceleration_deg_s2},
         {"frequency_hz", u.frequency_hz},
         {"resolution_deg", u.resolution_deg},
         {"output_start_deg", u.output_start_deg},
         {"output_stop_deg", u.output_stop_deg},
         {"beta_source", u.beta_source == BetaSource::Encoder ? "encoder" : "timestamp"},
         {"rssi", u.rssi}};
  return j.dump(2) + "\n";
}

}  // namespace sailshape
