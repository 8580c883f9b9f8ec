// What a measured scene can span (SPEC §3: 80 m of LMS511 range from a unit on a boat
// under 100 m long): a real sail's cloud passes, the same cloud in millimetres is named
// as such, and a cloud scaled by 1e30 or a non-finite value is refused.
#include "analysis/core/plausible.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace sailshape {
namespace {

// A 35 m luff on a boat whose mast foot is the origin, seen from a unit 20 m astern.
std::vector<Vec3> bigSail() { return {Vec3(0, 0, 1), Vec3(-2, 0, 36), Vec3(-14, 3, 2), Vec3(-20, 0, 2)}; }

std::vector<Vec3> scaled(std::vector<Vec3> points, double s) {
  for (Vec3& p : points) p *= s;
  return points;
}

TEST(Plausible, TheLargestSailsInMetresPass) {
  EXPECT_FALSE(implausibleCoordinates(bigSail(), "the cloud"));
  // The farthest a sample can lie: a unit at the far end of a 100 m boat, 80 m of range.
  EXPECT_FALSE(implausibleCoordinates({Vec3(kFarthestSampleM, 0, 0)}, "the cloud"));
  EXPECT_TRUE(implausibleCoordinates({Vec3(kFarthestSampleM * 1.01, 0, 0)}, "the cloud"));
}

TEST(Plausible, ACloudInMillimetresIsNamedAsSuch) {
  const auto why = implausibleCoordinates(scaled(bigSail(), 1000.0), "sail.ply");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("sail.ply looks like millimetres"), std::string::npos) << *why;
  // A small model sail in millimetres stays within 180 "m": it cannot be told from a
  // large sail in metres, so it passes (its analysis refuses its size later, if at all).
  EXPECT_FALSE(implausibleCoordinates(scaled({Vec3(0, 0, 0.1), Vec3(0, 0, 2.8)}, 1000.0 / 20), "model"));
}

TEST(Plausible, ACloudScaledBy1e30IsRefusedWithItsReach) {
  const auto why = implausibleCoordinates(scaled(bigSail(), 1e30), "the cloud");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("reaches 3.61e+31 m from the origin"), std::string::npos) << *why;
  EXPECT_EQ(why->find("millimetres"), std::string::npos) << *why;
  EXPECT_EQ(why->find('\n'), std::string::npos);
}

TEST(Plausible, NonFiniteCoordinatesAndResultsAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(implausibleCoordinates({Vec3(0, 0, 0), Vec3(nan, 0, 0)}, "the cloud"));
  EXPECT_TRUE(implausibleLength(nan, "the luff"));
  EXPECT_TRUE(implausibleLength(inf, "the luff"));
  EXPECT_TRUE(implausibleLength(-1, "the luff"));
  EXPECT_TRUE(implausibleArea(1e62, "the area"));
  EXPECT_FALSE(implausibleLength(35.2, "the luff"));
  EXPECT_FALSE(implausibleArea(450.0, "the area"));  // a maxi's gennaker
  // A length can span the whole scene, twice the farthest sample, and no more.
  EXPECT_FALSE(implausibleLength(2 * kFarthestSampleM, "the luff"));
  EXPECT_TRUE(implausibleLength(2 * kFarthestSampleM + 1, "the luff"));
}

}  // namespace
}  // namespace sailshape
