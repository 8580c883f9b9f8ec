// The pose verifier (issue 35) on an emulated room: the true pose is not
// contradicted by free space, the floor-for-ceiling swap is, and the
// comparison's margin follows the stated risk α.
#include "analysis/registration/pose_verification.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "tests/support/fixtures.hpp"
#include "tests/support/room_scene.hpp"

namespace sailshape {
namespace {

RoomScene alignedRoom() {
  RoomSceneParams p;
  p.reference_pose.translation() = Vec3(-1.6, -0.9, 0.7);
  p.moving_pose.translation() = Vec3(-0.6, 0.1, 1.7);
  p.moving_pose.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  p.alpha_step_deg = p.beta_step_deg = 1.0;
  return makeRoomScene(p);
}

TEST(PoseVerifier, FreeSpaceContradictsTheSwapAndNotTheTruth) {
  const RoomScene s = alignedRoom();
  const PoseVerifier v(s.reference, s.moving);
  // The room (6 × 3.6 × 2.4 m, origin at the floor's centre) turned 180° about
  // its long axis maps onto itself; seen from unit A's frame that is a turn
  // about the axis through (·, 0, 1.2) of the scene.
  RigidTransform swap_scene = RigidTransform::Identity();
  swap_scene.linear() = Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix();
  swap_scene.translation() = Vec3(0, 0, 2.4);
  RigidTransform a_pose = RigidTransform::Identity();
  a_pose.translation() = Vec3(-1.6, -0.9, 0.7);
  const RigidTransform swap = a_pose.inverse() * swap_scene * a_pose * s.truth;
  const PoseEvidence truth = v.evaluate(s.truth), wrong = v.evaluate(swap);
  EXPECT_EQ(truth.per_sample.size(), wrong.per_sample.size());
  // Right pose: stray samples only (mixed pixels are left out; noise beyond
  // 3σ_e on one side is 0.13 %).
  EXPECT_LT(static_cast<double>(truth.in_free_space), 0.005 * static_cast<double>(truth.per_sample.size()));
  // The cube carried to the ceiling hangs in unit A's free space, and the other way round.
  EXPECT_GT(wrong.in_free_space, 5 * truth.in_free_space + 30);
  const PoseComparison c = v.compare(truth, wrong);
  EXPECT_TRUE(c.decisive);
  EXPECT_GT(c.log_ratio, c.needed);
  // The margin is at least log(1/α) and z_α standard errors (z = 4.753 for α = 1e-6).
  EXPECT_GE(c.needed, -std::log(1e-6) - 1e-9);
  EXPECT_GE(c.needed, 4.75 * c.standard_error);
  EXPECT_LE(c.needed, std::max(-std::log(1e-6), 4.76 * c.standard_error));
  // A pose against itself is never decisive.
  EXPECT_FALSE(v.compare(truth, truth).decisive);
  EXPECT_NE(describePose(s.truth).find("90.00°"), std::string::npos);
}

TEST(PoseVerifier, BadInput) {
  const RoomScene s = alignedRoom();
  auto with = [&](auto change, const std::vector<std::string>& words) {
    PoseVerificationParams p;
    change(p);
    expectInvalidInput([&] { PoseVerifier v(s.reference, s.moving, p); }, words);
  };
  with([](PoseVerificationParams& p) { p.sigma_m = 0; }, {"PoseVerifier", "sigma_m"});
  with([](PoseVerificationParams& p) { p.free_space_outlier_rate = 1; }, {"free_space_outlier_rate"});
  with([](PoseVerificationParams& p) { p.false_accept_probability = 0; }, {"false_accept_probability"});
  with([](PoseVerificationParams& p) { p.samples_per_cloud = 3; }, {"samples_per_cloud"});
  with([](PoseVerificationParams& p) { p.coincidence_cell_m = 0; }, {"coincidence_cell_m"});
  expectInvalidInput([&] { PoseVerifier v(Cloud{}, s.moving); }, {"PoseVerifier", "at least 20 points"});
  const PoseVerifier v(s.reference, s.moving);
  PoseEvidence shorter = v.evaluate(s.truth, 100);
  expectInvalidInput([&] { v.compare(v.evaluate(s.truth), shorter); }, {"compare", "different samples"});
}

}  // namespace
}  // namespace sailshape
