#include "viewer/unit_camera.hpp"

#include <cmath>

#include "acquisition/sweep.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape::viewer {

CameraPlacement unitCamera(const UnitConfig& unit, double distance_m) {
  if (!(distance_m > 0)) throw InvalidInput("[unitCamera] distance_m must be > 0 (got " + std::to_string(distance_m) + ")");
  const double k = kRadPerDeg;
  const double beta = k * (unit.start_angle_deg + unit.sweep_angle_deg / 2);
  const double alpha = k * (unit.output_start_deg + unit.output_stop_deg) / 2;
  CameraPlacement c;
  c.position = sweepPointPosition(unit, 0.0, alpha, beta);
  c.focal_point = sweepPointPosition(unit, distance_m, alpha, beta);
  const Vec3 view = (c.focal_point - c.position).normalized();
  Vec3 up = Vec3::UnitZ() - Vec3::UnitZ().dot(view) * view;
  if (up.norm() < 1e-6) {  // looking straight up or down: the shaft's direction across the view
    const Vec3 shaft = unit.pose.linear() * Vec3::UnitX();
    up = shaft - shaft.dot(view) * view;
    if (up.norm() < 1e-6) up = view.unitOrthogonal();
  }
  c.view_up = up.normalized();
  return c;
}

std::optional<UnitConfig> scanUnit(const ScanRecord& record) {
  const nlohmann::json& settings = record.settings;
  if (!settings.is_object() || !settings.contains("pose") || !settings.contains("output_start_deg")) return std::nullopt;
  // The unit file's own keys, as unitToJson writes them; the scan's other settings (sweep, forces) are not the unit's.
  const nlohmann::json keys = nlohmann::json::parse(unitToJson(UnitConfig{}));
  nlohmann::json unit = nlohmann::json::object();
  for (const auto& item : settings.items())
    if (keys.contains(item.key())) unit[item.key()] = item.value();
  UnitConfig u;
  try {
    u = parseUnitJson(unit.dump(), "scan " + std::to_string(record.scan_id) + " settings");
  } catch (const std::exception&) {
    return std::nullopt;  // settings that do not make a valid unit: no camera from them
  }
  if (record.registration) u.pose = Eigen::Isometry3d(*record.registration);
  return u;
}

}  // namespace sailshape::viewer
