#include "analysis/spatial/direction_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "analysis/core/units.hpp"

namespace sailshape {
namespace {

// A unit at `scanner` sweeping vertical scan lines `between_deg` apart, each sampled
// every `along_deg`, onto a wall 6-9 m away (its range varies across the grid, as a
// sail's does): every sample where its beam meets the wall x = scanner.x + 6 + z/4.
std::vector<Vec3> wallOnGrid(const Vec3& scanner, double along_deg, double between_deg) {
  std::vector<Vec3> pts;
  for (double az = -20; az <= 20; az += between_deg)
    for (double el = -10; el <= 30; el += along_deg) {
      const double a = az * kRadPerDeg, e = el * kRadPerDeg;
      const Vec3 u(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      // x - z/4 = 6 along the beam scanner + t·u (wall relative to the scanner).
      const double t = 6.0 / (u.x() - 0.25 * u.z());
      pts.push_back(scanner + t * u);
    }
  return pts;
}

// The grid's coarser step is what a DirectionMap must span: an LMS111's 0.5° along its
// lines and the turntable's 0.25° between them; an LMS511's 1/6° and 0.25°; a 1° line
// step four times the turntable's; and the same grids shuffled (a plain file's order).
TEST(AngularGridStep, IsTheCoarserOfTheScanGridsTwoSteps) {
  const Vec3 scanner(1, -2, 0.5);
  struct Grid {
    double along_deg, between_deg;
  };
  for (const Grid g : {Grid{0.5, 0.25}, Grid{1.0 / 6.0, 0.25}, Grid{1.0, 0.25}, Grid{0.25, 0.25}}) {
    std::vector<Vec3> pts = wallOnGrid(scanner, g.along_deg, g.between_deg);
    std::mt19937 rng(3);
    std::shuffle(pts.begin(), pts.end(), rng);
    const double coarse_rad = std::max(g.along_deg, g.between_deg) * kRadPerDeg;
    EXPECT_NEAR(angularGridStep(pts, scanner), coarse_rad, 0.02 * coarse_rad)
        << "grid " << g.along_deg << "° along × " << g.between_deg << "° between";
  }
  EXPECT_EQ(angularGridStep({Vec3(1, 0, 0), Vec3(0, 1, 0)}, scanner), 0.0);
}

// Built at the grid's coarser step, the map finds a nearer thing (a pole between the
// unit and the wall, sampled on the same grid) in every direction it stands in, also
// between its scan lines; at the finer step, directions between its lines read as if
// the beams there met only the wall.
TEST(DirectionMap, AtTheGridsCoarserStepEveryDirectionOfAPoleFindsIt) {
  const Vec3 scanner(0, 0, 0);
  const double along = 0.5 * kRadPerDeg, between = 0.25 * kRadPerDeg;
  std::vector<Vec3> scene;
  // The pole: a vertical band 3 m out, 4° wide in azimuth, sampled on the grid.
  for (double az = -10; az <= 10; az += 0.25)
    for (double el = -5; el <= 5; el += 0.5) {
      const double a = az * kRadPerDeg, e = el * kRadPerDeg;
      const Vec3 u(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      scene.push_back((std::abs(az) <= 2 ? 3.0 : 8.0) * u);
    }
  const double step = angularGridStep(scene, scanner);
  ASSERT_NEAR(step, along, 0.02 * along);
  const DirectionMap coarse(scene, scanner, step), fine(scene, scanner, 0.4 * between);
  size_t missed_fine = 0, probes = 0;
  for (double az = -1.9; az <= 1.9; az += 0.05)
    for (double el = -4.9; el <= 4.9; el += 0.05) {
      const double a = az * kRadPerDeg, e = el * kRadPerDeg;
      const Vec3 u(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      ++probes;
      EXPECT_NEAR(coarse.nearest(u), 3.0, 1e-9) << az << "°, " << el << "°";
      missed_fine += fine.nearest(u) > 3.5;
    }
  EXPECT_GT(missed_fine, probes / 20);  // what the coarser cells are for
}

}  // namespace
}  // namespace sailshape
