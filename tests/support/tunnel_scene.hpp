#pragma once
// A synthetic two-unit wind-tunnel scan with known answers (the study's scale
// model campaign, §5.3.3): a test section (floor, ceiling, two side walls and the
// downstream screen) with a model main and jib and a reference cube turned 45°
// on the floor, scanned by two units that each see mostly their own half of the
// chamber and their own sail — poor overlap, as between real units.
#include <cstdint>

#include "analysis/core/cloud.hpp"
#include "analysis/registration/boat_registration.hpp"
#include "analysis/registration/rigid_transform.hpp"

namespace sailshape {

struct TunnelSceneParams {
  double noise_sigma_m = 0.0;             // range noise along each ray (SPEC §3: 0.004)
  double chamber_density_per_m2 = 350.0;  // points per m² on walls, floor, ceiling
  double cube_density_per_m2 = 3000.0;    // on the cube's faces
  size_t sail_points = 4000;              // on each unit's own sail
  uint64_t seed = 1;
  // Unit A's frame → tunnel frame; the reference cloud is in unit A's frame.
  RigidTransform reference_pose = RigidTransform::Identity();
  // Moving (unit B) frame → reference (unit A) frame: what registration must find.
  // Default: 90° about X and 1 m along each axis, the study's test (§5.3.3).
  RigidTransform truth = [] {
    RigidTransform t = RigidTransform::Identity();
    t.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
    t.translation() = Vec3(1.0, 1.0, 1.0);
    return t;
  }();
};

struct TunnelScene {
  Cloud reference;               // unit A, in its own frame; viewpoint = unit A
  Cloud moving;                  // unit B, in its own frame; viewpoint = unit B
  RigidTransform truth;          // moving → reference
  RigidTransform reference_pose;  // reference (unit A) → tunnel frame
  BoatReference chamber;         // the chamber's and the cube's faces, tunnel frame
};

// Deterministic for a given seed. Throws InvalidInput for a negative noise or a
// density or point count that is not positive.
TunnelScene makeTunnelScene(const TunnelSceneParams& params = {});

}  // namespace sailshape
