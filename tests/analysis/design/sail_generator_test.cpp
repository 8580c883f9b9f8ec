// The parametric generator's lean (SailDesign::lean_deg): the whole sail turned about the
// boat's X axis through the tack, its head towards leeward, its shape unchanged.
#include "analysis/design/sail_generator.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

TEST(SailGenerator, LeanTurnsTheSailAboutTheTackTowardsLeeward) {
  for (bool port : {true, false}) {
    SailDesign upright = exampleDesign(SailType::Gennaker);
    upright.leeward_port = port;
    SailDesign leaned = upright;
    leaned.lean_deg = 20;
    const SailSurface a(upright), b(leaned);
    const double side = port ? 1.0 : -1.0, lean = 20 * M_PI / 180;
    const Eigen::AngleAxisd turn(-side * lean, Vec3::UnitX());
    EXPECT_LT((b.tack() - a.tack()).norm(), 1e-12);
    // Every point of the leaned sail is the upright one's turned about the tack: the luff, the
    // head (towards leeward by luff height × sin 20°) and a point inside the cloth.
    for (double f : {0.0, 0.3, 0.7, 1.0}) {
      EXPECT_LT((b.luffPoint(f) - (a.tack() + turn * (a.luffPoint(f) - a.tack()))).norm(), 1e-9) << f;
      EXPECT_LT((b.leechPoint(f) - (a.tack() + turn * (a.leechPoint(f) - a.tack()))).norm(), 1e-9) << f;
    }
    const double rise = a.head().z() - a.tack().z();
    EXPECT_NEAR(side * (b.head().y() - a.head().y()), rise * std::sin(lean) + side * a.head().y() * (std::cos(lean) - 1),
                1e-9);
    // The shape at each height is the design's: same camber and draft, chords as long.
    for (double f : {0.25, 0.5, 0.75}) {
      EXPECT_EQ(b.section(f).camber_pct, a.section(f).camber_pct);
      EXPECT_EQ(b.section(f).draft_pct, a.section(f).draft_pct);
      EXPECT_NEAR(b.section(f).chord_m, a.section(f).chord_m, 1e-9);
    }
  }
}

TEST(SailGenerator, LeanBeyondSixtyDegreesIsRefused) {
  SailDesign d = exampleDesign(SailType::Gennaker);
  d.lean_deg = 75;
  EXPECT_THROW(validateDesign(d), InvalidInput);
}

}  // namespace
}  // namespace sailshape
