#pragma once
// Two scanner units swept by the emulator (acquisition/sensor_model) inside a
// box room or over an open deck, with an optional reference cube: the scenes a
// symmetric room can fool registration on (issue 35). Each unit's cloud is in
// its own frame, with its viewpoint (the unit origin) and its scan angles, as a
// real sweep delivers it; `truth` is what registration must find.
#include <cstdint>
#include <optional>
#include <string>

#include "acquisition/scene.hpp"
#include "acquisition/sensor_model.hpp"
#include "analysis/core/cloud.hpp"
#include "analysis/registration/rigid_transform.hpp"

namespace sailshape {

struct RoomSceneParams {
  // The room's inside, scene frame (m). deck = true drops the walls and the
  // ceiling: a floor 2 × the room's size with the cube on it.
  Vec3 room_min = Vec3(-3.0, -1.8, 0.0), room_max = Vec3(3.0, 1.8, 2.4);
  bool deck = false;
  std::optional<Vec3> mast_foot;  // a 0.1 m diameter mast standing 3 m tall here (decks)
  std::optional<Vec3> cube_centre = Vec3(1.2, 0.5, 0.3);  // none: an empty room
  double cube_size_m = 0.6;
  double cube_yaw_deg = 0;
  // Unit frames → scene frame. A unit sweeps its scanner plane (mirror angle α
  // about its +X axis) by β about its +X axis (SPEC §2 with p = 0).
  RigidTransform reference_pose = RigidTransform::Identity();
  RigidTransform moving_pose = RigidTransform::Identity();
  ScannerModel model = ScannerModel::Lms111;
  double noise_scale = 1.0;  // multiplies the materials' σ (SPEC §3: ≈ 4 mm)
  double reference_systematic_fraction = 0.0, moving_systematic_fraction = 0.0;  // range bias / range
  double alpha_step_deg = 0.5, beta_step_deg = 0.5;
  // Mirror angles kept (within the model's field of view): a window narrower
  // than the field of view makes a unit see one side of the room.
  double alpha_first_deg = -135, alpha_last_deg = 135;
  double beta_span_deg = 180;  // β from −span/2 to +span/2
  // Each unit keeps only the returns within this distance of its origin
  // (partial overlap: two units that see different ends of the room).
  double max_range_m = 20.0;
  uint64_t seed = 1;
};

struct RoomScene {
  Scene scene;
  Cloud reference, moving;  // each in its unit's frame; viewpoint = origin, α/β filled
  RigidTransform truth;     // moving → reference = reference_pose⁻¹ · moving_pose
};

// Throws InvalidInput (from the emulator or here) for a room whose min corner
// is not below its max corner or steps that are not > 0.
RoomScene makeRoomScene(const RoomSceneParams& params);

// One unit's sweep of `scene` from `pose` (unit → scene), in the unit's frame.
Cloud sweepUnit(const EmulatedSensor& sensor, const RigidTransform& pose, const RoomSceneParams& params,
                uint64_t seed);

}  // namespace sailshape

namespace sailshape {
// One random case of the registration suite (issue 35): a room (sometimes with
// a square cross-section) or a deck with a mast, a cube on the floor (most of the
// time), two units anywhere inside at any orientation, windows and ranges that
// leave partial overlap, noise 0–1.6 × SPEC §3's σ and a systematic range error
// of up to 0.3 % per unit (in a third of the cases). `label` says which.
// Cases where both units see the same two faces of the cube (≥ 200 returns, the plane detector's least region
// each) are `decidable`: the cube breaks the room's symmetry for both. The
// others (no cube, or one unit misses it) may be right to refuse.
struct RandomCase {
  RoomSceneParams params;
  RoomScene scene;
  std::string label;
  bool decidable = false;
};
RandomCase randomRegistrationCase(uint64_t seed);

// Which faces of the cube (bit 2·axis + side, cube frame) a unit's cloud (its
// own frame, unit → scene pose) holds at least `min_points` returns on (within 1 cm).
unsigned cubeFacesSeen(const Cloud& cloud, const RigidTransform& pose, const RoomSceneParams& params, size_t min_points);

// How far a right pose may stand from the truth. The figures: 0.01° and
// 0.1 mm noise-free, 0.05° and 2 mm at σ = 4 mm, growing with σ in between and
// beyond; a systematic range error s scales one unit's cloud by (1 + s), which
// moves its points by up to s·range (the room's diagonal) and turns the best fit
// by up to about s rad.
struct RegistrationTolerance {
  double rotation_deg, translation_m;
};
RegistrationTolerance registrationTolerance(const RoomSceneParams& params);
}  // namespace sailshape
