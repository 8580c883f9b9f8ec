#include "acquisition/scene.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "acquisition/tunnel.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/io/mesh_io.hpp"

namespace sailshape {

namespace {

using nlohmann::json;

// A hull as a prism (TunnelHull): the deck outline (square stern, pointed bow) at deck_z,
// the same outline narrowed at the keel line keel_z.
Mesh makeHull(double stern_x, double bow_x, double half_beam, double deck_z, double keel_z) {
  const double shoulder = stern_x + 0.6 * (bow_x - stern_x);
  const std::vector<std::pair<double, double>> outline{
      {stern_x, -half_beam}, {shoulder, -half_beam}, {bow_x, 0.0}, {shoulder, half_beam}, {stern_x, half_beam}};
  Mesh m;
  const size_t n = outline.size();
  for (const auto& [x, y] : outline) m.vertices.emplace_back(x, y, deck_z);
  for (const auto& [x, y] : outline) m.vertices.emplace_back(x, 0.4 * y, keel_z);
  const auto u = [](size_t i) { return static_cast<uint32_t>(i); };
  for (size_t i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({0, u(i), u(i + 1)});              // deck, facing up
    m.triangles.push_back({u(n), u(n + i + 1), u(n + i)});   // bottom, facing down
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    m.triangles.push_back({u(i), u(n + i), u(n + j)});
    m.triangles.push_back({u(i), u(n + j), u(j)});
  }
  return m;
}

SceneObject sparObject(const Spar& spar, int segments) {
  return {spar.name, Material::Metal, makeCylinder(spar.base, spar.axis, spar.radius_m, spar.length_m, segments)};
}

SceneObject sailObject(const std::string& name, const SailDesign& design, int rows = 80, int columns = 40) {
  return {name, Material::Cloth, generateSailMesh(design, rows, columns)};
}

// --- SCENE.json ---------------------------------------------------------------

std::string where(const std::string& origin, size_t index, const std::string& name) {
  return "[readScene] " + origin + ": object " + std::to_string(index) + (name.empty() ? "" : " (" + name + ")");
}

void checkKeys(const json& j, const std::set<std::string>& allowed, const std::string& at) {
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!allowed.count(it.key())) throw InvalidInput(at + ": unknown key '" + it.key() + "'");
}

Vec3 vec3(const json& j, const char* key, const std::string& at) {
  if (!j.contains(key)) throw InvalidInput(at + ": missing '" + key + "'");
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw InvalidInput(at + ": '" + key + "' must be [x, y, z] in metres (got " + v.dump() + ")");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

double number(const json& j, const char* key, const std::string& at) {
  if (!j.contains(key)) throw InvalidInput(at + ": missing '" + key + "'");
  if (!j.at(key).is_number()) throw InvalidInput(at + ": '" + key + "' must be a number (got " + j.at(key).dump() + ")");
  return j.at(key).get<double>();
}

double numberOr(const json& j, const char* key, double fallback, const std::string& at) {
  return j.contains(key) ? number(j, key, at) : fallback;
}

SailDesign sailFromJson(const json& j, const std::string& at) {
  if (!j.contains("sail_type") || !j.at("sail_type").is_string())
    throw InvalidInput(at + ": missing 'sail_type' (main, square-top, jib, gennaker)");
  SailDesign d = exampleDesign(parseSailType(j.at("sail_type").get<std::string>()));
  d = scaleDesign(d, numberOr(j, "scale", 1.0, at));
  d.luff_m = numberOr(j, "luff_m", d.luff_m, at);
  d.leech_m = numberOr(j, "leech_m", d.leech_m, at);
  d.foot_m = numberOr(j, "foot_m", d.foot_m, at);
  d.head_width_m = numberOr(j, "head_width_m", d.head_width_m, at);
  if (j.contains("tack")) d.tack = vec3(j, "tack", at);
  d.rake_deg = numberOr(j, "rake_deg", d.rake_deg, at);
  d.luff_round_m = numberOr(j, "luff_round_m", d.luff_round_m, at);
  d.luff_sag_m = numberOr(j, "luff_sag_m", d.luff_sag_m, at);
  d.leech_round_m = numberOr(j, "leech_round_m", d.leech_round_m, at);
  d.lean_deg = numberOr(j, "lean_deg", d.lean_deg, at);
  if (j.contains("leeward_port")) {
    if (!j.at("leeward_port").is_boolean()) throw InvalidInput(at + ": 'leeward_port' must be true or false");
    d.leeward_port = j.at("leeward_port").get<bool>();
  }
  if (j.contains("stations")) {
    if (!j.at("stations").is_array()) throw InvalidInput(at + ": 'stations' must be an array");
    d.stations.clear();
    for (const json& s : j.at("stations")) {
      const std::string sat = at + " station " + std::to_string(d.stations.size());
      if (!s.is_object()) throw InvalidInput(sat + ": must be an object");
      checkKeys(s, {"fraction", "camber_pct", "draft_pct", "twist_deg", "entry_factor", "exit_factor"}, sat);
      ProfileStation p;
      p.fraction = number(s, "fraction", sat);
      p.camber_pct = numberOr(s, "camber_pct", p.camber_pct, sat);
      p.draft_pct = numberOr(s, "draft_pct", p.draft_pct, sat);
      p.twist_deg = numberOr(s, "twist_deg", p.twist_deg, sat);
      p.entry_factor = numberOr(s, "entry_factor", p.entry_factor, sat);
      p.exit_factor = numberOr(s, "exit_factor", p.exit_factor, sat);
      d.stations.push_back(p);
    }
  }
  validateDesign(d);
  return d;
}

std::string directoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

}  // namespace

std::string materialName(Material material) {
  switch (material) {
    case Material::Cloth: return "cloth";
    case Material::Tape: return "tape";
    case Material::LightGrey: return "light_grey";
    case Material::DarkGrey: return "dark_grey";
    case Material::Paint: return "paint";
    case Material::Metal: return "metal";
  }
  return "paint";
}

Material parseMaterial(const std::string& name) {
  for (Material m : {Material::Cloth, Material::Tape, Material::LightGrey, Material::DarkGrey, Material::Paint,
                     Material::Metal})
    if (materialName(m) == name) return m;
  throw InvalidInput("[parseMaterial] unknown material '" + name +
                     "' (expected cloth, tape, light_grey, dark_grey, paint or metal)");
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const SceneObject& o : objects) n += o.mesh.triangles.size();
  return n;
}

Mesh makeQuad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  Mesh m;
  m.vertices = {a, b, c, d};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

Mesh makeBox(const Vec3& lo, const Vec3& hi) {
  if (!(hi.array() > lo.array()).all())
    throw InvalidInput("[makeBox] max corner must exceed min corner on every axis (got min " +
                       std::to_string(lo.x()) + "," + std::to_string(lo.y()) + "," + std::to_string(lo.z()) +
                       " max " + std::to_string(hi.x()) + "," + std::to_string(hi.y()) + "," +
                       std::to_string(hi.z()) + ")");
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  // Outward counter-clockwise faces: -Z, +Z, -Y, +Y, -X, +X.
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

Mesh makeCylinder(const Vec3& base, const Vec3& axis, double radius_m, double length_m, int segments) {
  if (!(radius_m > 0) || !(length_m > 0) || segments < 3 || !(axis.norm() > 0))
    throw InvalidInput("[makeCylinder] needs radius_m > 0, length_m > 0, segments >= 3 and a non-zero axis (got " +
                       std::to_string(radius_m) + ", " + std::to_string(length_m) + ", " +
                       std::to_string(segments) + ")");
  const Vec3 w = axis.normalized();
  const Vec3 u = w.unitOrthogonal();
  const Vec3 v = w.cross(u);
  Mesh m;
  const auto n = static_cast<uint32_t>(segments);
  for (uint32_t i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Vec3 r = radius_m * (std::cos(a) * u + std::sin(a) * v);
    m.vertices.push_back(base + r);
    m.vertices.push_back(base + r + length_m * w);
  }
  m.vertices.push_back(base);
  m.vertices.push_back(base + length_m * w);
  const uint32_t c0 = 2 * n, c1 = 2 * n + 1;
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    m.triangles.push_back({2 * i, 2 * j, 2 * j + 1});
    m.triangles.push_back({2 * i, 2 * j + 1, 2 * i + 1});
    m.triangles.push_back({c0, 2 * j, 2 * i});
    m.triangles.push_back({c1, 2 * i + 1, 2 * j + 1});
  }
  return m;
}

std::vector<SceneObject> makeChamber(const Vec3& lo, const Vec3& hi) {
  if (!(hi.array() > lo.array()).all()) throw InvalidInput("[makeChamber] max corner must exceed min corner");
  const auto p = [&](int x, int y, int z) { return Vec3(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z()); };
  // Faces wound to point into the chamber.
  return {{"floor", Material::Paint, makeQuad(p(0, 0, 0), p(1, 0, 0), p(1, 1, 0), p(0, 1, 0))},
          {"ceiling", Material::Paint, makeQuad(p(0, 0, 1), p(0, 1, 1), p(1, 1, 1), p(1, 0, 1))},
          {"wall_starboard", Material::Paint, makeQuad(p(0, 0, 0), p(0, 0, 1), p(1, 0, 1), p(1, 0, 0))},
          {"wall_port", Material::Paint, makeQuad(p(0, 1, 0), p(1, 1, 0), p(1, 1, 1), p(0, 1, 1))},
          {"wall_aft", Material::Paint, makeQuad(p(0, 0, 0), p(0, 1, 0), p(0, 1, 1), p(0, 0, 1))},
          {"wall_forward", Material::Paint, makeQuad(p(1, 0, 0), p(1, 0, 1), p(1, 1, 1), p(1, 1, 0))}};
}

Scene builtInTunnelScene() {
  const TunnelDescription t = builtInTunnel();
  Scene s;
  s.name = "tunnel";
  s.objects = makeChamber(t.chamber_min_m, t.chamber_max_m);
  const TunnelHull& h = t.hull;
  s.objects.push_back({"hull", Material::Paint, makeHull(h.stern_x_m, h.bow_x_m, h.half_beam_m, h.deck_z_m, h.keel_z_m)});
  s.objects.push_back(sparObject(t.mast, t.mast_segments));
  s.objects.push_back(sparObject(t.boom, t.boom_segments));
  SailDesign main = scaleDesign(exampleDesign(SailType::Main), t.model_scale);
  s.objects.push_back(sailObject("main", main));
  SailDesign gennaker = scaleDesign(exampleDesign(SailType::Gennaker), t.model_scale);
  gennaker.stations = {{0.0, 20, 45, 32, 2.4, 1.8}, {0.5, 25, 48, 42, 2.4, 1.8}, {1.0, 17, 50, 56, 2, 2}};  // A2 running
  s.objects.push_back(sailObject("gennaker", gennaker));
  return s;
}

Scene builtInDeckScene() {
  Scene s;
  s.name = "deck";
  s.objects.push_back({"hull", Material::Paint, makeHull(-6.0, 4.5, 1.8, 0.0, -1.2)});
  s.objects.push_back({"cube", Material::LightGrey, makeBox(Vec3(1.5, -1.25, 0.0), Vec3(2.0, -0.75, 0.5))});
  s.objects.push_back({"mast", Material::Metal, makeCylinder(Vec3(0.1, 0, 0), Vec3::UnitZ(), 0.09, 12.0, 24)});
  s.objects.push_back({"boom", Material::Metal, makeCylinder(Vec3(0.0, 0, 0.9), -Vec3::UnitX(), 0.06, 4.0, 16)});
  s.objects.push_back(sailObject("main", exampleDesign(SailType::Main)));
  return s;
}

Scene parseSceneJson(const std::string& text, const std::string& origin) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw FileError("[readScene] " + origin + ": not valid JSON (" + e.what() + ")");
  }
  if (!root.is_object()) throw FileError("[readScene] " + origin + ": the top level must be an object");
  checkKeys(root, {"name", "preset", "objects"}, "[readScene] " + origin);
  Scene scene;
  const std::string preset = root.value("preset", std::string("empty"));
  if (preset == "tunnel") scene = builtInTunnelScene();
  else if (preset == "deck") scene = builtInDeckScene();
  else if (preset != "empty")
    throw InvalidInput("[readScene] " + origin + ": unknown preset '" + preset + "' (tunnel, deck or empty)");
  scene.name = root.value("name", preset);
  const json objects = root.value("objects", json::array());
  if (!objects.is_array()) throw InvalidInput("[readScene] " + origin + ": 'objects' must be an array");
  const std::string dir = directoryOf(origin);
  for (size_t i = 0; i < objects.size(); ++i) {
    const json& o = objects[i];
    if (!o.is_object() || !o.contains("type") || !o.at("type").is_string())
      throw InvalidInput(where(origin, i, "") + ": needs a string 'type'");
    const std::string type = o.at("type").get<std::string>();
    const std::string name = o.value("name", type);
    const std::string at = where(origin, i, name);
    SceneObject obj;
    obj.name = name;
    obj.material = o.contains("material") ? parseMaterial(o.at("material").get<std::string>())
                   : type == "sail"       ? Material::Cloth
                                          : Material::Paint;
    if (type == "box") {
      checkKeys(o, {"type", "name", "material", "min", "max"}, at);
      obj.mesh = makeBox(vec3(o, "min", at), vec3(o, "max", at));
    } else if (type == "quad") {
      checkKeys(o, {"type", "name", "material", "corners"}, at);
      const json c = o.value("corners", json());
      if (!c.is_array() || c.size() != 4) throw InvalidInput(at + ": 'corners' must hold four [x, y, z]");
      Vec3 p[4];
      for (int k = 0; k < 4; ++k) p[k] = vec3(json{{"corner", c[k]}}, "corner", at);
      obj.mesh = makeQuad(p[0], p[1], p[2], p[3]);
    } else if (type == "cylinder") {
      checkKeys(o, {"type", "name", "material", "base", "axis", "radius_m", "length_m", "segments"}, at);
      obj.mesh = makeCylinder(vec3(o, "base", at), vec3(o, "axis", at), number(o, "radius_m", at),
                              number(o, "length_m", at), static_cast<int>(numberOr(o, "segments", 32, at)));
    } else if (type == "chamber") {
      checkKeys(o, {"type", "name", "material", "min", "max"}, at);
      for (SceneObject& wall : makeChamber(vec3(o, "min", at), vec3(o, "max", at))) {
        wall.material = obj.material;
        scene.objects.push_back(std::move(wall));
      }
      continue;
    } else if (type == "sail") {
      checkKeys(o, {"type", "name", "material", "sail_type", "scale", "luff_m", "leech_m", "foot_m", "head_width_m",
                    "tack", "rake_deg", "luff_round_m", "luff_sag_m", "leech_round_m", "lean_deg", "leeward_port", "stations",
                    "rows", "columns"},
                at);
      const int rows = static_cast<int>(numberOr(o, "rows", 80, at));
      const int columns = static_cast<int>(numberOr(o, "columns", 40, at));
      if (rows < 2 || columns < 2) throw InvalidInput(at + ": rows and columns must be >= 2");
      obj.mesh = generateSailMesh(sailFromJson(o, at), rows, columns);
    } else if (type == "mesh") {
      checkKeys(o, {"type", "name", "material", "file"}, at);
      if (!o.contains("file") || !o.at("file").is_string()) throw InvalidInput(at + ": missing 'file'");
      std::string file = o.at("file").get<std::string>();
      if (!file.empty() && file[0] != '/') file = dir + file;
      obj.mesh = readMesh(file);
    } else {
      throw InvalidInput(at + ": unknown type '" + type + "' (box, quad, cylinder, chamber, sail, mesh)");
    }
    scene.objects.push_back(std::move(obj));
  }
  if (scene.objects.empty()) throw InvalidInput("[readScene] " + origin + ": the scene has no objects");
  return scene;
}

Scene readSceneFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError("[readScene] cannot open " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return parseSceneJson(ss.str(), path);
}

}  // namespace sailshape
