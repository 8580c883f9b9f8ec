#include "analysis/io/cloud_io.hpp"

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
#include <random>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// readCloud(path) must fail with "<path>: ..." containing every part.
#define EXPECT_READ_ERROR(path, ...)                                                           \
  do {                                                                                         \
    SCOPED_TRACE("readCloud(" + std::string(path) + ")");                                      \
    const std::string p_ = (path);                                                             \
    expectFileError([&] { readCloud(p_); }, p_ + ": ", std::vector<std::string>{__VA_ARGS__}); \
  } while (0)

// Binary payloads for hand-made files.
struct Bytes {
  std::string data;
  template <typename T>
  Bytes& le(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    data.append(b, sizeof(T));  // tests run on little-endian hosts (x86, ARM)
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

// A scan-like cloud: points over a 10 m sail with sub-nanometre detail, scanner angles, intensities.
Cloud makeCloud(size_t n, bool attributes, unsigned seed = 42) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(-2.0, 12.0);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::uniform_real_distribution<float> rssi(0.0f, 255.0f);
  Cloud cloud;
  for (size_t i = 0; i < n; ++i) {
    cloud.points.emplace_back(coord(rng) + 1e-10 * static_cast<double>(i), coord(rng), coord(rng));
    if (attributes) {
      cloud.intensity.push_back(rssi(rng));
      cloud.alpha_rad.push_back(angle(rng));
      cloud.beta_rad.push_back(angle(rng));
    }
  }
  if (attributes) cloud.viewpoint = Vec3(0.125, -1.3333333333333333, 2.000000001);
  return cloud;
}

void expectSameCloud(const Cloud& expected, const Cloud& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  // Binary formats store float64 and text is written in shortest round-trip form: exact.
  for (size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(expected.points[i][k], actual.points[i][k]) << "point " << i;
  EXPECT_EQ(expected.intensity, actual.intensity);
  EXPECT_EQ(expected.alpha_rad, actual.alpha_rad);
  EXPECT_EQ(expected.beta_rad, actual.beta_rad);
  ASSERT_EQ(expected.viewpoint.has_value(), actual.viewpoint.has_value());
  if (expected.viewpoint) {
    EXPECT_EQ(*expected.viewpoint, *actual.viewpoint);
  }
}

class CloudIoTest : public ::testing::Test {
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

  fs::path dir_;
};

// ---------------------------------------------------------------------------
// Round trips

struct FormatCase {
  CloudFormat format;
  const char* file;
  const char* read_as;
};

class CloudRoundTrip : public CloudIoTest, public ::testing::WithParamInterface<FormatCase> {};

TEST_P(CloudRoundTrip, KeepsCoordinatesAttributesAndViewpoint) {
  const Cloud cloud = makeCloud(500, true);
  const std::string p = path(GetParam().file);
  writeCloud(p, cloud, GetParam().format);
  const CloudReadResult r = readCloud(p);
  EXPECT_EQ(r.format, GetParam().read_as);
  EXPECT_EQ(r.dropped_nan_points, 0u);
  EXPECT_TRUE(r.warnings.empty());
  expectSameCloud(cloud, r.cloud);
}

TEST_P(CloudRoundTrip, BareCloudStaysBare) {
  const Cloud cloud = makeCloud(50, false);
  const std::string p = path(GetParam().file);
  writeCloud(p, cloud, GetParam().format);
  const CloudReadResult r = readCloud(p);
  expectSameCloud(cloud, r.cloud);
  EXPECT_FALSE(r.cloud.hasIntensity());
  EXPECT_FALSE(r.cloud.viewpoint.has_value());
}

TEST_P(CloudRoundTrip, IntensityOnly) {
  Cloud cloud = makeCloud(50, true);
  cloud.alpha_rad.clear();
  cloud.beta_rad.clear();
  const std::string p = path(GetParam().file);
  writeCloud(p, cloud, GetParam().format);
  expectSameCloud(cloud, readCloud(p).cloud);
}

INSTANTIATE_TEST_SUITE_P(AllFormats, CloudRoundTrip,
                         ::testing::Values(FormatCase{CloudFormat::PlyAscii, "c.ply", "ply-ascii"},
                                           FormatCase{CloudFormat::PlyBinary, "c.ply", "ply-binary"},
                                           FormatCase{CloudFormat::PcdAscii, "c.pcd", "pcd-ascii"},
                                           FormatCase{CloudFormat::PcdBinary, "c.pcd", "pcd-binary"},
                                           FormatCase{CloudFormat::Xyz, "c.xyz", "xyz"},
                                           FormatCase{CloudFormat::Xyz, "c.txt", "xyz"},
                                           FormatCase{CloudFormat::Csv, "c.csv", "csv"}),
                         [](const auto& info) {
                           std::string name = info.param.file;
                           name[1] = '_';
                           return name + "_" + info.param.read_as[0] + std::to_string(info.index);
                         });

TEST_F(CloudIoTest, AutoFormatFollowsExtension) {
  const Cloud cloud = makeCloud(20, true);
  const std::pair<const char*, const char*> cases[] = {{"a.ply", "ply-binary"}, {"a.PLY", "ply-binary"},
                                                       {"a.pcd", "pcd-binary"}, {"a.csv", "csv"},
                                                       {"a.xyz", "xyz"},        {"a.txt", "xyz"}};
  for (const auto& [file, format] : cases) {
    writeCloud(path(file), cloud);
    const CloudReadResult r = readCloud(path(file));
    EXPECT_EQ(r.format, format) << file;
    expectSameCloud(cloud, r.cloud);
  }
}

TEST_F(CloudIoTest, IdentityPcdViewpointMeansNoViewpoint) {
  const Cloud cloud = makeCloud(5, false);
  writeCloud(path("a.pcd"), cloud, CloudFormat::PcdAscii);
  std::ifstream in(path("a.pcd"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("VIEWPOINT 0 0 0 1 0 0 0"), std::string::npos);
  EXPECT_FALSE(readCloud(path("a.pcd")).cloud.viewpoint.has_value());
}

TEST_F(CloudIoTest, WriteRejectsBadInput) {
  const Cloud cloud = makeCloud(5, true);
  expectFileError([&] { writeCloud(path("c.foo"), cloud); }, path("c.foo") + ": ",
                  {"unknown cloud file extension '.foo' (expected .ply .pcd .xyz .txt .csv)"});
  expectFileError([&] { writeCloud((dir_ / "no" / "such" / "dir.ply").string(), cloud); },
                  (dir_ / "no" / "such" / "dir.ply").string() + ": ", {"cannot open file for writing"});

  Cloud bad = cloud;
  bad.intensity.pop_back();
  try {
    writeCloud(path("bad.ply"), bad);
    ADD_FAILURE() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[writeCloud] intensity has 4 values for 5 points");
  }
  EXPECT_THROW(writeCloud(path("bad.ply"), bad), InvalidInput);
}

// ---------------------------------------------------------------------------
// Files that cannot be read at all

TEST_F(CloudIoTest, MissingFileAndUnknownExtension) {
  EXPECT_READ_ERROR(path("missing.ply"), "cannot open file");
  const std::string foo = write("c.foo", "1 2 3\n");
  expectFileError([&] { readCloud(foo); },
                  foo + ": unknown cloud file extension '.foo' (expected .ply .pcd .xyz .txt .csv)", {});
  fs::create_directories(path("dir.ply"));
  EXPECT_READ_ERROR(path("dir.ply"), "cannot open file");
}

// ---------------------------------------------------------------------------
// PLY

TEST_F(CloudIoTest, PlyBigEndianWithMixedTypes) {
  Bytes b;
  b.text(
      "ply\nformat binary_big_endian 1.0\ncomment from a scanner\ncomment viewpoint 1.5 -2 3\n"
      "element vertex 2\nproperty float32 x\nproperty float64 y\nproperty int16 z\n"
      "property uint8 reflectance\nproperty ushort ring\nend_header\n");
  b.be(1.25f).be(-2.5).be(int16_t{-7}).be(uint8_t{200}).be(uint16_t{3});
  b.be(0.5f).be(1e-9).be(int16_t{-170}).be(uint8_t{1}).be(uint16_t{4});
  const CloudReadResult r = readCloud(write("be.ply", b.data));
  EXPECT_EQ(r.format, "ply-binary");
  ASSERT_EQ(r.cloud.size(), 2u);
  EXPECT_EQ(r.cloud.points[0], Vec3(1.25, -2.5, -7));
  EXPECT_EQ(r.cloud.points[1], Vec3(0.5, 1e-9, -170));  // two bytes, sign-extended
  EXPECT_EQ(r.cloud.intensity, (std::vector<float>{200, 1}));
  EXPECT_FALSE(r.cloud.hasScanAngles());
  ASSERT_TRUE(r.cloud.viewpoint.has_value());
  EXPECT_EQ(*r.cloud.viewpoint, Vec3(1.5, -2, 3));
}

// A sweep's lost scan lines (Cloud::lost_beta_rad) travel with its PLY: ten to a
// comment line, exactly; a comment that is not a list of numbers is only a comment.
TEST_F(CloudIoTest, PlyKeepsTheSweepsLostScanLines) {
  Cloud cloud = makeCloud(20, true);
  for (int k = 0; k < 23; ++k) cloud.lost_beta_rad.push_back(-0.25 + 0.0058177641733144 * k + 1e-13 * k);
  for (const CloudFormat f : {CloudFormat::PlyAscii, CloudFormat::PlyBinary}) {
    const std::string p = path(f == CloudFormat::PlyAscii ? "a.ply" : "b.ply");
    writeCloud(p, cloud, f);
    const CloudReadResult r = readCloud(p);
    expectSameCloud(cloud, r.cloud);
    EXPECT_EQ(r.cloud.lost_beta_rad, cloud.lost_beta_rad);
    // And a crop keeps them: they say where the sweep has no line, whatever is cut.
    EXPECT_EQ(selectPoints(r.cloud, {3, 4}).lost_beta_rad, cloud.lost_beta_rad);
  }
  const CloudReadResult r = readCloud(
      write("odd.ply", "ply\nformat ascii 1.0\ncomment lost_beta_rad 0.1 lots\ncomment lost_beta_rad 0.2\n"
                       "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n1 2 3\n"));
  EXPECT_EQ(r.cloud.lost_beta_rad, (std::vector<double>{0.2}));
}

// The scanner's range travels with sailshape's PLY (a scan that stops at it ran out of
// range there), through a crop too; a malformed comment is only a comment.
TEST_F(CloudIoTest, PlyKeepsTheScannersRange) {
  Cloud cloud = makeCloud(20, true);
  cloud.scanner_range_m = 20.0;  // an LMS111 (SPEC §3)
  for (const CloudFormat f : {CloudFormat::PlyAscii, CloudFormat::PlyBinary}) {
    const std::string p = path(f == CloudFormat::PlyAscii ? "a.ply" : "b.ply");
    writeCloud(p, cloud, f);
    const CloudReadResult r = readCloud(p);
    EXPECT_EQ(r.cloud.scanner_range_m, 20.0);
    EXPECT_EQ(selectPoints(r.cloud, {3, 4}).scanner_range_m, 20.0);
  }
  cloud.scanner_range_m = 0;
  writeCloud(path("c.ply"), cloud);
  EXPECT_EQ(readCloud(path("c.ply")).cloud.scanner_range_m, 0.0);
  const CloudReadResult odd = readCloud(
      write("odd.ply", "ply\nformat ascii 1.0\ncomment scanner_range_m far\n"
                       "element vertex 1\nproperty double x\nproperty double y\nproperty double z\nend_header\n1 2 3\n"));
  EXPECT_EQ(odd.cloud.scanner_range_m, 0.0);
}

TEST_F(CloudIoTest, PlyAllScalarTypeNames) {
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
      "property char a\nproperty uchar b\nproperty short c\nproperty ushort d\nproperty int e\n"
      "property uint f\nproperty float x\nproperty double y\nproperty int8 g\nproperty uint8 h\n"
      "property int16 i\nproperty uint16 j\nproperty int32 z\nproperty uint32 k\nproperty float32 scalar_Intensity\n"
      "property float64 alpha_rad\nproperty double beta_rad\nend_header\n");
  b.le(int8_t{-1}).le(uint8_t{1}).le(int16_t{-2}).le(uint16_t{2}).le(int32_t{-3}).le(uint32_t{3});
  b.le(0.25f).le(0.125).le(int8_t{4}).le(uint8_t{5}).le(int16_t{6}).le(uint16_t{7}).le(int32_t{-8});
  b.le(uint32_t{9}).le(42.5f).le(0.75).le(-0.5);
  const CloudReadResult r = readCloud(write("types.ply", b.data));
  ASSERT_EQ(r.cloud.size(), 1u);
  EXPECT_EQ(r.cloud.points[0], Vec3(0.25, 0.125, -8));
  EXPECT_EQ(r.cloud.intensity, std::vector<float>{42.5f});
  EXPECT_EQ(r.cloud.alpha_rad, std::vector<double>{0.75});
  EXPECT_EQ(r.cloud.beta_rad, std::vector<double>{-0.5});
}

TEST_F(CloudIoTest, PlyBinaryFaceElementBeforeVerticesIsSkipped) {
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
      "property uchar flags\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n");
  b.le(uint8_t{3}).le(int32_t{0}).le(int32_t{1}).le(int32_t{2}).le(uint8_t{9});
  b.le(uint8_t{4}).le(int32_t{0}).le(int32_t{1}).le(int32_t{2}).le(int32_t{0}).le(uint8_t{9});
  for (int i = 0; i < 3; ++i) b.le(1.0 * i).le(2.0 * i).le(3.0 * i);
  b.le(int32_t{0}).le(int32_t{1});
  const CloudReadResult r = readCloud(write("faces.ply", b.data));
  ASSERT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.cloud.points[2], Vec3(2, 4, 6));
}

TEST_F(CloudIoTest, PlyAsciiWithFacesAfterVertices) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
      "property float intensity\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
      "0 0 0 10\r\n1 0 0 20\r\n+0.5 1e-3 -2 30\r\n3 0 1 2\r\n";
  const CloudReadResult r = readCloud(write("faces.ply", text));
  EXPECT_EQ(r.format, "ply-ascii");
  ASSERT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.cloud.points[2], Vec3(0.5, 1e-3, -2));
  EXPECT_EQ(r.cloud.intensity, (std::vector<float>{10, 20, 30}));
}

TEST_F(CloudIoTest, PlyBinaryNaNPointsAreDroppedWithWarning) {
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
      "property double z\nproperty float intensity\nend_header\n");
  const double xs[5][3] = {{1, 2, 3}, {kNaN, 0, 0}, {4, 5, 6}, {0, 0, kNaN}, {7, 8, 9}};
  for (int i = 0; i < 5; ++i) b.le(xs[i][0]).le(xs[i][1]).le(xs[i][2]).le(static_cast<float>(i));
  const CloudReadResult r = readCloud(write("nan.ply", b.data));
  ASSERT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.dropped_nan_points, 2u);
  EXPECT_EQ(r.warnings, std::vector<std::string>{"dropped 2 points with NaN coordinates"});
  EXPECT_EQ(r.cloud.points[1], Vec3(4, 5, 6));
  EXPECT_EQ(r.cloud.intensity, (std::vector<float>{0, 2, 4}));
}

TEST_F(CloudIoTest, PlyBinaryErrors) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n";

  Bytes truncated;
  truncated.text(header);
  for (int i = 0; i < 3 * 3 + 1; ++i) truncated.le(1.0);  // 3 vertices and a third of a fourth
  EXPECT_READ_ERROR(write("trunc.ply", truncated.data),
                    "byte " + std::to_string(truncated.data.size()) + ": truncated data (expected 10 vertices, got 3)");

  Bytes inf;
  inf.text(header);
  for (int i = 0; i < 10; ++i) inf.le(1.0).le(2.0).le(i == 2 ? kInf : 3.0);
  EXPECT_READ_ERROR(write("inf.ply", inf.data),
                    "byte " + std::to_string(header.size() + 2 * 24 + 16) + ": infinite coordinate (z of vertex 2)");

  Bytes all_nan;
  all_nan.text(header);
  for (int i = 0; i < 10; ++i) all_nan.le(kNaN).le(2.0).le(3.0);
  EXPECT_READ_ERROR(write("allnan.ply", all_nan.data), "no finite points (all 10 points have NaN coordinates)");

  Bytes face_first;
  face_first.text(
      "ply\nformat binary_little_endian 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  face_first.le(uint8_t{3}).le(int32_t{0}).le(int32_t{0});  // the first face's list ends early
  EXPECT_READ_ERROR(write("facetrunc.ply", face_first.data), "byte", "truncated data (expected 2 faces, got 0)");

  EXPECT_READ_ERROR(write("empty.ply",
                          "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n"),
                    "no points");
}

TEST_F(CloudIoTest, PlyHeaderErrors) {
  EXPECT_READ_ERROR(write("magic.ply", "pcd\nformat ascii 1.0\n"), "line 1: not a PLY file (missing 'ply' magic)");
  EXPECT_READ_ERROR(write("empty.ply", ""), "line 1: not a PLY file");
  EXPECT_READ_ERROR(write("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                    "line 2: unknown PLY format 'binary_middle_endian'");
  EXPECT_READ_ERROR(write("version.ply", "ply\nformat ascii 2.0\nend_header\n"),
                    "line 2: unsupported PLY version '2.0'");
  EXPECT_READ_ERROR(write("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty real y\n"),
                    "line 5: unknown PLY property type 'real'");
  EXPECT_READ_ERROR(write("listtype.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list float int v\n"),
                    "line 4: list count type must be an integer type");
  EXPECT_READ_ERROR(write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
                    "line 4: truncated PLY header (no 'end_header')");
  EXPECT_READ_ERROR(write("noformat.ply", "ply\nelement vertex 1\nend_header\n"),
                    "line 3: PLY header has no 'format' line");
  EXPECT_READ_ERROR(write("noelement.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
                    "line 3: property before any element");
  EXPECT_READ_ERROR(write("count.ply", "ply\nformat ascii 1.0\nelement vertex many\nend_header\n"),
                    "line 3: malformed element line");
  EXPECT_READ_ERROR(write("keyword.ply", "ply\nformat ascii 1.0\nelemnet vertex 1\nend_header\n"),
                    "line 3: unknown PLY header keyword 'elemnet'");
  EXPECT_READ_ERROR(write("novertex.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n"),
                    "line 4: PLY header has no 'element vertex'");
  EXPECT_READ_ERROR(write("noz.ply",
                          "ply\nformat ascii 1.0\ncomment x\nelement vertex 1\nproperty float x\n"
                          "property float y\nend_header\n0 0\n"),
                    "line 4: PLY vertex element has no 'z' property");
  EXPECT_READ_ERROR(write("listx.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\n"
                          "property float y\nproperty float z\nend_header\n"),
                    "line 4: vertex property 'x' is a list");
}

TEST_F(CloudIoTest, PlyAsciiErrors) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  EXPECT_READ_ERROR(write("abc.ply", header + "0 0 0\n1 abc 2\n"), "line 9: non-numeric value 'abc'");
  EXPECT_READ_ERROR(write("garbage.ply", header + "0 0 0\n1 2 1.5abc\n"), "line 9: non-numeric value '1.5abc'");
  EXPECT_READ_ERROR(write("count.ply", header + "0 0 0\n1 2\n"), "line 9: expected 3 values, got 2");
  EXPECT_READ_ERROR(write("extra.ply", header + "0 0 0 0\n"), "line 8: expected 3 values, got 4");
  EXPECT_READ_ERROR(write("trunc.ply", header + "0 0 0\n1 1 1\n"),
                    "line 10: truncated data (expected 3 vertices, got 2)");
  EXPECT_READ_ERROR(write("inf.ply", header + "0 0 0\n1 -inf 1\n2 2 2\n"), "line 9: infinite coordinate '-inf'");
  EXPECT_READ_ERROR(write("range.ply", header + "0 0 1e999\n"), "line 8: value out of range '1e999'");
  const CloudReadResult r = readCloud(write("nan.ply", header + "0 0 0\nnan 1 1\n2 2 NaN\n"));
  EXPECT_EQ(r.cloud.size(), 1u);
  EXPECT_EQ(r.dropped_nan_points, 2u);
}

// ---------------------------------------------------------------------------
// PCD

TEST_F(CloudIoTest, PcdAsciiLikePcl) {
  const std::string text =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb intensity normal\n"
      "SIZE 4 4 4 4 4 4\nTYPE F F F U F F\nCOUNT 1 1 1 1 1 3\nWIDTH 4\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS 4\nDATA ascii\n"
      "1 2 3 4278190080 7 0 0 1\nnan nan nan 0 0 0 0 1\n\n4.5 -5 6e-3 0 8 0 0 1\n7 8 9 0 9 0 0 1\n";
  const CloudReadResult r = readCloud(write("pcl.pcd", text));
  EXPECT_EQ(r.format, "pcd-ascii");
  ASSERT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.cloud.points[1], Vec3(4.5, -5, 6e-3));
  EXPECT_EQ(r.cloud.intensity, (std::vector<float>{7, 8, 9}));
  EXPECT_EQ(r.dropped_nan_points, 1u);
  EXPECT_EQ(r.warnings, std::vector<std::string>{"dropped 1 points with NaN coordinates"});
  EXPECT_FALSE(r.cloud.viewpoint.has_value());
}

TEST_F(CloudIoTest, PcdBinaryMixedTypesAndViewpoint) {
  Bytes b;
  b.text(
      "VERSION .7\nFIELDS ring x y z intensity\nSIZE 2 4 4 8 1\nTYPE U F F F U\nCOUNT 1 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nVIEWPOINT 1 2 3 0.7071 0 0 0.7071\nPOINTS 2\nDATA binary\n");
  b.le(uint16_t{1}).le(1.5f).le(2.5f).le(3.25).le(uint8_t{17});
  b.le(uint16_t{2}).le(-1.5f).le(0.f).le(kNaN).le(uint8_t{18});
  const CloudReadResult r = readCloud(write("mixed.pcd", b.data));
  EXPECT_EQ(r.format, "pcd-binary");
  ASSERT_EQ(r.cloud.size(), 1u);
  EXPECT_EQ(r.cloud.points[0], Vec3(1.5, 2.5, 3.25));
  EXPECT_EQ(r.cloud.intensity, std::vector<float>{17});
  EXPECT_EQ(r.dropped_nan_points, 1u);
  ASSERT_TRUE(r.cloud.viewpoint.has_value());
  EXPECT_EQ(*r.cloud.viewpoint, Vec3(1, 2, 3));
}

// Files written by PCL's own savePCDFileBinaryCompressed (tests/analysis/data/README.md).
std::string pclFile(const std::string& name) { return std::string(SAILSHAPE_TEST_DATA) + "/" + name; }

std::string fileBytes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_F(CloudIoTest, PcdBinaryCompressedWrittenByPcl) {
  const CloudReadResult r = readCloud(pclFile("xyzi_compressed.pcd"));
  EXPECT_EQ(r.format, "pcd-binary-compressed");
  ASSERT_EQ(r.cloud.size(), 600u);
  ASSERT_EQ(r.cloud.intensity.size(), 600u);
  for (size_t i = 0; i < 600; ++i) {
    // PCL stored floats: compare with the same float arithmetic.
    const Vec3 want(0.01f * static_cast<float>(i % 30), 0.02f * static_cast<float>(i / 30), 0.001f * static_cast<float>(i));
    ASSERT_EQ(r.cloud.points[i], want) << "point " << i;
    ASSERT_EQ(r.cloud.intensity[i], static_cast<float>(i)) << "point " << i;
  }
  ASSERT_TRUE(r.cloud.viewpoint.has_value());
  EXPECT_EQ(*r.cloud.viewpoint, Vec3(1.5, -2, 3));
  EXPECT_EQ(r.dropped_nan_points, 0u);
}

TEST_F(CloudIoTest, PcdBinaryCompressedOrganisedWithAnInvalidReturn) {
  const CloudReadResult r = readCloud(pclFile("xyz_organised_nan_compressed.pcd"));
  ASSERT_EQ(r.cloud.size(), 599u);
  EXPECT_EQ(r.dropped_nan_points, 1u);
  EXPECT_EQ(r.cloud.points[300], Vec3(0.5 * 0, 0.25 * 15, 1));  // point 300; 301 was NaN
  EXPECT_EQ(r.cloud.points[301], Vec3(0.5 * 2, 0.25 * 15, 1));  // point 302
  EXPECT_EQ(r.cloud.points[598], Vec3(0.5 * 19, 0.25 * 29, 1));
}

TEST_F(CloudIoTest, PcdBinaryCompressedErrors) {
  const std::string good = fileBytes(pclFile("xyzi_compressed.pcd"));
  const size_t line = good.find("DATA binary_compressed\n");
  ASSERT_NE(line, std::string::npos);
  const size_t data = line + std::strlen("DATA binary_compressed\n");
  uint32_t packed = 0;
  std::memcpy(&packed, good.data() + data, 4);
  ASSERT_EQ(good.size(), data + 8 + packed);  // PCL writes nothing after the stream

  EXPECT_READ_ERROR(write("short.pcd", good.substr(0, good.size() - 100)),
                    "byte " + std::to_string(good.size() - 100),
                    "truncated binary_compressed data (" + std::to_string(packed) + " compressed bytes announced, " +
                        std::to_string(packed - 100) + " in the file)");
  EXPECT_READ_ERROR(write("nosizes.pcd", good.substr(0, data + 5)),
                    "truncated binary_compressed data (no size words after the DATA line)");
  // The stream opens with a literal run; a back reference there points before the
  // start of the output, which LZF refuses.
  std::string bad = good;
  bad[data + 8] = static_cast<char>(0xff);
  EXPECT_READ_ERROR(write("corrupt.pcd", bad), "byte " + std::to_string(data + 8),
                    "corrupt binary_compressed data (LZF stream is invalid: 0 of 9600 bytes inflated)");
  // A header that does not match the stream: 601 points need 9616 bytes.
  std::string more = good;
  more.replace(more.find("POINTS 600"), 10, "POINTS 601");
  EXPECT_READ_ERROR(write("points.pcd", more),
                    "binary_compressed data inflates to 9600 bytes, but 601 points of 16 bytes need 9616");
}

TEST_F(CloudIoTest, PcdErrors) {
  const std::string fields = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 5\nHEIGHT 1\n";
  EXPECT_READ_ERROR(write("datatype.pcd", fields + "POINTS 5\nDATA hex\n"), "line 9: unknown PCD DATA type 'hex'");
  EXPECT_READ_ERROR(write("nodata.pcd", fields + "POINTS 5\n"), "line 8: truncated PCD header (no DATA line)");
  EXPECT_READ_ERROR(write("notpcd.pcd", "ply\nformat ascii 1.0\n"),
                    "line 1: not a PCD file (unknown header keyword 'ply')");
  EXPECT_READ_ERROR(write("keyword.pcd", "VERSION 0.7\nFEILDS x y z\n"), "line 2: unknown PCD header keyword 'FEILDS'");
  EXPECT_READ_ERROR(write("size.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n0 0 0\n"),
                    "line 2: SIZE has 2 entries but FIELDS has 3");
  EXPECT_READ_ERROR(write("type.pcd", "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nPOINTS 1\nDATA ascii\n0 0 0\n"),
                    "line 3: unsupported TYPE 'F' with SIZE 2 for field 'z'");
  EXPECT_READ_ERROR(write("nox.pcd", "FIELDS u y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n0 0 0\n"),
                    "line 5: PCD FIELDS has no 'x' field");
  EXPECT_READ_ERROR(write("nopoints.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n0 0 0\n"),
                    "line 4: PCD header has neither POINTS nor WIDTH");
  EXPECT_READ_ERROR(write("viewpoint.pcd", "FIELDS x y z\nVIEWPOINT 0 0 0 1 0 0\n"), "line 2: malformed VIEWPOINT");
  EXPECT_READ_ERROR(write("width.pcd", "FIELDS x y z\nWIDTH -5\n"), "line 2: malformed WIDTH line");

  EXPECT_READ_ERROR(write("values.pcd", fields + "POINTS 2\nDATA ascii\n1 2 3\n1 2\n"),
                    "line 11: expected 3 values, got 2");
  EXPECT_READ_ERROR(write("nonnum.pcd", fields + "POINTS 2\nDATA ascii\n1 2 3\n1 2 x\n"),
                    "line 11: non-numeric value 'x'");
  EXPECT_READ_ERROR(write("truncascii.pcd", fields + "POINTS 5\nDATA ascii\n1 2 3\n"),
                    "line 11: truncated data (expected 5 points, got 1)");
  EXPECT_READ_ERROR(write("zero.pcd", fields + "POINTS 0\nDATA ascii\n"), "no points");

  Bytes trunc;
  trunc.text(fields + "POINTS 5\nDATA binary\n");
  for (int i = 0; i < 7; ++i) trunc.le(1.0f);
  EXPECT_READ_ERROR(write("trunc.pcd", trunc.data),
                    "byte " + std::to_string(trunc.data.size()) + ": truncated data (expected 5 points, got 2)");

  Bytes inf;
  inf.text(fields + "POINTS 2\nDATA binary\n");
  const size_t header_size = inf.data.size();
  inf.le(1.f).le(2.f).le(3.f).le(1.f).le(static_cast<float>(-kInf)).le(3.f);
  EXPECT_READ_ERROR(write("inf.pcd", inf.data),
                    "byte " + std::to_string(header_size + 16) + ": infinite coordinate (y of point 1)");
}

// ---------------------------------------------------------------------------
// XYZ / CSV

TEST_F(CloudIoTest, XyzWithoutHeader) {
  const CloudReadResult r =
      readCloud(write("scan.xyz", "# exported\n\n1 2 3\n  4\t5  6  \r\n# comment\n+7e-3 -8 9.\n"));
  EXPECT_EQ(r.format, "xyz");
  ASSERT_EQ(r.cloud.size(), 3u);
  EXPECT_EQ(r.cloud.points[2], Vec3(7e-3, -8, 9));
  EXPECT_FALSE(r.cloud.hasIntensity());

  const CloudReadResult with_intensity = readCloud(write("scan.txt", "1 2 3 10 99 99\n4,5,6,20\n7;8;9;30\n"));
  EXPECT_EQ(with_intensity.cloud.intensity, (std::vector<float>{10, 20, 30}));
}

// A cloud another program wrote in millimetres reads as a scene kilometres across:
// refused at the door with its unit named, whatever the format, rather than analysed.
TEST_F(CloudIoTest, ACloudInMillimetresOrBeyondAnyScannersReachIsRefused) {
  EXPECT_READ_ERROR(write("mm.xyz", "0 0 1000\n-500 0 12400\n-3600 0 1300\n"), "looks like millimetres",
                    "write it in metres");
  Cloud huge;
  huge.points = {Vec3(0, 0, 1e30), Vec3(1e30, 0, 0)};
  writeCloud(path("huge.ply"), huge);
  EXPECT_READ_ERROR(path("huge.ply"), "reaches 1e+30 m from the origin");
}

TEST_F(CloudIoTest, CsvHeaderMapsColumnsByName) {
  const CloudReadResult r = readCloud(
      write("scan.csv", "# viewpoint 1 2 3\nlabel;Intensity;Z;Y;X;beta_rad\nsail; 5 ;3;2;1;0.5\njib;6;6;5;4;-0.5\n"));
  EXPECT_EQ(r.format, "csv");
  ASSERT_EQ(r.cloud.size(), 2u);
  EXPECT_EQ(r.cloud.points[0], Vec3(1, 2, 3));
  EXPECT_EQ(r.cloud.points[1], Vec3(4, 5, 6));
  EXPECT_EQ(r.cloud.intensity, (std::vector<float>{5, 6}));
  EXPECT_EQ(r.cloud.beta_rad, (std::vector<double>{0.5, -0.5}));
  EXPECT_TRUE(r.cloud.alpha_rad.empty());
  ASSERT_TRUE(r.cloud.viewpoint.has_value());
  EXPECT_EQ(*r.cloud.viewpoint, Vec3(1, 2, 3));

  const CloudReadResult cc = readCloud(write("cc.txt", "//X,Y,Z,Scalar_Intensity\n1,2,3,4\n"));
  EXPECT_EQ(cc.cloud.points[0], Vec3(1, 2, 3));
  EXPECT_EQ(cc.cloud.intensity, std::vector<float>{4});
}

TEST_F(CloudIoTest, TextNaNPointsAreDroppedWithWarning) {
  const CloudReadResult r = readCloud(write("nan.xyz", "1 2 3\nnan 0 0\n0 NaN 0\n4 5 6\n0 0 -nan\n"));
  EXPECT_EQ(r.cloud.size(), 2u);
  EXPECT_EQ(r.dropped_nan_points, 3u);
  EXPECT_EQ(r.warnings, std::vector<std::string>{"dropped 3 points with NaN coordinates"});
}

TEST_F(CloudIoTest, TextErrors) {
  EXPECT_READ_ERROR(write("pts.xyz", "# a\n1 2 3\n\n4 5 6\n# b\n7 8 9\n1.5abc 2 3\n"),
                    "line 7: non-numeric value '1.5abc'");
  EXPECT_READ_ERROR(write("x.xyz", "1 2 3\n1 2 3\n1 2 3\ninf 2 3\n"), "line 4: infinite coordinate 'inf'");
  EXPECT_READ_ERROR(write("two.xyz", "1 2 3\n1 2\n"), "line 2: expected at least 3 values, got 2");
  EXPECT_READ_ERROR(write("four.xyz", "1 2 3 4\n1 2 3\n"), "line 2: expected at least 4 values, got 3");
  EXPECT_READ_ERROR(write("noz.csv", "x,y,intensity\n1,2,3\n"), "line 1: header has no 'z' column");
  EXPECT_READ_ERROR(write("empty.csv", "x,y,z\n1,,3\n"), "line 2: empty value in column 2");
  EXPECT_READ_ERROR(write("mixed.csv", "x,2,3\n"), "line 1: non-numeric value 'x'");
  EXPECT_READ_ERROR(write("n.xyz", "nan 0 0\nnan 0 0\n0 nan 0\n0 0 nan\nNaN NaN NaN\n"),
                    "no finite points (all 5 points have NaN coordinates)");
  EXPECT_READ_ERROR(write("e.xyz", "# only a comment\n\n"), "no points");
  EXPECT_READ_ERROR(write("h.csv", "x,y,z\n"), "no points");
}

// ---------------------------------------------------------------------------
// selectPoints (analysis/cloud.hpp), used by every reader's caller

TEST(SelectPoints, CopiesAttributesAtIndicesAndKeepsViewpoint) {
  const Cloud cloud = makeCloud(10, true);
  const Cloud sub = selectPoints(cloud, {7, 2, 2});
  ASSERT_EQ(sub.size(), 3u);
  EXPECT_EQ(sub.points[0], cloud.points[7]);
  EXPECT_EQ(sub.intensity, (std::vector<float>{cloud.intensity[7], cloud.intensity[2], cloud.intensity[2]}));
  EXPECT_EQ(sub.alpha_rad[1], cloud.alpha_rad[2]);
  EXPECT_EQ(sub.beta_rad[0], cloud.beta_rad[7]);
  EXPECT_EQ(sub.viewpoint, cloud.viewpoint);
  EXPECT_FALSE(selectPoints(makeCloud(4, false), {1}).hasIntensity());
}

TEST(SelectPoints, RejectsBadIndexAndInconsistentAttributes) {
  Cloud cloud = makeCloud(10, true);
  try {
    selectPoints(cloud, {1, 10});
    ADD_FAILURE() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[selectPoints] index 10 out of range (cloud has 10 points)");
  }
  EXPECT_THROW(selectPoints(cloud, {10}), InvalidInput);
  cloud.alpha_rad.pop_back();
  EXPECT_THROW(selectPoints(cloud, {0}), InvalidInput);
}

}  // namespace
}  // namespace sailshape
