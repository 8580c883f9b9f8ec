#include "analysis/io/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;

// readMesh(path) must fail with "<path>: ..." containing every part.
#define EXPECT_READ_ERROR(path, ...)                                                          \
  do {                                                                                        \
    SCOPED_TRACE("readMesh(" + std::string(path) + ")");                                      \
    const std::string p_ = (path);                                                            \
    expectFileError([&] { readMesh(p_); }, p_ + ": ", std::vector<std::string>{__VA_ARGS__}); \
  } while (0)

// Binary payloads for hand-made files (tests run on little-endian hosts).
struct Bytes {
  std::string data;
  template <typename T>
  Bytes& le(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    data.append(b, sizeof(T));
    return *this;
  }
  template <typename T>
  Bytes& be(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    std::reverse(b, b + sizeof(T));
    data.append(b, sizeof(T));
    return *this;
  }
  Bytes& text(const std::string& s) {
    data += s;
    return *this;
  }
};

// A cambered 6 × 5 panel, 8 m high and 4 m wide, with a twist: a small design sail.
Mesh makeSailPanel() {
  constexpr int kCols = 6, kRows = 5;
  Mesh mesh;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) {
      const double u = c / double(kCols - 1), v = r / double(kRows - 1);
      const double camber = 0.4 * u * (1 - u) * (1 - 0.5 * v);
      mesh.vertices.emplace_back(4.0 * u * (1 - 0.6 * v) + 0.1 * v + 1.23456789e-7, camber + 0.3 * v * u,
                                 8.0 * v + 0.05 * u);
    }
  for (int r = 0; r + 1 < kRows; ++r)
    for (int c = 0; c + 1 < kCols; ++c) {
      const uint32_t a = r * kCols + c, b = a + 1, d = a + kCols, e = d + 1;
      mesh.triangles.push_back({a, b, e});
      mesh.triangles.push_back({a, e, d});
    }
  return mesh;
}

// Same triangles at the same positions (vertex numbering may differ after STL's merge).
void expectSameGeometry(const Mesh& expected, const Mesh& actual, double tolerance_m) {
  ASSERT_EQ(expected.triangles.size(), actual.triangles.size());
  EXPECT_EQ(expected.vertices.size(), actual.vertices.size());
  for (size_t t = 0; t < expected.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      ASSERT_LT(actual.triangles[t][c], actual.vertices.size());
      const Vec3& want = expected.vertices[expected.triangles[t][c]];
      const Vec3& got = actual.vertices[actual.triangles[t][c]];
      ASSERT_LE((want - got).cwiseAbs().maxCoeff(), tolerance_m) << "triangle " << t << " corner " << c;
    }
  EXPECT_NEAR(meshArea(expected), meshArea(actual), 1e-5);
}

class MeshIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace_if(
        name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    dir_ = fs::temp_directory_path() /
           ("sailshape_" + name + "_" + std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const std::string& content) const {
    const std::string p = path(name);
    std::ofstream out(p, std::ios::binary);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    return p;
  }

  std::string contents(const std::string& p) const {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }

  fs::path dir_;
};

// ---------------------------------------------------------------------------
// Round trips

struct MeshFormatCase {
  MeshFormat format;
  const char* file;
  bool float32;  // STL
};

class MeshRoundTrip : public MeshIoTest, public ::testing::WithParamInterface<MeshFormatCase> {};

TEST_P(MeshRoundTrip, ReproducesVerticesToAMicrometre) {
  const Mesh mesh = makeSailPanel();
  const std::string p = path(GetParam().file);
  writeMesh(p, mesh, GetParam().format);
  const Mesh back = readMesh(p);
  expectSameGeometry(mesh, back, 1e-6);
  if (!GetParam().float32) {  // PLY and OBJ keep numbering and full precision
    EXPECT_EQ(back.triangles, mesh.triangles);
    for (size_t i = 0; i < mesh.vertices.size(); ++i) EXPECT_EQ(back.vertices[i], mesh.vertices[i]);
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, MeshRoundTrip,
                         ::testing::Values(MeshFormatCase{MeshFormat::PlyAscii, "m.ply", false},
                                           MeshFormatCase{MeshFormat::PlyBinary, "m.ply", false},
                                           MeshFormatCase{MeshFormat::Obj, "m.obj", false},
                                           MeshFormatCase{MeshFormat::StlAscii, "m.stl", true},
                                           MeshFormatCase{MeshFormat::StlBinary, "m.stl", true}),
                         [](const auto& info) {
                           return std::to_string(info.index) + "_" + std::string(info.param.file).substr(2);
                         });

TEST_F(MeshIoTest, AutoFormatFollowsExtension) {
  const Mesh mesh = makeSailPanel();
  writeMesh(path("a.ply"), mesh);
  EXPECT_EQ(contents(path("a.ply")).rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  writeMesh(path("a.stl"), mesh);
  EXPECT_EQ(contents(path("a.stl")).size(), 84 + 50 * mesh.triangles.size());
  writeMesh(path("a.obj"), mesh);
  EXPECT_NE(contents(path("a.obj")).find("\nf 1 2 8\n"), std::string::npos);
  for (const char* file : {"a.ply", "a.stl", "a.obj"}) expectSameGeometry(mesh, readMesh(path(file)), 1e-6);
}

TEST_F(MeshIoTest, WriteRejectsBadInput) {
  Mesh mesh = makeSailPanel();
  expectFileError([&] { writeMesh(path("m.foo"), mesh); }, path("m.foo") + ": ",
                  {"unknown mesh file extension '.foo' (expected .ply .obj .stl)"});
  expectFileError([&] { writeMesh((dir_ / "no" / "m.obj").string(), mesh); }, (dir_ / "no" / "m.obj").string() + ": ",
                  {"cannot open file for writing"});
  mesh.triangles[3][1] = 30;
  try {
    writeMesh(path("m.ply"), mesh);
    ADD_FAILURE() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[writeMesh] triangle 3 has vertex index 30 (mesh has 30 vertices)");
  }
  EXPECT_THROW(writeMesh(path("m.ply"), mesh), InvalidInput);
}

TEST_F(MeshIoTest, MissingFileAndUnknownExtension) {
  EXPECT_READ_ERROR(path("missing.obj"), "cannot open file");
  const std::string foo = write("m.3ds", "");
  expectFileError([&] { readMesh(foo); }, foo + ": unknown mesh file extension '.3ds' (expected .ply .obj .stl)", {});
}

// ---------------------------------------------------------------------------
// PLY

TEST_F(MeshIoTest, PlyAsciiFacesFirstWithQuadAndExtraProperties) {
  const Mesh mesh =
      readMesh(write("quad.ply",
                     "ply\nformat ascii 1.0\ncomment faces before vertices\nelement face 2\nproperty uchar red\n"
                     "property list uint8 uint32 vertex_indices\nelement vertex 5\nproperty float x\nproperty float y\n"
                     "property float z\nproperty list uchar float texcoord\nend_header\n"
                     "255 4 0 1 2 3\n0 3 2 1 4\n0 0 0 2 0.1 0.2\n1 0 0 0\n1 1 0 0\n0 1 0 0\n0.5 0.5 1 0\n"));
  ASSERT_EQ(mesh.vertices.size(), 5u);
  EXPECT_EQ(mesh.vertices[4], Vec3(0.5, 0.5, 1));
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(mesh.triangles[2], (std::array<uint32_t, 3>{2, 1, 4}));
  EXPECT_DOUBLE_EQ(meshArea(Mesh{mesh.vertices, {mesh.triangles[0], mesh.triangles[1]}}), 1.0);
}

TEST_F(MeshIoTest, PlyBinaryBigEndianWithVertexIndexName) {
  Bytes b;
  b.text(
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nproperty uchar flags\nelement face 1\nproperty list uchar uint vertex_index\n"
      "element material 1\nproperty float shine\nend_header\n");
  b.be(0.0).be(0.0).be(0.0).be(uint8_t{1});
  b.be(2.0).be(0.0).be(0.0).be(uint8_t{1});
  b.be(0.0).be(3.0).be(1e-9).be(uint8_t{1});
  b.be(uint8_t{3}).be(uint32_t{0}).be(uint32_t{1}).be(uint32_t{2});
  // The trailing "material" element is missing entirely: not needed, not an error.
  const Mesh mesh = readMesh(write("be.ply", b.data));
  ASSERT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(mesh.vertices[2], Vec3(0, 3, 1e-9));
  EXPECT_DOUBLE_EQ(meshArea(mesh), 3.0);
}

TEST_F(MeshIoTest, PlyErrors) {
  const std::string vertices3 =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  EXPECT_READ_ERROR(write("noface.ply", vertices3 + "end_header\n0 0 0\n1 0 0\n0 1 0\n"),
                    "line 7: PLY header has no 'element face' (a point cloud, not a mesh)");
  const std::string header = vertices3 + "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_READ_ERROR(write("range.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                    "line 13: vertex index 3 out of range (3 vertices)");
  EXPECT_READ_ERROR(write("negative.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
                    "line 13: vertex index -1 out of range (3 vertices)");
  EXPECT_READ_ERROR(write("two.ply", header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                    "line 13: face with 2 vertices (need at least 3)");
  EXPECT_READ_ERROR(write("short.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
                    "line 13: too few values for list property 'vertex_indices'");
  EXPECT_READ_ERROR(write("nan.ply", header + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                    "line 11: non-finite vertex coordinate 'nan'");
  EXPECT_READ_ERROR(write("abc.ply", header + "0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n"), "line 11: non-numeric value 'abc'");
  EXPECT_READ_ERROR(write("trunc.ply", header + "0 0 0\n1 0 0\n0 1 0\n"),
                    "line 13: truncated data (expected 1 faces, got 0)");
  EXPECT_READ_ERROR(write("zero.ply", vertices3 + "element face 0\nproperty list uchar int vertex_indices\n"
                                                  "end_header\n0 0 0\n1 0 0\n0 1 0\n"),
                    "no triangles");
  EXPECT_READ_ERROR(write("floatidx.ply", vertices3 + "element face 1\nproperty list uchar float vertex_indices\n"
                                                      "end_header\n"),
                    "line 8: face vertex indices must have an integer type");
  EXPECT_READ_ERROR(write("nolist.ply", vertices3 + "element face 1\nproperty int flags\nend_header\n"),
                    "line 7: PLY face element has no 'vertex_indices' list");
  EXPECT_READ_ERROR(write("magic.ply", "solid x\n"), "line 1: not a PLY file (missing 'ply' magic)");

  const std::string binary_header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  Bytes range;
  range.text(binary_header);
  for (int i = 0; i < 9; ++i) range.le(static_cast<float>(i));
  range.le(uint8_t{3}).le(int32_t{0}).le(int32_t{1}).le(int32_t{2});
  range.le(uint8_t{3}).le(int32_t{0}).le(int32_t{7}).le(int32_t{2});
  EXPECT_READ_ERROR(write("range_bin.ply", range.data), "byte " + std::to_string(binary_header.size() + 36 + 13 + 5) +
                                                            ": vertex index 7 out of range (3 vertices)");

  Bytes trunc;
  trunc.text(binary_header);
  for (int i = 0; i < 9; ++i) trunc.le(static_cast<float>(i));
  trunc.le(uint8_t{3}).le(int32_t{0}).le(int32_t{1}).le(int32_t{2});
  trunc.le(uint8_t{3}).le(int32_t{0});
  EXPECT_READ_ERROR(write("trunc_bin.ply", trunc.data),
                    "byte " + std::to_string(trunc.data.size()) + ": truncated data (expected 2 faces, got 1)");

  Bytes inf;
  inf.text(binary_header);
  for (int i = 0; i < 9; ++i) inf.le(i == 4 ? std::numeric_limits<float>::infinity() : 1.f);
  EXPECT_READ_ERROR(write("inf_bin.ply", inf.data), "byte " + std::to_string(binary_header.size() + 16) +
                                                        ": non-finite vertex coordinate (y of vertex 1)");
}

// ---------------------------------------------------------------------------
// OBJ

TEST_F(MeshIoTest, ObjCornerFormsNegativeIndicesAndPolygons) {
  const Mesh mesh =
      readMesh(write("forms.obj",
                     "# exported\nmtllib sail.mtl\no jib\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0 0.5 0.5 0.5\n"
                     "vt 0 0\nvn 0 0 1\ng panel\nusemtl cloth\ns off\n"
                     "f 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -3 -2/1\nl 1 2\n\nf 1 3 5\nv 0.5 0.5 1\n"));
  ASSERT_EQ(mesh.vertices.size(), 5u);
  ASSERT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(mesh.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(mesh.triangles[2], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[3], (std::array<uint32_t, 3>{0, 2, 4}));
}

TEST_F(MeshIoTest, ObjErrors) {
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
  EXPECT_READ_ERROR(write("range.obj", square + "f 1 2 4\n"), "line 4: vertex index 4 out of range (3 vertices)");
  EXPECT_READ_ERROR(write("negative.obj", square + "f -1 -2 -4\n"),
                    "line 4: vertex index -4 out of range (3 vertices)");
  EXPECT_READ_ERROR(write("zero.obj", square + "f 0 1 2\n"), "line 4: vertex index 0 (OBJ indices start at 1)");
  EXPECT_READ_ERROR(write("bad.obj", square + "f 1 2 x/1\n"), "line 4: invalid vertex index 'x/1'");
  EXPECT_READ_ERROR(write("two.obj", square + "f 1 2\n"), "line 4: face with 2 vertices (need at least 3)");
  EXPECT_READ_ERROR(write("coords.obj", "v 0 0\n"), "line 1: expected 3 coordinates, got 2");
  EXPECT_READ_ERROR(write("abc.obj", "v 0 0 0\nv 0 abc 0\n"), "line 2: non-numeric value 'abc'");
  EXPECT_READ_ERROR(write("inf.obj", "v 0 0 inf\n"), "line 1: non-finite vertex coordinate 'inf'");
  EXPECT_READ_ERROR(write("forward.obj", square + "f 1 2 5\nv 2 2 2\n"),
                    "line 4: vertex index 5 out of range (4 vertices)");
  EXPECT_READ_ERROR(write("points.obj", square), "no triangles");
}

// ---------------------------------------------------------------------------
// STL

// Two triangles sharing an edge, with -0 and +0 in the shared corner.
Bytes twoTriangleStl(const std::string& header80) {
  Bytes b;
  std::string header = header80;
  header.resize(80, ' ');
  b.text(header).le(uint32_t{2});
  const float tris[2][3][3] = {{{-0.f, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  for (const auto& tri : tris) {
    b.le(0.f).le(0.f).le(1.f);
    for (const auto& corner : tri) b.le(corner[0]).le(corner[1]).le(corner[2]);
    b.le(uint16_t{0});
  }
  return b;
}

TEST_F(MeshIoTest, StlBinaryStartingWithSolidIsReadAsBinaryAndMerged) {
  const Mesh mesh = readMesh(write("solid.stl", twoTriangleStl("solid exported by a CAD tool").data));
  EXPECT_EQ(mesh.vertices.size(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_DOUBLE_EQ(meshArea(mesh), 1.0);
}

TEST_F(MeshIoTest, StlAsciiMergesSharedCorners) {
  const Mesh mesh = readMesh(write("a.stl",
                                   "solid panel\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                                   "   vertex 1 1 0\n  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n"
                                   "   vertex 0 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\n"
                                   "endsolid panel\n"));
  EXPECT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_DOUBLE_EQ(meshArea(mesh), 1.0);
}

TEST_F(MeshIoTest, StlErrors) {
  const Bytes full = twoTriangleStl("binary");
  EXPECT_READ_ERROR(write("trunc.stl", full.data.substr(0, full.data.size() - 10)),
                    "byte " + std::to_string(full.data.size() - 10) + ": truncated data (expected 2 triangles, got 1)");
  EXPECT_READ_ERROR(write("tiny.stl", "binary"), "byte 6: truncated STL header");
  Bytes nan = full;
  const float bad = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan.data[84 + 50 + 12 + 12 + 4], &bad, 4);
  EXPECT_READ_ERROR(write("nan.stl", nan.data), "byte 162: non-finite vertex coordinate (triangle 1)");
  Bytes empty;
  empty.text(std::string(80, ' ')).le(uint32_t{0});
  EXPECT_READ_ERROR(write("empty.stl", empty.data), "no triangles");

  const std::string facet = "solid s\n facet normal 0 0 1\n  outer loop\n";
  EXPECT_READ_ERROR(write("abc.stl", facet + "   vertex 0 0 abc\n"), "line 4: non-numeric value 'abc'");
  EXPECT_READ_ERROR(write("coords.stl", facet + "   vertex 0 0\n"), "line 4: expected 3 coordinates, got 2");
  EXPECT_READ_ERROR(write("two.stl", facet + "   vertex 0 0 0\n   vertex 1 0 0\n  endloop\n"),
                    "line 6: face with 2 vertices (need at least 3)");
  EXPECT_READ_ERROR(write("open.stl", facet + "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n  endloop\n"),
                    "line 7: truncated data (facet of line 2 not closed)");
  EXPECT_READ_ERROR(write("keyword.stl", facet + "   vertx 0 0 0\n"), "line 4: unknown STL keyword 'vertx'");
  EXPECT_READ_ERROR(write("outside.stl", "solid s\n facet normal 0 0 1\n   vertex 0 0 0\n"),
                    "line 3: 'vertex' outside a loop");
  EXPECT_READ_ERROR(write("nofacets.stl", "solid s\nendsolid s\n"), "no triangles");
}

// ---------------------------------------------------------------------------
// meshArea / triangleNormal (analysis/mesh.hpp), which the STL writer uses for facet normals

TEST(MeshGeometry, AreaAndNormals) {
  const Mesh mesh{{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 3, 0), Vec3(4, 0, 0)}, {{0, 1, 2}, {0, 2, 1}, {0, 1, 3}}};
  EXPECT_DOUBLE_EQ(meshArea(mesh), 6.0);
  EXPECT_EQ(triangleNormal(mesh, 0), Vec3(0, 0, 1));
  EXPECT_EQ(triangleNormal(mesh, 1), Vec3(0, 0, -1));
  EXPECT_EQ(triangleNormal(mesh, 2), Vec3::Zero());  // collinear corners
  const Mesh sail = makeSailPanel();
  for (size_t t = 0; t < sail.triangles.size(); ++t) EXPECT_NEAR(triangleNormal(sail, t).norm(), 1.0, 1e-12);
}

TEST(MeshGeometry, RejectsBadIndices) {
  const Mesh mesh{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}, {0, 1, 5}}};
  try {
    triangleNormal(mesh, 2);
    ADD_FAILURE() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[triangleNormal] triangle 2 out of range (mesh has 2 triangles)");
  }
  EXPECT_THROW(triangleNormal(mesh, 2), InvalidInput);
  EXPECT_THROW(triangleNormal(mesh, 1), InvalidInput);
  try {
    meshArea(mesh);
    ADD_FAILURE() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[meshArea] triangle 1 has vertex index 5 (mesh has 3 vertices)");
  }
  EXPECT_THROW(meshArea(mesh), InvalidInput);
}

}  // namespace
}  // namespace sailshape
