#include "analysis/io/design_import.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/io/mesh_io.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;

class DesignImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    dir_ = fs::temp_directory_path() / ("sailshape_design_import_" + std::string(::testing::UnitTest::GetInstance()
                                                                                       ->current_test_info()
                                                                                       ->name()) +
                                        "_" + std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& content) const {
    const std::string p = (dir_ / name).string();
    std::ofstream out(p, std::ios::binary);
    out << content;
    return p;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// One 3DFACE entity as Sailcut writes it: group code and value on alternate lines.
std::string face(const std::string& layer, const std::vector<Vec3>& corners) {
  std::string s = "0\n3DFACE\n8\n" + layer + "\n";
  for (size_t c = 0; c < corners.size(); ++c)
    for (int a = 0; a < 3; ++a) s += std::to_string((a + 1) * 10 + static_cast<int>(c)) + "\n" + std::to_string(corners[c][a]) + "\n";
  return s;
}

std::string dxf(const std::string& entities) {
  return "999\nwritten by a test\n0\nSECTION\n2\nHEADER\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n" + entities +
         "0\nENDSEC\n0\nEOF\n";
}

bool hasNote(const DesignImport& r, const std::string& part) {
  return std::any_of(r.notes.begin(), r.notes.end(), [&](const std::string& n) { return n.find(part) != std::string::npos; });
}

// ---------------------------------------------------------------------------
// DXF 3DFACE

TEST_F(DesignImportTest, DxfTrianglesAndQuadsImportToTheExpectedTriangles) {
  // A triangle (4th corner = 3rd), and a quad sharing the edge (1,0,0)–(1,1,0).
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(2, 0, 0.5), e(2, 1, 0.25);
  const std::string p = write("panel.dxf", dxf(face("1", {a, b, c, c}) + face("2", {b, d, e, c})));
  size_t faces = 0;
  const Mesh mesh = readDxf3dFaces(p, &faces);
  EXPECT_EQ(faces, 2u);
  ASSERT_EQ(mesh.vertices.size(), 5u);  // b and c shared
  ASSERT_EQ(mesh.triangles.size(), 3u);
  const std::vector<std::array<Vec3, 3>> expected{{a, b, c}, {b, d, e}, {b, e, c}};
  for (size_t t = 0; t < 3; ++t)
    for (size_t k = 0; k < 3; ++k)
      EXPECT_EQ(mesh.vertices[mesh.triangles[t][k]], expected[t][k]) << "triangle " << t << " corner " << k;
  EXPECT_NEAR(meshArea(mesh), 0.5 + (0.5 * ((d - b).cross(e - b)).norm() + 0.5 * ((e - b).cross(c - b)).norm()), 1e-12);
}

TEST_F(DesignImportTest, DxfInBoatAxesAndMetresIsTakenAsIs) {
  const std::string p = write("m.dxf", dxf(face("0", {Vec3(0, 0, 0), Vec3(-3, 0.2, 0), Vec3(0, 0, 9), Vec3(0, 0, 9)})));
  DesignImportOptions o;
  o.unit = "m";
  o.axes = "boat";
  const DesignImport r = importDesign(p, o);
  EXPECT_EQ(r.format, "dxf");
  EXPECT_EQ(r.unit, "m");
  EXPECT_EQ(r.axes, "boat");
  ASSERT_EQ(r.mesh.vertices.size(), 3u);
  EXPECT_EQ(r.mesh.vertices[1], Vec3(-3, 0.2, 0));
  EXPECT_TRUE(hasNote(r, "unit: metres (given)"));
  EXPECT_TRUE(hasNote(r, "axes: boat"));
}

TEST_F(DesignImportTest, DxfAutoDetectsMillimetresAndSailcutAxes) {
  // Sailcut frame, mm: tack at the origin, clew 370 along +X, head 1050 up (+Y), depth +Z.
  const Vec3 tack(0, 0, 0), clew(370, 0, 0), head(100, 1050, 0), belly(150, 500, 40);
  const std::string p = write("sc.dxf", dxf(face("1", {tack, clew, belly, belly}) + face("1", {clew, head, belly, belly}) +
                                            face("1", {head, tack, belly, belly})));
  const DesignImport r = importDesign(p);
  EXPECT_EQ(r.unit, "mm");
  EXPECT_EQ(r.axes, "sailcut");
  EXPECT_TRUE(hasNote(r, "unit: millimetres (detected: largest extent 1050 > 100)"));
  EXPECT_TRUE(hasNote(r, "axes: sailcut"));
  ASSERT_EQ(r.mesh.vertices.size(), 4u);
  // Boat frame: X = −x, Y = z, Z = y, metres: the tack is forward of the clew, the head up, the belly to port.
  EXPECT_EQ(r.mesh.vertices[0], Vec3(0, 0, 0));
  EXPECT_NEAR((r.mesh.vertices[1] - Vec3(-0.370, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((r.mesh.vertices[2] - Vec3(-0.150, 0.040, 0.500)).norm(), 0, 1e-15);
  EXPECT_NEAR((r.mesh.vertices[3] - Vec3(-0.100, 0, 1.050)).norm(), 0, 1e-15);
  EXPECT_GT(r.mesh.vertices[0].x(), r.mesh.vertices[1].x());
  // The mapping is a rotation: areas are kept (scaled by mm → m).
  const Mesh raw = readDxf3dFaces(p);
  EXPECT_NEAR(meshArea(r.mesh), meshArea(raw) * 1e-6, 1e-12);

  DesignImportOptions cm;
  cm.unit = "cm";
  EXPECT_NEAR(importDesign(p, cm).mesh.vertices[3].z(), 10.50, 1e-12);
}

TEST_F(DesignImportTest, DxfDegenerateFacesAreDroppedWithANote) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const std::string p = write("deg.dxf", dxf(face("1", {a, b, c, c}) + face("1", {a, a, b, b})));
  const DesignImport r = importDesign(p);
  EXPECT_EQ(r.faces_read, 2u);
  EXPECT_EQ(r.mesh.triangles.size(), 1u);
  EXPECT_TRUE(hasNote(r, "dropped 1 degenerate"));
}

TEST_F(DesignImportTest, DxfErrorsNameTheFileAndTheProblem) {
  const std::string binary = write("bin.dxf", std::string("AutoCAD Binary DXF\r\n\x1a\0", 22) + "junk");
  expectFileError([&] { readDxf3dFaces(binary); }, binary + ": ", {"binary DXF"});

  const std::string lines_only = write("lines.dxf", dxf("0\nLINE\n8\n0\n10\n0\n20\n0\n30\n0\n11\n1\n21\n1\n31\n1\n"));
  expectFileError([&] { importDesign(lines_only); }, lines_only + ": ", {"no 3DFACE", "LINE"});

  const std::string empty = write("empty.dxf", "");
  expectFileError([&] { readDxf3dFaces(empty); }, empty + ": ", {"no 3DFACE"});

  // The file stops after corner 2's y; line 14 holds "3DFACE".
  std::string text = dxf(face("1", {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 0)}));
  const std::string head = text.substr(0, text.find("31\n"));
  const std::string truncated = write("trunc.dxf", head);
  expectFileError([&] { readDxf3dFaces(truncated); }, truncated + ": line 14: ", {"truncated 3DFACE", "group 31"});

  const std::string partial4 = write("partial4.dxf", dxf("0\n3DFACE\n10\n0\n20\n0\n30\n0\n11\n1\n21\n0\n31\n0\n12\n0\n"
                                                         "22\n1\n32\n0\n13\n5\n"));
  expectFileError([&] { readDxf3dFaces(partial4); }, partial4 + ": line 14: ", {"corner 4"});

  std::string bad = text;
  bad.replace(bad.find("21\n0.000000"), 11, "21\n0.0x0000");
  const std::string non_numeric = write("nan.dxf", bad);
  // Line 26 holds group 21's value.
  expectFileError([&] { readDxf3dFaces(non_numeric); }, non_numeric + ": line 26: ", {"non-numeric", "0.0x0000"});

  const std::string bad_code = write("code.dxf", "0\nSECTION\nTWO\nENTITIES\n");
  expectFileError([&] { readDxf3dFaces(bad_code); }, bad_code + ": line 3: ", {"group code", "TWO"});

  const std::string no_value = write("novalue.dxf", "0\nSECTION\n2\n");
  expectFileError([&] { readDxf3dFaces(no_value); }, no_value + ": line 3: ", {"truncated", "no value"});

  const std::string missing = path("missing.dxf");
  expectFileError([&] { importDesign(missing); }, missing + ": ", {});
}

TEST_F(DesignImportTest, RejectsUnknownExtensionAndOptions) {
  const std::string p = write("sail.igs", "whatever");
  expectFileError([&] { importDesign(p); }, p + ": ", {"unsupported", ".igs"});
  const std::string ok = write("ok.dxf", dxf(face("1", {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)})));
  DesignImportOptions unit;
  unit.unit = "inch";
  expectInvalidInput([&] { importDesign(ok, unit); }, {"[importDesign]", "unit", "inch"});
  DesignImportOptions axes;
  axes.axes = "z-up";
  expectInvalidInput([&] { importDesign(ok, axes); }, {"[importDesign]", "axes", "z-up"});
}

// ---------------------------------------------------------------------------
// Meshes: export → import round trips, and frame detection

class DesignRoundTrip : public DesignImportTest, public ::testing::WithParamInterface<std::pair<MeshFormat, const char*>> {};

TEST_P(DesignRoundTrip, GeneratedDesignComesBackToAMicrometre) {
  for (SailType type : {SailType::Main, SailType::SquareTopMain, SailType::Jib, SailType::Gennaker}) {
    SCOPED_TRACE(sailTypeName(type));
    const Mesh mesh = generateSailMesh(exampleDesign(type), 40, 20);
    const std::string p = path(std::string("design") + GetParam().second);
    writeMesh(p, mesh, GetParam().first);
    const DesignImport r = importDesign(p);  // auto: metres, boat frame
    EXPECT_EQ(r.unit, "m");
    EXPECT_EQ(r.axes, "boat");
    ASSERT_EQ(r.mesh.triangles.size(), mesh.triangles.size());
    ASSERT_EQ(r.mesh.vertices.size(), mesh.vertices.size());
    double worst = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (size_t k = 0; k < 3; ++k)
        worst = std::max(worst, (mesh.vertices[mesh.triangles[t][k]] - r.mesh.vertices[r.mesh.triangles[t][k]])
                                    .cwiseAbs()
                                    .maxCoeff());
    EXPECT_LE(worst, 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, DesignRoundTrip,
                         ::testing::Values(std::make_pair(MeshFormat::Obj, ".obj"),
                                           std::make_pair(MeshFormat::StlBinary, ".stl"),
                                           std::make_pair(MeshFormat::StlAscii, ".stl"),
                                           std::make_pair(MeshFormat::PlyBinary, ".ply"),
                                           std::make_pair(MeshFormat::PlyAscii, ".ply")));

TEST_F(DesignImportTest, YUpMeshIsDetectedAndRotatedIntoTheBoatFrame) {
  // The generated main turned into a Y-up file in millimetres: (x, y, z)_file = 1000 (−X, Z, Y).
  const Mesh boat = generateSailMesh(exampleDesign(SailType::Main), 30, 15);
  Mesh file = boat;
  for (Vec3& v : file.vertices) v = 1000.0 * Vec3(-v.x(), v.z(), v.y());
  const std::string p = path("yup.obj");
  writeMesh(p, file);
  const DesignImport r = importDesign(p);
  EXPECT_EQ(r.unit, "mm");
  EXPECT_EQ(r.axes, "sailcut");
  EXPECT_TRUE(hasNote(r, "Y-up"));
  ASSERT_EQ(r.mesh.vertices.size(), boat.vertices.size());
  for (size_t i = 0; i < boat.vertices.size(); ++i) ASSERT_LE((r.mesh.vertices[i] - boat.vertices[i]).norm(), 1e-9);
}

// ---------------------------------------------------------------------------
// The real Sailcut export (Star45-JIB.dxf, defined by Star45-JIB.xml: luff 1050,
// foot 370, leech 940 mm, depth 5 % at the middle profile, 40 % height).

TEST(DesignImportSailcut, Star45JibImportsInMetresInTheBoatFrame) {
  const std::string p = std::string(SAILSHAPE_SHARED) + "/sailcut-examples/Star45-JIB.dxf";
  const DesignImport r = importDesign(p);
  EXPECT_EQ(r.faces_read, 260u);
  EXPECT_EQ(r.mesh.triangles.size(), 260u);
  EXPECT_EQ(r.mesh.vertices.size(), 186u);
  EXPECT_EQ(r.unit, "mm");
  EXPECT_EQ(r.axes, "sailcut");

  SectionParams at;
  at.fractions = {0.4, 0.5};  // the middle profile stands at 40 % height
  const MeshSections a = analyzeMeshSections(r.mesh, {}, at);
  EXPECT_TRUE(a.resampled);  // 130 boundary edges: too coarse to find edges and corners on as it is
  const SailOutline& o = a.outline;
  // Boat frame: head above the tack, the clew aft of the tack.
  EXPECT_GT(o.head.z() - o.tack.z(), 1.0);
  EXPECT_LT(o.clew.x(), o.tack.x() - 0.3);
  // The definition's lengths are straight corner to corner (the file's own corner
  // vertices are 1050.4, 370.0 and 940.0 mm apart). The head is a 20° point whose
  // corner, placed where the fitted luff and leech meet, stands ~4 mm high.
  EXPECT_NEAR((o.head - o.tack).norm(), 1.050, 0.005);
  EXPECT_NEAR((o.clew - o.tack).norm(), 0.370, 0.005);
  EXPECT_NEAR((o.head - o.clew).norm(), 0.940, 0.005);
  // Along the edges: luff round 2 mm, leech and foot round 13 mm add under 1 mm.
  EXPECT_NEAR(o.luff_length_m, 1.050, 0.006);
  EXPECT_NEAR(o.foot_length_m, 0.370, 0.006);
  EXPECT_NEAR(o.leech_length_m, 0.940, 0.008);
  // Sailcut's mould gives depth 5.00 % at 40 % height and 5.03 % at 50 % of the chord
  // between its straight edges; the leech round (13 mm at 55 %) lengthens the real
  // chord by ~5 % there, so a horizontal cut measures ~4.8 % and the SPEC §5 plane,
  // tilted to hold the surface normal, 4.5 %.
  ASSERT_EQ(a.sections.sections.size(), 2u);
  EXPECT_NEAR(a.sections.sections[0].value.camber_pct, 5.0, 0.6);
  EXPECT_NEAR(a.sections.sections[1].value.camber_pct, 5.0, 0.6);
}

}  // namespace
}  // namespace sailshape
