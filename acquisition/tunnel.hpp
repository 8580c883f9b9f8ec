#pragma once
// The built-in wind tunnel described once: the chamber and the yacht model's hull
// and spars, in the boat frame (SPEC §2: +X forward, +Y port, +Z up, metres; the
// mast foot at deck level is the origin). The emulator ray-casts a scene built
// from it (scene.hpp builtInTunnelScene), and a session in that tunnel registers
// on the same walls and looks for the same spars, as a crew measures them once
// per tunnel and boat.
#include <vector>

#include "analysis/registration/boat_registration.hpp"
#include "analysis/segmentation/spars.hpp"

namespace sailshape {

// A hull as a prism: the deck outline (square stern, pointed bow) at deck_z_m,
// the same outline narrowed at the keel line keel_z_m.
struct TunnelHull {
  double stern_x_m = 0, bow_x_m = 0, half_beam_m = 0;
  double deck_z_m = 0, keel_z_m = 0;
};

struct TunnelDescription {
  double model_scale = 1;  // the yacht model against the full-scale example designs
  // The chamber's inside: floor at min.z, ceiling at max.z, four walls (boat frame, metres).
  Vec3 chamber_min_m = Vec3::Zero(), chamber_max_m = Vec3::Zero();
  TunnelHull hull;
  Spar mast, boom;
  int mast_segments = 16, boom_segments = 12;  // facets around the emulator's spar cylinders
};

// 16 m × 14 m × 3.8 m chamber, its floor 0.6 m below the deck of a 1:3.6 yacht model.
TunnelDescription builtInTunnel();

// The chamber's six faces as a registration reference, normals into the chamber.
BoatReference tunnelWalls(const TunnelDescription& tunnel);

// Mast, then boom.
std::vector<Spar> tunnelSpars(const TunnelDescription& tunnel);

}  // namespace sailshape
