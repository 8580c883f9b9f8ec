#include "analysis/io/mesh_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/io/ply_format.hpp"
#include "analysis/io/text_scan.hpp"

namespace sailshape {

using namespace detail;

namespace {

FileError unknownMeshExtension(const std::string& path) {
  return fileError(path, "unknown mesh file extension '" + std::filesystem::path(path).extension().string() +
                             "' (expected .ply .obj .stl)");
}

// ---------------------------------------------------------------------------
// Building the mesh

std::string outOfRange(long long index, uint64_t n_vertices) {
  return "vertex index " + std::to_string(index) + " out of range (" + std::to_string(n_vertices) + " vertices)";
}

std::string tooFewCorners(long long count) {
  return "face with " + std::to_string(count) + " vertices (need at least 3)";
}

// Fan triangulation of a polygon whose indices are already checked.
void addPolygon(Mesh& mesh, const std::vector<uint32_t>& polygon) {
  for (size_t k = 1; k + 1 < polygon.size(); ++k) mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
}

// STL repeats every corner per facet: one vertex per bit-identical position (-0 and +0 count as one).
class VertexMerger {
 public:
  explicit VertexMerger(Mesh& mesh) : mesh_(mesh) {}

  uint32_t add(const Vec3& v) {
    Key key;
    for (int k = 0; k < 3; ++k) {
      const double c = v[k] + 0.0;
      std::memcpy(&key[k], &c, sizeof(c));
    }
    const auto [it, inserted] = index_.try_emplace(key, static_cast<uint32_t>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.push_back(v);
    return it->second;
  }

 private:
  using Key = std::array<uint64_t, 3>;
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = 0;
      for (uint64_t x : k) h = (h ^ x) * 0x9E3779B97F4A7C15ull + (h >> 29);
      return static_cast<size_t>(h ^ (h >> 32));
    }
  };
  Mesh& mesh_;
  std::unordered_map<Key, uint32_t, KeyHash> index_;
};

// ---------------------------------------------------------------------------
// PLY meshes: element vertex (x y z) and element face (list vertex_indices), in either order.

struct PlyMeshLayout {
  size_t vertex = 0;  // element indices in the header
  size_t face = 0;
  uint64_t n_vertices = 0;
  std::vector<int> axis;  // per vertex property: 0/1/2 for x/y/z, -1 for others
  size_t indices = 0;     // the face's index list property
};

PlyMeshLayout plyMeshLayout(const std::string& path, const PlyHeader& header) {
  const auto& elements = header.elements;
  auto find = [&](const char* name) {
    for (size_t e = 0; e < elements.size(); ++e)
      if (elements[e].name == name) return e;
    return elements.size();
  };
  PlyMeshLayout layout;
  layout.vertex = find("vertex");
  layout.face = find("face");
  if (layout.vertex == elements.size())
    throw atLine(path, header.end_header_line, "PLY header has no 'element vertex'");
  if (layout.face == elements.size())
    throw atLine(path, header.end_header_line, "PLY header has no 'element face' (a point cloud, not a mesh)");

  const PlyElement& vertex = elements[layout.vertex];
  if (vertex.count > std::numeric_limits<uint32_t>::max())
    throw atLine(path, vertex.line, "too many vertices (" + std::to_string(vertex.count) + ")");
  layout.n_vertices = vertex.count;
  layout.axis.assign(vertex.properties.size(), -1);
  const char* const axis_names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    size_t k = 0;
    while (k < vertex.properties.size() && vertex.properties[k].name != axis_names[a]) ++k;
    if (k == vertex.properties.size())
      throw atLine(path, vertex.line, "PLY vertex element has no '" + std::string(axis_names[a]) + "' property");
    if (vertex.properties[k].is_list)
      throw atLine(path, vertex.properties[k].line, "vertex property '" + vertex.properties[k].name + "' is a list");
    layout.axis[k] = a;
  }

  const PlyElement& face = elements[layout.face];
  size_t k = 0;
  while (k < face.properties.size() && face.properties[k].name != "vertex_indices" &&
         face.properties[k].name != "vertex_index")
    ++k;
  if (k == face.properties.size()) throw atLine(path, face.line, "PLY face element has no 'vertex_indices' list");
  const PlyProperty& list = face.properties[k];
  if (!list.is_list) throw atLine(path, list.line, "face property '" + list.name + "' is not a list");
  if (!isIntegerScalar(list.type)) throw atLine(path, list.line, "face vertex indices must have an integer type");
  layout.indices = k;
  return layout;
}

void readPlyMeshBinary(const std::string& path, const std::string& buf, const PlyHeader& header,
                       const PlyMeshLayout& layout, Mesh& mesh) {
  const bool swap = (header.encoding == PlyEncoding::BinaryLittleEndian) != kHostLittleEndian;
  const char* base = buf.data();
  const size_t size = buf.size();
  size_t pos = header.data_offset;
  std::vector<uint32_t> polygon;
  const size_t last = std::max(layout.vertex, layout.face);  // elements after both are not needed
  for (size_t e = 0; e <= last; ++e) {
    const PlyElement& el = header.elements[e];
    if (e != layout.vertex && e != layout.face) {
      pos = skipBinaryElement(path, buf, pos, el, swap);
      continue;
    }
    const bool is_vertex = e == layout.vertex;
    for (uint64_t i = 0; i < el.count; ++i) {
      Vec3 v = Vec3::Zero();
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const PlyProperty& p = el.properties[k];
        if (!is_vertex && k == layout.indices) {
          const size_t count_size = scalarSize(p.count_type);
          if (size - pos < count_size) throw truncatedAtByte(path, size, el, i);
          const double count = loadScalar(base + pos, p.count_type, swap);
          if (count < 3) throw atByte(path, pos, tooFewCorners(static_cast<long long>(count)));
          pos += count_size;
          const uint64_t corners = static_cast<uint64_t>(count);  // the count type is an integer type
          const size_t item = scalarSize(p.type);
          if ((size - pos) / item < corners) throw truncatedAtByte(path, size, el, i);
          polygon.clear();
          for (uint64_t j = 0; j < corners; ++j, pos += item) {
            const double index = loadScalar(base + pos, p.type, swap);
            if (index < 0 || index >= static_cast<double>(layout.n_vertices))
              throw atByte(path, pos, outOfRange(static_cast<long long>(index), layout.n_vertices));
            polygon.push_back(static_cast<uint32_t>(index));
          }
          addPolygon(mesh, polygon);
        } else if (p.is_list) {
          pos = skipBinaryList(path, buf, pos, p, swap, el, i);
        } else {
          const size_t n = scalarSize(p.type);
          if (size - pos < n) throw truncatedAtByte(path, size, el, i);
          if (is_vertex && layout.axis[k] >= 0) {
            const double x = loadScalar(base + pos, p.type, swap);
            if (!std::isfinite(x))
              throw atByte(path, pos,
                           "non-finite vertex coordinate (" + p.name + " of vertex " + std::to_string(i) + ")");
            v[layout.axis[k]] = x;
          }
          pos += n;
        }
      }
      if (is_vertex) mesh.vertices.push_back(v);
    }
  }
}

void readPlyMeshAscii(const std::string& path, const std::string& buf, const PlyHeader& header,
                      const PlyMeshLayout& layout, Mesh& mesh) {
  LineReader lines(buf.data() + header.data_offset, buf.data() + buf.size(), header.end_header_line + 1);
  std::string_view line;
  std::vector<std::string_view> tok;
  std::vector<uint32_t> polygon;
  const size_t last = std::max(layout.vertex, layout.face);
  for (size_t e = 0; e <= last; ++e) {
    const PlyElement& el = header.elements[e];
    const bool is_vertex = e == layout.vertex;
    const bool is_face = e == layout.face;
    for (uint64_t i = 0; i < el.count; ++i) {
      if (!lines.nextNonEmpty(line)) throw truncatedAtLine(path, lines.line() + 1, el, i);
      if (!is_vertex && !is_face) continue;
      const size_t n = lines.line();
      splitWhitespace(line, tok);
      Vec3 v = Vec3::Zero();
      size_t t = 0;
      for (size_t k = 0; k < el.properties.size(); ++k) {
        const PlyProperty& p = el.properties[k];
        if (t >= tok.size()) throw atLine(path, n, "too few values (no value for property '" + p.name + "')");
        const std::string_view first = tok[t++];
        if (p.is_list) {
          long long count = 0;
          if (!parseInteger(first, count) || count < 0) throw atLine(path, n, "invalid list length " + quoted(first));
          if (static_cast<unsigned long long>(count) > tok.size() - t)
            throw atLine(path, n, "too few values for list property '" + p.name + "'");
          if (!(is_face && k == layout.indices)) {
            t += static_cast<size_t>(count);
            continue;
          }
          if (count < 3) throw atLine(path, n, tooFewCorners(count));
          polygon.clear();
          for (long long j = 0; j < count; ++j) {
            long long index = 0;
            if (!parseInteger(tok[t], index)) throw atLine(path, n, "invalid vertex index " + quoted(tok[t]));
            if (index < 0 || static_cast<unsigned long long>(index) >= layout.n_vertices)
              throw atLine(path, n, outOfRange(index, layout.n_vertices));
            polygon.push_back(static_cast<uint32_t>(index));
            ++t;
          }
          addPolygon(mesh, polygon);
        } else {
          const double x = numberOnLine(path, n, first);
          if (is_vertex && layout.axis[k] >= 0) {
            if (!std::isfinite(x)) throw atLine(path, n, "non-finite vertex coordinate " + quoted(first));
            v[layout.axis[k]] = x;
          }
        }
      }
      if (t != tok.size())
        throw atLine(path, n, "expected " + std::to_string(t) + " values, got " + std::to_string(tok.size()));
      if (is_vertex) mesh.vertices.push_back(v);
    }
  }
}

Mesh readPlyMesh(const std::string& path, const std::string& buf) {
  const PlyHeader header = parsePlyHeader(path, buf);
  const PlyMeshLayout layout = plyMeshLayout(path, header);
  Mesh mesh;
  mesh.vertices.reserve(
      static_cast<size_t>(std::min<uint64_t>(layout.n_vertices, (buf.size() - header.data_offset) / 3)));
  if (header.encoding == PlyEncoding::Ascii)
    readPlyMeshAscii(path, buf, header, layout, mesh);
  else
    readPlyMeshBinary(path, buf, header, layout, mesh);
  return mesh;
}

// ---------------------------------------------------------------------------
// OBJ: "v x y z", "f a b c ..." with a, a/t, a/t/n or a//n corners, 1-based or negative (relative).

Mesh readObj(const std::string& path, const std::string& buf) {
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::string_view line;
  std::vector<std::string_view> tok;
  std::vector<uint32_t> polygon;
  // Faces may name vertices defined further down; those are checked at the end.
  std::vector<std::pair<size_t, long long>> forward_references;  // (line, 1-based index)
  Mesh mesh;
  while (lines.next(line)) {
    const size_t n = lines.line();
    splitWhitespace(line, tok);
    if (tok.empty() || tok[0].front() == '#') continue;
    if (tok[0] == "v") {
      if (tok.size() < 4) throw atLine(path, n, "expected 3 coordinates, got " + std::to_string(tok.size() - 1));
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        v[k] = numberOnLine(path, n, tok[1 + k]);
        if (!std::isfinite(v[k])) throw atLine(path, n, "non-finite vertex coordinate " + quoted(tok[1 + k]));
      }
      mesh.vertices.push_back(v);
    } else if (tok[0] == "f") {
      if (tok.size() < 4) throw atLine(path, n, tooFewCorners(static_cast<long long>(tok.size() - 1)));
      polygon.clear();
      for (size_t c = 1; c < tok.size(); ++c) {
        const std::string_view corner = tok[c].substr(0, tok[c].find('/'));
        long long index = 0;
        if (!parseInteger(corner, index)) throw atLine(path, n, "invalid vertex index " + quoted(tok[c]));
        const long long count = static_cast<long long>(mesh.vertices.size());
        if (index == 0) throw atLine(path, n, "vertex index 0 (OBJ indices start at 1)");
        if (index < 0) {
          if (-index > count) throw atLine(path, n, outOfRange(index, mesh.vertices.size()));
          polygon.push_back(static_cast<uint32_t>(count + index));
        } else {
          if (index > std::numeric_limits<uint32_t>::max())
            throw atLine(path, n, outOfRange(index, mesh.vertices.size()));
          if (index > count) forward_references.emplace_back(n, index);
          polygon.push_back(static_cast<uint32_t>(index - 1));
        }
      }
      addPolygon(mesh, polygon);
    }
    // vt, vn, o, g, s, usemtl, mtllib, l, p, ...: not geometry we keep.
  }
  for (const auto& [n, index] : forward_references)
    if (static_cast<unsigned long long>(index) > mesh.vertices.size())
      throw atLine(path, n, outOfRange(index, mesh.vertices.size()));
  return mesh;
}

// ---------------------------------------------------------------------------
// STL

constexpr size_t kStlHeaderBytes = 84;  // 80-byte header + uint32 triangle count
constexpr size_t kStlTriangleBytes = 50;

uint64_t stlBinaryCount(const std::string& buf) { return loadAs<uint32_t>(buf.data() + 80, !kHostLittleEndian); }

// Binary files may also start with "solid": the size decides first.
bool isAsciiStl(const std::string& buf) {
  if (buf.size() >= kStlHeaderBytes && kStlHeaderBytes + kStlTriangleBytes * stlBinaryCount(buf) == buf.size())
    return false;
  const std::string_view head = trim(std::string_view(buf).substr(0, 4096));
  if (lowercase(head.substr(0, 5)) != "solid") return false;
  return head.find("facet") != std::string_view::npos || head.find("endsolid") != std::string_view::npos;
}

Mesh readStlBinary(const std::string& path, const std::string& buf) {
  if (buf.size() < kStlHeaderBytes)
    throw atByte(path, buf.size(), "truncated STL header (a binary STL starts with 84 bytes)");
  const uint64_t count = stlBinaryCount(buf);
  const size_t available = (buf.size() - kStlHeaderBytes) / kStlTriangleBytes;
  if (count > available)
    throw atByte(
        path, buf.size(),
        "truncated data (expected " + std::to_string(count) + " triangles, got " + std::to_string(available) + ")");
  Mesh mesh;
  mesh.triangles.reserve(static_cast<size_t>(count));
  VertexMerger merger(mesh);
  const bool swap = !kHostLittleEndian;
  for (size_t t = 0; t < count; ++t) {
    const size_t record = kStlHeaderBytes + kStlTriangleBytes * t;
    std::array<uint32_t, 3> tri;
    for (int c = 0; c < 3; ++c) {
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        const size_t at = record + 12 + 12 * c + 4 * k;  // after the facet normal
        const float x = loadAs<float>(buf.data() + at, swap);
        if (!std::isfinite(x))
          throw atByte(path, at, "non-finite vertex coordinate (triangle " + std::to_string(t) + ")");
        v[k] = x;
      }
      tri[c] = merger.add(v);
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

Mesh readStlAscii(const std::string& path, const std::string& buf) {
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::string_view line;
  std::vector<std::string_view> tok;
  std::vector<uint32_t> polygon;
  Mesh mesh;
  VertexMerger merger(mesh);
  bool in_facet = false, in_loop = false;
  size_t facet_line = 0;
  while (lines.next(line)) {
    const size_t n = lines.line();
    splitWhitespace(line, tok);
    if (tok.empty()) continue;
    const std::string key = lowercase(tok[0]);
    if (key == "solid") {
      if (in_facet) throw atLine(path, n, "'solid' inside the facet of line " + std::to_string(facet_line));
    } else if (key == "facet") {
      if (in_facet)
        throw atLine(path, n, "'facet' before 'endfacet' of the facet of line " + std::to_string(facet_line));
      in_facet = true;
      facet_line = n;
    } else if (key == "outer") {
      if (!in_facet || in_loop) throw atLine(path, n, "'outer loop' outside a facet");
      in_loop = true;
      polygon.clear();
    } else if (key == "vertex") {
      if (!in_loop) throw atLine(path, n, "'vertex' outside a loop");
      if (tok.size() != 4) throw atLine(path, n, "expected 3 coordinates, got " + std::to_string(tok.size() - 1));
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        v[k] = numberOnLine(path, n, tok[1 + k]);
        if (!std::isfinite(v[k])) throw atLine(path, n, "non-finite vertex coordinate " + quoted(tok[1 + k]));
      }
      polygon.push_back(merger.add(v));
    } else if (key == "endloop") {
      if (!in_loop) throw atLine(path, n, "'endloop' without 'outer loop'");
      if (polygon.size() < 3) throw atLine(path, n, tooFewCorners(static_cast<long long>(polygon.size())));
      addPolygon(mesh, polygon);
      in_loop = false;
    } else if (key == "endfacet") {
      if (!in_facet || in_loop) throw atLine(path, n, "'endfacet' without a complete facet");
      in_facet = false;
    } else if (key == "endsolid") {
      if (in_facet) throw atLine(path, n, "'endsolid' inside the facet of line " + std::to_string(facet_line));
    } else {
      throw atLine(path, n, "unknown STL keyword " + quoted(tok[0]));
    }
  }
  if (in_facet)
    throw atLine(path, lines.line(), "truncated data (facet of line " + std::to_string(facet_line) + " not closed)");
  return mesh;
}

// ---------------------------------------------------------------------------
// Writing

void checkTriangles(const Mesh& mesh) {
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        throw InvalidInput("[writeMesh] triangle " + std::to_string(t) + " has vertex index " + std::to_string(v) +
                           " (mesh has " + std::to_string(mesh.vertices.size()) + " vertices)");
}

std::string plyMeshContent(const Mesh& mesh, bool binary) {
  std::string out = "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by sailshape\n";
  out += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  if (binary) {
    out.reserve(out.size() + 24 * mesh.vertices.size() + 13 * mesh.triangles.size());
    for (const Vec3& v : mesh.vertices)
      for (int k = 0; k < 3; ++k) appendLittleEndian(out, v[k]);
    for (const auto& tri : mesh.triangles) {
      out += static_cast<char>(3);
      for (uint32_t i : tri) appendLittleEndian(out, static_cast<int32_t>(i));
    }
    return out;
  }
  for (const Vec3& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      appendNumber(out, v[k]);
    }
    out += '\n';
  }
  for (const auto& tri : mesh.triangles)
    out += "3 " + std::to_string(tri[0]) + ' ' + std::to_string(tri[1]) + ' ' + std::to_string(tri[2]) + '\n';
  return out;
}

std::string objContent(const Mesh& mesh) {
  std::string out = "# written by sailshape\n";
  for (const Vec3& v : mesh.vertices) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      appendNumber(out, v[k]);
    }
    out += '\n';
  }
  for (const auto& tri : mesh.triangles)
    out +=
        "f " + std::to_string(tri[0] + 1) + ' ' + std::to_string(tri[1] + 1) + ' ' + std::to_string(tri[2] + 1) + '\n';
  return out;
}

// STL stores float32 and repeats each corner per facet.
std::string stlContent(const Mesh& mesh, bool binary) {
  std::string out;
  if (binary) {
    std::string header = "binary STL written by sailshape";
    header.resize(80, ' ');
    out = header;
    appendLittleEndian(out, static_cast<uint32_t>(mesh.triangles.size()));
    out.reserve(out.size() + kStlTriangleBytes * mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Vec3 normal = triangleNormal(mesh, t);
      for (int k = 0; k < 3; ++k) appendLittleEndian(out, static_cast<float>(normal[k]));
      for (uint32_t i : mesh.triangles[t])
        for (int k = 0; k < 3; ++k) appendLittleEndian(out, static_cast<float>(mesh.vertices[i][k]));
      appendLittleEndian(out, uint16_t{0});
    }
    return out;
  }
  out = "solid sailshape\n";
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 normal = triangleNormal(mesh, t);
    out += "  facet normal";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      appendNumber(out, static_cast<float>(normal[k]));
    }
    out += "\n    outer loop\n";
    for (uint32_t i : mesh.triangles[t]) {
      out += "      vertex";
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        appendNumber(out, static_cast<float>(mesh.vertices[i][k]));
      }
      out += '\n';
    }
    out += "    endloop\n  endfacet\n";
  }
  out += "endsolid sailshape\n";
  return out;
}

}  // namespace

void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format) {
  checkTriangles(mesh);
  if (format == MeshFormat::Auto) {
    const std::string ext = extensionOf(path);
    if (ext == ".ply")
      format = MeshFormat::PlyBinary;
    else if (ext == ".obj")
      format = MeshFormat::Obj;
    else if (ext == ".stl")
      format = MeshFormat::StlBinary;
    else
      throw unknownMeshExtension(path);
  }
  std::string content;
  switch (format) {
    case MeshFormat::PlyAscii:
      content = plyMeshContent(mesh, false);
      break;
    case MeshFormat::PlyBinary:
      content = plyMeshContent(mesh, true);
      break;
    case MeshFormat::Obj:
      content = objContent(mesh);
      break;
    case MeshFormat::StlAscii:
      content = stlContent(mesh, false);
      break;
    case MeshFormat::StlBinary:
      content = stlContent(mesh, true);
      break;
    case MeshFormat::Auto:
      break;
  }
  writeWholeFile(path, content);
}

Mesh readMesh(const std::string& path) {
  const std::string ext = extensionOf(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".stl") throw unknownMeshExtension(path);
  const std::string buf = readWholeFile(path);
  Mesh mesh;
  if (ext == ".ply")
    mesh = readPlyMesh(path, buf);
  else if (ext == ".obj")
    mesh = readObj(path, buf);
  else
    mesh = isAsciiStl(buf) ? readStlAscii(path, buf) : readStlBinary(path, buf);
  if (mesh.triangles.empty()) throw fileError(path, "no triangles");
  return mesh;
}

}  // namespace sailshape
