#pragma once
// The camera preset "from a scanner unit": the eye at the unit's scanner, looking
// along the centre of its sweep, as the unit itself sees the sail.
#include <optional>

#include "acquisition/unit_config.hpp"
#include "database/scan_record.hpp"

namespace sailshape::viewer {

struct CameraPlacement {
  Vec3 position = Vec3::Zero();     // boat frame, metres
  Vec3 focal_point = Vec3::Zero();  // `distance_m` along the view direction
  Vec3 view_up = Vec3::UnitZ();     // unit length, perpendicular to the view direction
};

// The scanner origin at the sweep's middle turntable angle (start + sweep/2) and
// the beam at the middle of the output range, both by SPEC §2 with the unit's p,
// θ and pose (from its unit file, or a registration written into `unit.pose`).
// View up is the boat's +Z made perpendicular (the shaft's direction when the
// beam looks straight up or down). Throws InvalidInput for distance_m <= 0.
CameraPlacement unitCamera(const UnitConfig& unit, double distance_m = 8.0);

// The unit that took a stored scan: its unit file's keys kept in the scan's settings
// (as `sailshape demo` and `scan` store them; other keys there are ignored), the pose
// replaced by the scan's registration when it has one (the registration maps the
// unit's frame into the boat frame). nullopt when the settings hold no unit.
std::optional<UnitConfig> scanUnit(const ScanRecord& record);

}  // namespace sailshape::viewer
