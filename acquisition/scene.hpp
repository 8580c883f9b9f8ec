#pragma once
// Emulated scenes the scanner emulator ray-casts into (issue 4): a wind-tunnel
// chamber (floor, walls, ceiling) or a boat deck with a reference cube, mast,
// boom and hull, plus sails made by the parametric generator with flying-shape
// parameters. Everything is a triangle mesh in the scene frame (the boat frame
// of SPEC §2: +X forward, +Y port, +Z up, metres) tagged with a material that
// the sensor model (SPEC §3) turns into noise, bias and RSSI.
#include <string>
#include <vector>

#include "analysis/core/mesh.hpp"
#include "analysis/design/sail_generator.hpp"

namespace sailshape {

// Surface classes the study qualified (SPEC §3): sail cloth, reflective tape,
// light and dark grey targets; the rest (walls, painted metal) sits in between.
enum class Material { Cloth, Tape, LightGrey, DarkGrey, Paint, Metal };

std::string materialName(Material material);
// "cloth", "tape", "light_grey", "dark_grey", "paint", "metal"; throws InvalidInput otherwise.
Material parseMaterial(const std::string& name);

struct SceneObject {
  std::string name;  // "floor", "mast", "main", ...
  Material material = Material::Paint;
  Mesh mesh;         // metres, scene frame
};

struct Scene {
  std::string name;
  std::vector<SceneObject> objects;
  size_t triangleCount() const;
};

// Primitive builders (closed, outward-facing triangles).
Mesh makeBox(const Vec3& min_corner, const Vec3& max_corner);
// A quad a → b → c → d (planar, convex) as two triangles.
Mesh makeQuad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
// Capped cylinder from `base` along `axis` (need not be unit) over `length_m`; `segments` ≥ 3 around.
Mesh makeCylinder(const Vec3& base, const Vec3& axis, double radius_m, double length_m, int segments = 32);

// Inside faces of an axis-aligned chamber: floor at min.z, ceiling at max.z, four walls.
std::vector<SceneObject> makeChamber(const Vec3& min_corner, const Vec3& max_corner);

// The built-in wind-tunnel scene, from builtInTunnel() (tunnel.hpp): the chamber, the
// 1:3.6 yacht model's hull, mast and boom, its mainsail and an A2 gennaker.
Scene builtInTunnelScene();
// A full-scale boat deck with a 0.5 m reference cube, mast, boom, hull and a mainsail.
Scene builtInDeckScene();

// SCENE.json (format in acquisition/README.md): {"name": ..., "preset": "tunnel"|"deck"|"empty",
// "objects": [{"type": "box"|"quad"|"cylinder"|"chamber"|"sail"|"mesh", ...}]}.
// Throws FileError naming the file for unreadable/malformed JSON and
// InvalidInput naming the object and field for bad values.
Scene readSceneFile(const std::string& path);
Scene parseSceneJson(const std::string& text, const std::string& origin = "scene");

}  // namespace sailshape
