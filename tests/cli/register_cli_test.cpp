// `sailshape register` run as a user would, on the synthetic two-unit tunnel scene.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/core/units.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/registration/registration.hpp"
#include "analysis/registration/rigid_transform.hpp"
#include "tests/cli/run_sailshape.hpp"
#include "tests/support/tunnel_scene.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using sailshape::testing::Outcome;
using sailshape::testing::readText;

constexpr double kSigma = 0.004;  // SPEC §3

class RegisterCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ctest runs each case in its own process, two at a time: each process gets its own folder.
    dir_ = fs::temp_directory_path() / ("sailshape_register_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    sailshape::TunnelSceneParams p;
    p.noise_sigma_m = kSigma;
    scene_ = new sailshape::TunnelScene(sailshape::makeTunnelScene(p));
    sailshape::writeCloud((dir_ / "unit_a.ply").string(), scene_->reference);
    sailshape::writeCloud((dir_ / "unit_b.ply").string(), scene_->moving);
    json faces = json::array();
    for (const auto& f : scene_->chamber.faces)
      faces.push_back({{"name", f.name},
                       {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
                       {"point", {f.offset_m * f.normal.x(), f.offset_m * f.normal.y(), f.offset_m * f.normal.z()}}});
    std::ofstream((dir_ / "tunnel.json").string()) << json{{"name", "test section"}, {"faces", faces}}.dump(2);
  }
  static void TearDownTestSuite() {
    delete scene_;
    fs::remove_all(dir_);
  }
  Outcome sailshape(const std::string& args) { return sailshape::testing::runSailshape(dir_, args); }
  static std::string path(const std::string& name) { return (dir_ / name).string(); }

  static fs::path dir_;
  static sailshape::TunnelScene* scene_;
};
fs::path RegisterCli::dir_;
sailshape::TunnelScene* RegisterCli::scene_ = nullptr;

TEST_F(RegisterCli, HelpExplainsEveryOption) {
  const Outcome r = sailshape("register --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* word : {"--reference", "--moving", "--method", "planes", "svd", "icp", "--pairs", "--plane-hints",
                           "--initial", "--icp", "--no-refine", "--crossed-radius-mm", "--uncertainty-mm",
                           "--boat-reference", "--out", "--apply", "--json", "--transform", "--check",
                           "--drift-radius-m", "--force", "--quiet"})
    EXPECT_NE(r.out.find(word), std::string::npos) << "help lacks " << word;
}

TEST_F(RegisterCli, PlaneMethodWritesTheTransformTheJsonAndTheMovedCloud) {
  const Outcome r = sailshape("register --reference " + path("unit_a.ply") + " --moving " + path("unit_b.ply") +
                              " --out " + path("t.txt") + " --json " + path("reg.json") + " --apply " +
                              path("b_in_a.ply") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Issue 5 tolerances under 4 mm noise: 0.05°, 2 mm.
  const sailshape::RigidTransform t = sailshape::readTransform(path("t.txt"));
  EXPECT_LT(sailshape::rotationDifferenceDeg(t.linear(), scene_->truth.linear()), 0.05);
  EXPECT_LT((t.translation() - scene_->truth.translation()).norm(), 0.002);
  EXPECT_EQ(r.out, readText(path("t.txt")));  // the same four lines on stdout
  const json doc = json::parse(readText(path("reg.json")));
  EXPECT_EQ(doc["method"], "planes");
  EXPECT_TRUE(doc["accepted"].get<bool>());
  EXPECT_LT(doc["fitness_rms_m"].get<double>(), 0.009);
  // Every plane the pose lands is paired: at least the three that fix it.
  EXPECT_GE(doc["planes"]["pairings"].size(), 3u);
  EXPECT_EQ(doc["planes"]["pairings"].size(), doc["planes"]["moving_planes_on_reference"].get<size_t>());
  EXPECT_GE(doc["planes"]["poses_verified"].get<size_t>(), 1u);
  EXPECT_GT(doc["distances_after_refinement"]["count"].get<size_t>(), 1000u);
  EXPECT_EQ(doc["matrix"].size(), 4u);
  const sailshape::Cloud moved = sailshape::readCloud(path("b_in_a.ply")).cloud;
  ASSERT_EQ(moved.size(), scene_->moving.size());
  EXPECT_LT((moved.points[0] - scene_->truth * scene_->moving.points[0]).norm(), 0.002 + 0.05 * sailshape::kRadPerDeg * 5);

  // Reapplying the stored transform to a later scan gives the same cloud.
  const Outcome again = sailshape("register --moving " + path("unit_b.ply") + " --transform " + path("t.txt") +
                                  " --apply " + path("again.ply") + " -q");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_LT((sailshape::readCloud(path("again.ply")).cloud.points[5] - moved.points[5]).norm(), 1e-6);
}

TEST_F(RegisterCli, PlainIcpFromTheRawPoseIsRefusedWithOneLine) {
  const Outcome r = sailshape("register --reference " + path("unit_a.ply") + " --moving " + path("unit_b.ply") +
                              " --method icp --out " + path("icp.txt") + " --json " + path("icp.json") + " -q");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("not accepted"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(path("icp.txt")));
  const json doc = json::parse(readText(path("icp.json")));  // the diagnostics are still written
  EXPECT_FALSE(doc["accepted"].get<bool>());
}

TEST_F(RegisterCli, BoatReferenceAndDriftCheck) {
  const Outcome r = sailshape("register --reference " + path("unit_a.ply") + " --boat-reference " +
                              path("tunnel.json") + " --out " + path("a_boat.txt") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const sailshape::RigidTransform t = sailshape::readTransform(path("a_boat.txt"));
  EXPECT_LT(sailshape::rotationDifferenceDeg(t.linear(), scene_->reference_pose.linear()), 0.05);
  EXPECT_LT((t.translation() - scene_->reference_pose.translation()).norm(), 0.002);
  // Re-scan of the same pose: no drift reported.
  const Outcome check = sailshape("register --reference " + path("unit_a.ply") + " --boat-reference " +
                                  path("tunnel.json") + " --check " + path("a_boat.txt") + " --json " +
                                  path("drift.json") + " -q");
  ASSERT_EQ(check.exit_code, 0) << check.err;
  EXPECT_NE(check.err.find("unchanged"), std::string::npos) << check.err;
  const json doc = json::parse(readText(path("drift.json")));
  EXPECT_FALSE(doc["drift"]["moved"].get<bool>());
  EXPECT_LT(doc["drift"]["translation_m"].get<double>(), 1e-6);

  // A unit whose ranges read 0.3 % long (SPEC §3's bound): the walls give the
  // scale, --apply takes it out, and the cloud lands where the unit's points are.
  const double k = 1.003;
  sailshape::writeCloud(path("unit_a_long.ply"), sailshape::removeRangeScale(scene_->reference, 1 / k));
  const Outcome longer = sailshape("register --reference " + path("unit_a_long.ply") + " --boat-reference " +
                                   path("tunnel.json") + " --apply " + path("a_in_boat.ply") + " --json " +
                                   path("scale.json") + " -q");
  ASSERT_EQ(longer.exit_code, 0) << longer.err;
  const json scaled = json::parse(readText(path("scale.json")));
  const double fitted = scaled["boat"]["range_scale"].get<double>(), sigma = scaled["boat"]["range_scale_sigma"].get<double>();
  EXPECT_LT(std::abs(fitted - k), 3 * sigma) << fitted << " ± " << sigma;
  const sailshape::Cloud in_boat = sailshape::readCloud(path("a_in_boat.ply")).cloud;
  ASSERT_EQ(in_boat.size(), scene_->reference.size());
  for (size_t i : {size_t{0}, in_boat.size() / 2, in_boat.size() - 1})
    EXPECT_LT((in_boat.points[i] - scene_->reference_pose * scene_->reference.points[i]).norm(), 0.002) << i;
}

TEST_F(RegisterCli, BadInputIsOneLineNamingTheProblem) {
  auto oneLine = [](const Outcome& r, const std::string& what) {
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  };
  oneLine(sailshape("register --moving " + path("unit_b.ply")), "--reference is required");
  oneLine(sailshape("register --reference " + path("unit_a.ply")), "--moving");
  oneLine(sailshape("register --reference " + path("none.ply") + " --moving " + path("unit_b.ply")), path("none.ply"));
  oneLine(sailshape("register --reference " + path("unit_a.ply") + " --moving " + path("unit_b.ply") +
                    " --method svd"),
          "3 point pairs");
  oneLine(sailshape("register --reference " + path("unit_a.ply") + " --moving " + path("unit_b.ply") +
                    " --method magic"),
          "--method");
  std::ofstream(path("bad_t.txt")) << "1 0 0\n";
  oneLine(sailshape("register --moving " + path("unit_b.ply") + " --transform " + path("bad_t.txt") + " --apply " +
                    path("x.ply")),
          "bad_t.txt");
  oneLine(sailshape("register --moving " + path("unit_b.ply") + " --transform " + path("bad_t.txt")), "--apply");
}

}  // namespace
