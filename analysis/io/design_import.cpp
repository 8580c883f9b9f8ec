#include "analysis/io/design_import.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <string_view>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/io/text_scan.hpp"

namespace sailshape {

using namespace detail;

namespace {

constexpr double kAutoMillimetresAbove = 100.0;  // no sail is 100 m long; a 100 mm model sail is unusual

// One 3DFACE entity: corners 0..3, coordinates x, y, z, each present or not.
struct DxfFace {
  std::array<std::array<double, 3>, 4> corner{};
  std::array<std::array<bool, 3>, 4> has{};
  size_t line = 0;  // of its "3DFACE" value
};

struct DxfRead {
  Mesh mesh;
  size_t faces = 0;
  size_t dropped = 0;  // faces that collapsed when identical corners merged
};

class CornerMerger {
 public:
  explicit CornerMerger(Mesh& mesh) : mesh_(mesh) {}
  uint32_t add(const std::array<double, 3>& c) {
    Key key;
    for (int k = 0; k < 3; ++k) {
      const double v = c[static_cast<size_t>(k)] + 0.0;  // -0 and +0 are one position
      std::memcpy(&key[static_cast<size_t>(k)], &v, sizeof(v));
    }
    const auto [it, inserted] = index_.try_emplace(key, static_cast<uint32_t>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.emplace_back(c[0], c[1], c[2]);
    return it->second;
  }

 private:
  using Key = std::array<uint64_t, 3>;
  struct Hash {
    size_t operator()(const Key& k) const {
      return std::hash<uint64_t>()(k[0]) ^ (std::hash<uint64_t>()(k[1]) * 31) ^ (std::hash<uint64_t>()(k[2]) * 131);
    }
  };
  Mesh& mesh_;
  std::unordered_map<Key, uint32_t, Hash> index_;
};

std::string groupName(int corner, int axis) { return std::to_string((axis + 1) * 10 + corner); }

void addFace(const std::string& path, const DxfFace& f, CornerMerger& merger, DxfRead& out) {
  const char* axis_name = "xyz";
  for (int c = 0; c < 3; ++c)
    for (int a = 0; a < 3; ++a)
      if (!f.has[static_cast<size_t>(c)][static_cast<size_t>(a)])
        throw atLine(path, f.line,
                     "truncated 3DFACE entity: group " + groupName(c, a) + " (corner " + std::to_string(c + 1) + " " +
                         axis_name[a] + ") is missing");
  const auto& h4 = f.has[3];
  const bool any4 = h4[0] || h4[1] || h4[2], all4 = h4[0] && h4[1] && h4[2];
  if (any4 && !all4)
    throw atLine(path, f.line, "truncated 3DFACE entity: corner 4 has only some of groups 13, 23, 33");
  std::array<uint32_t, 4> v{};
  for (size_t c = 0; c < 3; ++c) v[c] = merger.add(f.corner[c]);
  v[3] = all4 ? merger.add(f.corner[3]) : v[2];  // no 4th corner: a triangle
  ++out.faces;
  auto push = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (a == b || b == c || a == c) {
      ++out.dropped;
      return;
    }
    out.mesh.triangles.push_back({a, b, c});
  };
  push(v[0], v[1], v[2]);
  if (v[3] != v[2]) push(v[0], v[2], v[3]);
}

DxfRead parseDxf(const std::string& path) {
  const std::string buf = readWholeFile(path);
  if (buf.rfind("AutoCAD Binary DXF", 0) == 0)
    throw fileError(path, "binary DXF is not supported (export it as ASCII DXF)");
  DxfRead out;
  CornerMerger merger(out.mesh);
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::set<std::string> other_entities;
  bool in_face = false, in_entities = false, last_was_section = false;
  DxfFace face;
  std::string_view line;
  while (lines.nextNonEmpty(line)) {
    const size_t code_line = lines.line();
    int code = 0;
    if (!parseInteger(trim(line), code))
      throw atLine(path, code_line, "group code " + quoted(trim(line)) + " is not an integer (not an ASCII DXF file?)");
    if (!lines.next(line))
      throw atLine(path, code_line, "truncated file: group code " + std::to_string(code) + " has no value");
    const std::string_view value = trim(line);
    if (code == 0) {
      if (in_face) addFace(path, face, merger, out);
      in_face = false;
      last_was_section = value == "SECTION";
      if (value == "ENDSEC") in_entities = false;
      if (value == "3DFACE") {
        in_face = true;
        face = DxfFace{};
        face.line = lines.line();
      } else if (in_entities && value != "ENDSEC") {
        other_entities.insert(std::string(value));
      }
      if (value == "EOF") break;
      continue;
    }
    if (code == 2 && last_was_section) in_entities = value == "ENTITIES";
    last_was_section = false;
    if (!in_face) continue;
    const int axis = code / 10 - 1, corner = code % 10;
    if (code >= 10 && code < 40 && corner <= 3) {
      face.corner[static_cast<size_t>(corner)][static_cast<size_t>(axis)] = numberOnLine(path, lines.line(), value);
      const double c = face.corner[static_cast<size_t>(corner)][static_cast<size_t>(axis)];
      if (!std::isfinite(c)) throw atLine(path, lines.line(), "non-finite coordinate " + quoted(value));
      face.has[static_cast<size_t>(corner)][static_cast<size_t>(axis)] = true;
    }
  }
  if (in_face) addFace(path, face, merger, out);
  if (out.faces == 0) {
    std::string seen;
    for (const auto& e : other_entities) seen += (seen.empty() ? "" : ", ") + e;
    throw fileError(path, "no 3DFACE entity found (only 3DFACE surfaces are supported" +
                              (seen.empty() ? std::string(")") : "; entities in the file: " + seen + ")"));
  }
  if (out.mesh.triangles.empty()) throw fileError(path, "every 3DFACE entity is degenerate (repeated corners)");
  return out;
}

std::string formatNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.4g", v);
  return b;
}

Vec3 extents(const Mesh& mesh) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return mesh.vertices.empty() ? Vec3::Zero() : Vec3(hi - lo);
}

}  // namespace

Mesh readDxf3dFaces(const std::string& path, size_t* faces_read) {
  DxfRead r = parseDxf(path);
  if (faces_read) *faces_read = r.faces;
  return std::move(r.mesh);
}

DesignImport importDesign(const std::string& path, const DesignImportOptions& options) {
  static const std::set<std::string> kUnits{"auto", "m", "mm", "cm"}, kAxes{"auto", "boat", "sailcut"};
  if (!kUnits.count(options.unit))
    throw InvalidInput("[importDesign] unit must be auto, m, mm or cm (got '" + options.unit + "')");
  if (!kAxes.count(options.axes))
    throw InvalidInput("[importDesign] axes must be auto, boat or sailcut (got '" + options.axes + "')");

  DesignImport result;
  const std::string ext = extensionOf(path);
  if (ext == ".dxf") {
    DxfRead r = parseDxf(path);
    result.mesh = std::move(r.mesh);
    result.format = "dxf";
    result.faces_read = r.faces;
    result.notes.push_back("read " + std::to_string(r.faces) + " 3DFACE entities: " +
                           std::to_string(result.mesh.triangles.size()) + " triangles, " +
                           std::to_string(result.mesh.vertices.size()) + " distinct vertices");
    if (r.dropped > 0)
      result.notes.push_back("dropped " + std::to_string(r.dropped) + " degenerate faces (repeated corners)");
  } else if (ext == ".obj" || ext == ".stl" || ext == ".ply") {
    result.mesh = readMesh(path);
    result.format = ext.substr(1);
    result.faces_read = result.mesh.triangles.size();
    result.notes.push_back("read " + std::to_string(result.mesh.triangles.size()) + " triangles, " +
                           std::to_string(result.mesh.vertices.size()) + " vertices");
  } else {
    throw fileError(path, "unsupported design file extension " + quoted(ext) + " (expected .dxf .obj .stl .ply)");
  }

  // Unit.
  const Vec3 ext_file = extents(result.mesh);
  const double largest = ext_file.maxCoeff();
  std::string unit = options.unit;
  std::string why = "(given)";
  if (unit == "auto") {
    unit = largest > kAutoMillimetresAbove ? "mm" : "m";
    why = std::string("(detected: largest extent ") + formatNumber(largest) + (unit == "mm" ? " > " : " <= ") +
          formatNumber(kAutoMillimetresAbove) + ")";
  }
  const double scale = unit == "mm" ? 1e-3 : unit == "cm" ? 1e-2 : 1.0;
  const char* unit_name = unit == "mm" ? "millimetres" : unit == "cm" ? "centimetres" : "metres";
  result.unit = unit;
  result.notes.push_back(std::string("unit: ") + unit_name + " " + why);

  // Axes.
  std::string axes = options.axes;
  why = "(given)";
  if (axes == "auto") {
    if (result.format == "dxf") {
      axes = "sailcut";
      why = "(assumed for DXF, as Sailcut CAD writes it)";
    } else if (ext_file.y() > ext_file.x() && ext_file.y() > ext_file.z() && ext_file.z() < ext_file.x()) {
      axes = "sailcut";
      why = "(detected: Y is the largest extent and Z the smallest, a Y-up file)";
    } else {
      axes = "boat";
      why = "(assumed: Y is not the up axis)";
    }
  }
  result.axes = axes;
  if (axes == "sailcut") {
    result.notes.push_back("axes: sailcut, X tack->clew, Y up, Z depth, mapped to boat X = -x, Y = z, Z = y " + why);
    for (Vec3& v : result.mesh.vertices) v = scale * Vec3(-v.x(), v.z(), v.y());
  } else {
    result.notes.push_back("axes: boat, +X forward, +Y port, +Z up " + why);
    for (Vec3& v : result.mesh.vertices) v *= scale;
  }
  const Vec3 e = extents(result.mesh);
  if (e.z() < e.x() && e.z() < e.y())
    result.notes.push_back("warning: the sail is shallowest along Z (up) after import; check the axes option");
  return result;
}

}  // namespace sailshape
