#include "acquisition/tunnel.hpp"

namespace sailshape {

TunnelDescription builtInTunnel() {
  TunnelDescription t;
  t.model_scale = 1.0 / 3.6;
  t.chamber_min_m = Vec3(-8.0, -7.0, -0.6);
  t.chamber_max_m = Vec3(8.0, 7.0, 3.2);
  t.hull = {-1.3, 1.5, 0.42, 0.0, -0.6};
  t.mast = {"mast", Vec3(0.035, 0, 0), Vec3::UnitZ(), 3.05, 0.025};
  t.boom = {"boom", Vec3(0.0, 0, 0.26), -Vec3::UnitX(), 1.05, 0.015};
  return t;
}

BoatReference tunnelWalls(const TunnelDescription& tunnel) {
  const Vec3& lo = tunnel.chamber_min_m;
  const Vec3& hi = tunnel.chamber_max_m;
  BoatReference ref;
  ref.name = "wind tunnel chamber";
  ref.faces = {{"floor", Vec3::UnitZ(), lo.z()},          {"ceiling", -Vec3::UnitZ(), -hi.z()},
               {"starboard wall", Vec3::UnitY(), lo.y()}, {"port wall", -Vec3::UnitY(), -hi.y()},
               {"aft wall", Vec3::UnitX(), lo.x()},       {"forward wall", -Vec3::UnitX(), -hi.x()}};
  return ref;
}

std::vector<Spar> tunnelSpars(const TunnelDescription& tunnel) { return {tunnel.mast, tunnel.boom}; }

}  // namespace sailshape
