#include "analysis/pipeline/params_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A fresh directory under the system temp dir, removed afterwards.
class ParamsFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sailshape_params_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  fs::path dir_;
};

// Parameters with every stage moved off its defaults.
AnalysisParams changedParams() {
  AnalysisParams p;
  p.sensor_sigma_m = 0.0035;
  p.normals.k_neighbours = 24;
  p.normals.orientation = "propagate";
  p.segment = false;
  p.region_growing.k_neighbours = 40;
  p.region_growing.max_normal_angle_deg = 7.5;
  p.region_growing.max_curvature = 0.03;
  p.region_growing.min_points = 800;
  p.region_growing.max_points = 123456789012ull;
  p.sail_pick.method = "seed";
  p.sail_pick.seed_point = {1.5, -0.25, 4.0};
  p.sail_pick.cluster_index = 2;
  p.statistical_outliers = false;
  p.statistical.std_ratio = 2.5;
  p.radius.radius_m = 0.03;
  p.radius.min_neighbours = 6;
  p.smoothing.k_neighbours = 80;
  p.smoothing.polynomial_order = 1;
  p.smoothing.fair_m = 0.014;
  p.smoothing.max_radius_ratio = 0.05;
  p.surface.projection = "scan_angles";
  p.surface.max_edge_factor = 3.0;
  p.surface.largest_component_only = false;
  p.outline.corners = 4;
  p.outline.design_lengths_m = {10.0, 10.5, 3.6};
  p.sections.fractions = {0.2, 0.4, 0.6, 0.8};
  p.sections.plane = "horizontal";
  p.sections.curve_points = 101;
  p.mixed_pixels = false;
  p.mixed.jump_sigmas = 6.5;
  p.mixed.max_missing = 3;
  return p;
}

TEST(ParamsJson, RoundTripsEveryChangedField) {
  const AnalysisParams in = changedParams();
  const json doc = paramsToJson(in);
  // Nested by stage, fields by their C++ names.
  EXPECT_EQ(doc["region_growing"]["k_neighbours"], 40);
  EXPECT_EQ(doc["region_growing"]["max_points"], 123456789012ull);
  EXPECT_EQ(doc["sail_pick"]["seed_point"], json({1.5, -0.25, 4.0}));
  EXPECT_EQ(doc["surface"]["projection"], "scan_angles");
  EXPECT_EQ(doc["segment"], false);

  // Through text and back: every value survives.
  const AnalysisParams out = paramsFromJson(json::parse(doc.dump()));
  EXPECT_EQ(paramsToJson(out), doc);
  EXPECT_EQ(out.sensor_sigma_m, 0.0035);
  EXPECT_EQ(out.normals.orientation, "propagate");
  EXPECT_FALSE(out.segment);
  EXPECT_EQ(out.region_growing.max_normal_angle_deg, 7.5);
  EXPECT_EQ(out.region_growing.min_points, 800u);
  EXPECT_EQ(out.region_growing.max_points, 123456789012ull);
  EXPECT_EQ(out.sail_pick.seed_point, (std::vector<double>{1.5, -0.25, 4.0}));
  EXPECT_EQ(out.smoothing.polynomial_order, 1);
  EXPECT_DOUBLE_EQ(out.smoothing.max_radius_ratio, 0.05);
  EXPECT_FALSE(out.surface.largest_component_only);
  EXPECT_EQ(out.outline.design_lengths_m, (std::vector<double>{10.0, 10.5, 3.6}));
  EXPECT_EQ(out.sections.fractions, (std::vector<double>{0.2, 0.4, 0.6, 0.8}));
  EXPECT_EQ(out.sections.curve_points, 101);
  EXPECT_FALSE(out.mixed_pixels);
  EXPECT_EQ(out.mixed.jump_sigmas, 6.5);
  EXPECT_EQ(out.mixed.max_missing, 3);
}

TEST(ParamsJson, APartialDocumentOverridesOnlyWhatItSets) {
  const AnalysisParams out = paramsFromJson(json::parse(R"({"region_growing": {"max_curvature": 0.02},
                                                            "smooth": false})"));
  EXPECT_EQ(out.region_growing.max_curvature, 0.02);
  EXPECT_FALSE(out.smooth);
  json expected = paramsToJson(AnalysisParams{});
  expected["region_growing"]["max_curvature"] = 0.02;
  expected["smooth"] = false;
  EXPECT_EQ(paramsToJson(out), expected);
  // An empty document is the defaults.
  EXPECT_EQ(paramsToJson(paramsFromJson(json::object())), paramsToJson(AnalysisParams{}));
}

TEST(ParamsJson, IntegralValuesAreAcceptedForRealParameters) {
  // "max_normal_angle_deg": 8 is an integer in JSON, a double in C++.
  const AnalysisParams out = paramsFromJson(json::parse(R"({"region_growing": {"max_normal_angle_deg": 8}})"));
  EXPECT_EQ(out.region_growing.max_normal_angle_deg, 8.0);
}

TEST(ParamsJson, UnknownKeysAreNamedWithTheirPath) {
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"region_growing": {"k_neighbors": 30}})")); },
                                {"[paramsFromJson]", "unknown parameter 'region_growing.k_neighbors'"});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"smoothing_radius": 0.1})")); },
                                {"unknown parameter 'smoothing_radius'"});
}

TEST(ParamsJson, AParameterNoLongerReadIsRefusedByName) {
  // outline.edge_smoothing_m was documented and written but read by nothing; a file
  // that still sets it is told so rather than believed.
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"outline": {"edge_smoothing_m": 0.05}})")); },
                                {"[paramsFromJson]", "unknown parameter 'outline.edge_smoothing_m'"});
  EXPECT_FALSE(paramsToJson(AnalysisParams{})["outline"].contains("edge_smoothing_m"));
}

TEST(ParamsJson, WrongTypesAreNamedWithTheirPath) {
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"region_growing": {"k_neighbours": "thirty"}})")); },
                                {"[paramsFromJson]", "'region_growing.k_neighbours'", "\"thirty\""});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"segment": "yes"})")); },
                                {"[paramsFromJson]", "'segment'"});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"surface": {"projection": 2}})")); },
                                {"[paramsFromJson]", "'surface.projection'"});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"sections": {"fractions": [0.25, "half"]}})")); },
                                {"[paramsFromJson]", "'sections.fractions'"});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"sail_pick": {"seed_point": 3}})")); },
                                {"[paramsFromJson]", "'sail_pick.seed_point'"});
  // A stage that is not an object.
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"region_growing": 30})")); },
                                {"[paramsFromJson]", "'region_growing' must be an object"});
  // Counts are integers: a fraction or a negative value would be silently truncated or wrapped.
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"normals": {"k_neighbours": 20.5}})")); },
                                {"[paramsFromJson]", "'normals.k_neighbours'", "20.5"});
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse(R"({"region_growing": {"max_points": -1}})")); },
                                {"[paramsFromJson]", "'region_growing.max_points'", "-1"});
  // The document itself must be an object.
  expectThrowWith<InvalidInput>([] { paramsFromJson(json::parse("[1, 2]")); }, {"[paramsFromJson]", "object"});
}

TEST_F(ParamsFile, LoadsYaml) {
  const std::string path = write("trim.yaml", R"(# tunnel session, gennaker
sensor_sigma_m: 0.0041
segment: true
normals:
  k_neighbours: 25
  orientation: "propagate"
region_growing:
  max_normal_angle_deg: 7
  max_curvature: 0.03
  min_points: 800
sail_pick:
  method: seed
  seed_point: [1.0, 0.5, 6]
smooth: False
sections:
  fractions: [0.25, 0.5, 0.75]
  plane: horizontal
)");
  const AnalysisParams p = loadParams(path);
  EXPECT_EQ(p.sensor_sigma_m, 0.0041);
  EXPECT_TRUE(p.segment);
  EXPECT_EQ(p.normals.k_neighbours, 25);
  EXPECT_EQ(p.normals.orientation, "propagate");
  EXPECT_EQ(p.region_growing.max_normal_angle_deg, 7.0);
  EXPECT_EQ(p.region_growing.max_curvature, 0.03);
  EXPECT_EQ(p.region_growing.min_points, 800u);
  EXPECT_EQ(p.sail_pick.method, "seed");
  EXPECT_EQ(p.sail_pick.seed_point, (std::vector<double>{1.0, 0.5, 6.0}));
  EXPECT_FALSE(p.smooth);
  EXPECT_EQ(p.sections.fractions, (std::vector<double>{0.25, 0.5, 0.75}));
  EXPECT_EQ(p.sections.plane, "horizontal");
  // Everything else keeps its default.
  EXPECT_EQ(p.region_growing.k_neighbours, RegionGrowingParams{}.k_neighbours);
  EXPECT_EQ(paramsToJson(p)["surface"], paramsToJson(AnalysisParams{})["surface"]);
}

TEST_F(ParamsFile, YamlQuotedNumbersStayStrings) {
  // A quoted "10" is text: wrong for a number parameter, and named.
  const std::string path = write("quoted.yml", "region_growing:\n  k_neighbours: \"10\"\n");
  expectThrowWith<FileError>([&] { loadParams(path); }, {path, "'region_growing.k_neighbours'"});
}

TEST_F(ParamsFile, LoadsJsonAndRoundTripsThroughAFile) {
  const AnalysisParams in = changedParams();
  const std::string path = write("all.json", paramsToJson(in).dump(2));
  EXPECT_EQ(paramsToJson(loadParams(path)), paramsToJson(in));
}

TEST_F(ParamsFile, FileErrorsNameTheFile) {
  const std::string missing = (dir_ / "missing.json").string();
  expectThrowWith<FileError>([&] { loadParams(missing); }, {missing, "cannot open"});

  const std::string bad_json = write("bad.json", R"({"region_growing": {"k_neighbours": 30,}})");
  expectThrowWith<FileError>([&] { loadParams(bad_json); }, {bad_json, "JSON parse error"});

  const std::string bad_yaml = write("bad.yaml", "region_growing: [1, 2\n  k: {\n");
  expectThrowWith<FileError>([&] { loadParams(bad_yaml); }, {bad_yaml, "YAML parse error"});

  // Content errors become FileErrors naming the file and the key, without the function tag.
  const std::string unknown = write("unknown.yaml", "region_growing:\n  k_neighbors: 30\n");
  expectThrowWith<FileError>([&] { loadParams(unknown); },
                             {unknown + ": unknown parameter 'region_growing.k_neighbors'"});
  const std::string wrong = write("wrong.json", R"({"smoothing": {"polynomial_order": "quadratic"}})");
  expectThrowWith<FileError>([&] { loadParams(wrong); }, {wrong + ": ", "'smoothing.polynomial_order'"});
  const std::string not_object = write("list.yaml", "- 1\n- 2\n");
  expectThrowWith<FileError>([&] { loadParams(not_object); }, {not_object + ": ", "must be an object"});
}

}  // namespace
}  // namespace sailshape
