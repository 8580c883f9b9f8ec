// Registration into the boat (or tunnel) frame from faces known in boat
// coordinates, the reference file, and the drift check on a re-scan.
#include "analysis/registration/boat_registration.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "analysis/design/sail_generator.hpp"
#include "analysis/registration/registration.hpp"
#include "tests/support/fixtures.hpp"
#include "tests/support/tunnel_scene.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;

RigidTransform unitPose() {
  // Unit A mounted turned 30° about Z and tilted 5°, not at the tunnel origin.
  RigidTransform t = RigidTransform::Identity();
  t.linear() = (Eigen::AngleAxisd(30 * kRadPerDeg, Vec3::UnitZ()) * Eigen::AngleAxisd(5 * kRadPerDeg, Vec3::UnitY())).toRotationMatrix();
  t.translation() = Vec3(-1.6, -1.1, 1.0);
  return t;
}

TEST(BoatRegistration, ChamberWallsAndCubeGiveTheUnitPose) {
  // Tolerances: the issue's noisy registration bounds (0.05°, 2 mm); the faces'
  // points lie about σ off their faces.
  TunnelSceneParams p;
  p.noise_sigma_m = kSigma;
  p.reference_pose = unitPose();
  const TunnelScene s = makeTunnelScene(p);
  const BoatRegistration b = registerToBoat(s.reference, s.chamber);
  EXPECT_LT(rotationDifferenceDeg(b.transform.linear(), s.reference_pose.linear()), 0.05);
  EXPECT_LT((b.transform.translation() - s.reference_pose.translation()).norm(), 0.002);
  EXPECT_TRUE(b.accepted);
  EXPECT_FALSE(b.ambiguous);
  EXPECT_NEAR(b.fitness_rms_m, kSigma, 0.5 * kSigma);
  EXPECT_EQ(b.faces.size(), 7u);  // floor, ceiling, starboard wall, screen, cube top and two sides
  for (const FaceMatch& f : b.faces) EXPECT_LT(f.angle_deg, 0.1) << f.face;
}

TEST(BoatRegistration, NoiseFreeIsExact) {
  TunnelSceneParams p;
  p.reference_pose = unitPose();
  const TunnelScene s = makeTunnelScene(p);
  const BoatRegistration b = registerToBoat(s.reference, s.chamber);
  EXPECT_LT(rotationDifferenceDeg(b.transform.linear(), s.reference_pose.linear()), 0.01);
  EXPECT_LT((b.transform.translation() - s.reference_pose.translation()).norm(), 1e-4);
}

TEST(BoatRegistration, ACubeAloneIsAmbiguousWithoutAPrior) {
  // Deck and a cube: a quarter turn about the cube's vertical axis looks the
  // same. Without a prior the result must say ambiguous (never accepted); with
  // the unit's rough orientation (within 30°) it picks the right one.
  TunnelSceneParams p;
  p.reference_pose = unitPose();
  const TunnelScene s = makeTunnelScene(p);
  BoatReference cube;
  cube.name = "cube on the deck";
  cube.faces = {{"deck", Vec3::UnitZ(), 0.0}};
  for (const ReferenceFace& f : cubeFaces("cube", Vec3(1.9, 0.1, 0.3), 0.6, 45)) cube.faces.push_back(f);
  const BoatRegistration loose = registerToBoat(s.reference, cube);
  EXPECT_TRUE(loose.ambiguous);
  EXPECT_FALSE(loose.accepted);
  BoatRegistrationParams bp;
  bp.prior_rotation = Eigen::AngleAxisd(20 * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  bp.prior_tolerance_deg = 30;
  const BoatRegistration b = registerToBoat(s.reference, cube, bp);
  EXPECT_FALSE(b.ambiguous);
  EXPECT_TRUE(b.accepted);
  EXPECT_LT(rotationDifferenceDeg(b.transform.linear(), s.reference_pose.linear()), 0.01);
  EXPECT_LT((b.transform.translation() - s.reference_pose.translation()).norm(), 1e-4);
}

TEST(BoatRegistration, ReScanOfTheReferenceShowsWhetherTheUnitMoved) {
  // Session start: register and store. Later re-scans (new noise): the same
  // pose gives a drift within the 9 mm uncertainty; a unit knocked by 2 cm
  // shows as moved.
  TunnelSceneParams p;
  p.noise_sigma_m = kSigma;
  p.reference_pose = unitPose();
  const RigidTransform stored = registerToBoat(makeTunnelScene(p).reference, makeTunnelScene(p).chamber).transform;
  p.seed = 9;
  const TunnelScene again = makeTunnelScene(p);
  const Drift still = compareTransforms(stored, registerToBoat(again.reference, again.chamber).transform);
  EXPECT_FALSE(still.moved);
  EXPECT_LT(still.translation_m, 0.004);
  p.reference_pose.translation() += Vec3(0.02, 0, 0);
  const TunnelScene knocked = makeTunnelScene(p);
  const Drift moved = compareTransforms(stored, registerToBoat(knocked.reference, knocked.chamber).transform);
  EXPECT_TRUE(moved.moved);
  EXPECT_NEAR(moved.translation_m, 0.02, 0.004);
}

TEST(BoatRegistration, TooFewPlanesOrFacesAreClearErrors) {
  const TunnelScene s = makeTunnelScene({});
  BoatReference two;
  two.name = "deck and mast";
  two.faces = {{"deck", Vec3::UnitZ(), 0}, {"mast", Vec3::UnitX(), 0}};
  expectInvalidInput([&] { registerToBoat(s.reference, two); }, {"registerToBoat", "no three faces", "deck and mast"});
  BoatReference parallel;
  parallel.name = "floor and ceiling";
  parallel.faces = {{"floor", Vec3::UnitZ(), 0}, {"ceiling", -Vec3::UnitZ(), -2.4}, {"shelf", Vec3::UnitZ(), 1}};
  expectInvalidInput([&] { registerToBoat(s.reference, parallel); }, {"registerToBoat", "independent"});
  Cloud sail = sampleSail(exampleDesign(SailType::Main), {5000, 0, 1});
  expectThrowWith<AnalysisError>([&] { registerToBoat(sail, s.chamber); },
                                 {"registerToBoat", "fewer than three usable planes", "found 0"});
  BoatReference skew;
  skew.name = "skew";
  skew.faces = {{"a", Vec3::UnitZ(), 0}, {"b", Vec3(1, 0, 1).normalized(), 0}, {"c", Vec3(0, 1, 1).normalized(), 0}};
  expectThrowWith<AnalysisError>([&] { registerToBoat(s.reference, skew); },
                                 {"registerToBoat", "no three planes", "skew"});
  BoatRegistrationParams bad;
  bad.max_face_distance_m = 0;
  expectInvalidInput([&] { registerToBoat(s.reference, s.chamber, bad); }, {"registerToBoat", "max_face_distance_m"});
  bad = {};
  bad.max_angle_mismatch_deg = 0;
  expectInvalidInput([&] { registerToBoat(s.reference, s.chamber, bad); }, {"registerToBoat", "max_angle_mismatch_deg"});
  bad = {};
  bad.uncertainty_m = 0;
  expectInvalidInput([&] { registerToBoat(s.reference, s.chamber, bad); }, {"registerToBoat", "uncertainty_m"});
  bad = {};
  bad.refine_iterations = -1;
  expectInvalidInput([&] { registerToBoat(s.reference, s.chamber, bad); }, {"registerToBoat", "refine_iterations"});
}

TEST(BoatReferenceFile, ReadsFacesAndACube) {
  const BoatReference r = parseBoatReference(
      R"({"name": "foredeck cube", "faces": [{"name": "deck", "normal": [0, 0, 2], "point": [0, 0, 0.1]}],
          "cube": {"centre": [1.2, 0.0, 0.35], "size_m": 0.5, "yaw_deg": 90}})",
      "ref.json");
  EXPECT_EQ(r.name, "foredeck cube");
  ASSERT_EQ(r.faces.size(), 6u);
  EXPECT_EQ(r.faces[0].name, "deck");
  EXPECT_EQ(r.faces[0].normal, Vec3::UnitZ());  // normalised
  EXPECT_NEAR(r.faces[0].offset_m, 0.1, 1e-12);
  // The cube's +x face, turned 90°, faces +Y at y = 0.25; its top is at z = 0.6.
  EXPECT_LT((r.faces[1].normal - Vec3::UnitY()).norm(), 1e-12);
  EXPECT_NEAR(r.faces[1].offset_m, 0.25, 1e-12);
  EXPECT_EQ(r.faces[5].name, "cube top");
  EXPECT_NEAR(r.faces[5].offset_m, 0.6, 1e-12);
}

TEST(BoatReferenceFile, BadFilesNameTheProblem) {
  expectFileError([] { parseBoatReference("{", "r.json"); }, "r.json", {"not valid JSON"});
  expectFileError([] { parseBoatReference("[1]", "r.json"); }, "r.json", {"JSON object"});
  expectFileError([] { parseBoatReference(R"({"faces": 3})", "r.json"); }, "r.json", {"\"faces\" must be an array"});
  expectFileError([] { parseBoatReference(R"({"faces": [{"normal": [0,0,1]}]})", "r.json"); }, "r.json",
                  {"faces[0]", "\"point\""});
  expectFileError([] { parseBoatReference(R"({"faces": [{"normal": [0,0], "point": [0,0,0]}]})", "r.json"); },
                  "r.json", {"faces[0].normal", "three numbers"});
  expectFileError([] { parseBoatReference(R"({"faces": [{"normal": [0,0,0], "point": [0,0,0]}]})", "r.json"); },
                  "r.json", {"faces[0].normal is zero"});
  expectFileError([] { parseBoatReference(R"({"faces": [{"normal": [0,0,1], "point": [0,0,0]}]})", "r.json"); },
                  "r.json", {"at least three faces", "found 1"});
  expectFileError([] { parseBoatReference(R"({"cube": {"centre": [0,0,0]}})", "r.json"); }, "r.json",
                  {"\"cube\" needs"});
  expectFileError([] { parseBoatReference(R"({"cube": {"centre": [0,0,0], "size_m": -1}})", "r.json"); }, "r.json",
                  {"size_m must be > 0"});
  const std::string missing = (fs::temp_directory_path() / "sailshape_no_such_reference.json").string();
  expectFileError([&] { readBoatReference(missing); }, missing, {});
  expectInvalidInput([] { cubeFaces("c", Vec3::Zero(), 0, 0); }, {"cubeFaces", "size_m"});
}

}  // namespace
}  // namespace sailshape
