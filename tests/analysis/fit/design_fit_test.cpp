// The design fitted to a scan of the same sail flying deeper and more twisted (issue 37's
// known answers): through the samples within the noise, smooth across the gaps.
#include "analysis/fit/design_fit.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <algorithm>
#include <array>

#include "analysis/design/design_compare.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "tests/support/fit_case.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

void print(const char* what, const std::array<RegionError, 3>& e) {
  std::printf("%s: scanned %zu rms %.1f max %.1f mm; hole %zu rms %.1f max %.1f mm; above %zu rms %.1f max %.1f mm\n",
              what, e[0].count, 1e3 * e[0].rms_m, 1e3 * e[0].max_m, e[1].count, 1e3 * e[1].rms_m, 1e3 * e[1].max_m,
              e[2].count, 1e3 * e[2].rms_m, 1e3 * e[2].max_m);
}

// Issue 37's known answers, for a scan `c` of the sail flying deeper and more twisted.
void expectKnownAnswers(const FitCase& c, const FitCaseOptions& o, const std::vector<Vec3>& samples) {
  const DesignFit fit = fitDesign(c.design_mesh, samples);
  std::printf("fit: rms %.2f mm, noise %.2f mm, coverage %.3f, strain p95 %.2f %% max %.2f %%\n", 1e3 * fit.rms_m,
              1e3 * fit.noise_m, fit.coverage, fit.strain.p95_pct, fit.strain.max_pct);
  for (const auto& w : fit.warnings) std::printf("warning: %s\n", w.c_str());
  ASSERT_EQ(fit.fitted.vertices.size(), c.design_mesh.vertices.size());
  ASSERT_EQ(fit.fitted.triangles, c.design_mesh.triangles);
  const auto before = regionErrors(c.design_mesh.vertices, c, o);
  const auto after = regionErrors(fit.fitted.vertices, c, o, &fit.supported, &fit.sigma_m);
  print("design", before);
  print("fitted", after);
  // The test means something: above the last samples the design alone is 150–250 mm off.
  EXPECT_GT(before[2].rms_m, 0.150);
  EXPECT_LT(before[2].rms_m, 0.250);
  EXPECT_GT(before[1].rms_m, 0.150);  // and as far in the hole
  // Where scanned, through the samples: the 4 mm noise (SPEC §3) averages over the samples
  // on each vertex's triangles (about a dozen at this density), well under 3 mm.
  ASSERT_GT(after[0].count, c.design_mesh.vertices.size() / 2);
  EXPECT_LT(after[0].rms_m, 0.003);
  // In the hole (20 % of the height, 60 % of the chord), bridged from all around.
  ASSERT_GT(after[1].count, 100u);
  EXPECT_LT(after[1].rms_m, 0.015);
  // Above the last samples (the top 12 %), continued from below.
  ASSERT_GT(after[2].count, 100u);
  EXPECT_LT(after[2].rms_m, 0.040);
  // σ says where the surface was inferred: small where scanned, and covering the error
  // above the samples for most vertices.
  std::vector<double> sig_scanned, sig_above;
  for (size_t v = 0; v < fit.sigma_m.size(); ++v) (fit.supported[v] ? sig_scanned : sig_above).push_back(fit.sigma_m[v]);
  std::sort(sig_scanned.begin(), sig_scanned.end());
  EXPECT_LT(sig_scanned[sig_scanned.size() / 2], kSigma);
  EXPECT_GT(static_cast<double>(after[2].within_3_sigma), 0.8 * static_cast<double>(after[2].count));
  // Strain: the generator maps design (f, u) to flying (f, u), which stretches the edges of
  // this deeper, more twisted sail by 3.3 % at the 95th percentile; the fit need not find that
  // same map where the surface gives no tangential hold, so the two agree to 1.5 points.
  const Mesh flying_mesh = generateSailMesh(c.flying, o.rows, o.columns);
  std::vector<double> true_strain;
  for (const auto& t : c.design_mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      true_strain.push_back(100 * ((flying_mesh.vertices[a] - flying_mesh.vertices[b]).norm() /
                                       (c.design_mesh.vertices[a] - c.design_mesh.vertices[b]).norm() -
                                   1));
    }
  std::sort(true_strain.begin(), true_strain.end());
  const double true_p95 = true_strain[true_strain.size() * 19 / 20];
  std::printf("strain p95: true %.2f %%, fitted %.2f %%\n", true_p95, fit.strain.p95_pct);
  EXPECT_NEAR(fit.strain.p95_pct, true_p95, 1.5);
}

TEST(DesignFit, DeeperAndMoreTwistedThroughGaps) {
  FitCaseOptions o;
  o.seed = freshTestSeed();
  const FitCase c = makeFitCase(o);
  expectKnownAnswers(c, o, c.scan.points);
}

// The same in a scene (mast, boom and deck at the same density): the pipeline's segmentation
// hands the fit the sail's own samples, and the fit meets the same known answers.
TEST(DesignFit, DeeperAndMoreTwistedInASceneAfterSegmentation) {
  FitCaseOptions o;
  o.seed = freshTestSeed();
  o.scene = true;
  const FitCase c = makeFitCase(o);
  const Cloud sail = sailSamples(c.scan);
  size_t foreign = 0, sail_points = 0;
  for (char s : c.is_sail) sail_points += s ? 1 : 0;
  {
    // Samples the segmentation kept that are not the sail: within a few σ of a spar's surface.
    const DesignDistance truth(generateSailMesh(c.flying, 320, 160));
    for (const Vec3& p : sail.points) foreign += std::abs(truth.signedDistance(p)) > 5 * kSigma ? 1 : 0;
  }
  std::printf("segmentation kept %zu of %zu sail points, %zu more than 5σ off the sail\n", sail.size(), sail_points,
              foreign);
  // As analyze's segmentation does on this scene (tests/analysis/pipeline): nearly every sail
  // point, at most 1 % foreign ones.
  EXPECT_GT(static_cast<double>(sail.size()), 0.9 * static_cast<double>(sail_points));
  EXPECT_LE(static_cast<double>(foreign), 0.01 * static_cast<double>(sail.size()));
  expectKnownAnswers(c, o, sail.points);
}

TEST(DesignFit, RefusesBadInputNamingIt) {
  FitCaseOptions o;
  o.points = 5000;
  const FitCase c = makeFitCase(o);
  expectInvalidInput([&] { fitDesign(c.design_mesh, {}); }, {"no points"});
  expectInvalidInput([&] { fitDesign(Mesh{}, c.scan.points); }, {"no triangles"});
  std::vector<Vec3> nan = c.scan.points;
  nan[17].y() = std::nan("");
  expectInvalidInput([&] { fitDesign(c.design_mesh, nan); }, {"point 17", "non-finite"});
  // The same sail 30 m away: not in the design's frame.
  std::vector<Vec3> far = c.scan.points;
  for (Vec3& p : far) p += Vec3(30, 0, 0);
  expectInvalidInput([&] { fitDesign(c.design_mesh, far); }, {"from the design", "not in the boat frame"});
  Mesh broken = c.design_mesh;
  broken.triangles[3][1] = 999999;
  expectInvalidInput([&] { fitDesign(broken, c.scan.points); }, {"vertex index 999999"});
  DesignFitParams p;
  p.bending_length_m = 0;
  expectInvalidInput([&] { fitDesign(c.design_mesh, c.scan.points, p); }, {"bending_length_m"});
  p = {};
  p.outer_iterations = 0;
  expectInvalidInput([&] { fitDesign(c.design_mesh, c.scan.points, p); }, {"outer_iterations"});
}

// A design that stands a few cm off in the boat frame (a tack fitting 5 cm aft and lower, a
// degree more rake) is brought onto the scan by the rigid stage first; the fitted surface then
// passes through the samples as if the design had been placed right.
TEST(DesignFit, RigidStageCorrectsAMisplacedDesign) {
  FitCaseOptions o;
  o.seed = freshTestSeed();
  FitCase c = makeFitCase(o);
  c.flying = c.design;  // the same shape: only the placement differs
  ScanSimulation sim;
  sim.points = 40'000;
  sim.noise_sigma_m = kSigma;
  sim.seed = o.seed;
  const Cloud scan = sampleSail(c.flying, sim);
  Mesh moved = c.design_mesh;
  const Eigen::Isometry3d t = Eigen::Translation3d(-0.05, 0.0, -0.03) * Eigen::AngleAxisd(0.0175, Vec3::UnitY());
  for (Vec3& v : moved.vertices) v = t * v;
  const DesignFit fit = fitDesign(moved, scan.points);
  for (const auto& w : fit.warnings) std::printf("warning: %s\n", w.c_str());
  // The rigid stage undid most of the move (5.8 cm, 17.5 mrad): its transform composed with t
  // is the identity within a tenth of the rotation and under half the translation. Its own
  // limit is not the noise (σ/√n of its 5,000 pairs is 0.06 mm) but the samples at the sail's
  // edges, paired with the moved design's edge, and the sail's weak curvature along itself:
  // across the sail (the design's mean normal, which the pairs see directly) it is within 3 mm.
  // The non-rigid stage takes the rest: the fitted surface lies on the true one within
  // issue 37's 3 mm RMS.
  const Eigen::Matrix4d undo = fit.rigid * t.matrix();
  const Vec3 residual = undo.block<3, 1>(0, 3);
  Vec3 mean_normal = Vec3::Zero();
  for (const Vec3& n : vertexNormals(c.design_mesh)) mean_normal += n;
  mean_normal.normalize();
  std::printf("residual translation %.2f mm, across the sail %.2f mm, rotation %.3f mrad\n", 1e3 * residual.norm(),
              1e3 * std::abs(residual.dot(mean_normal)),
              1e3 * Eigen::AngleAxisd(Eigen::Matrix3d(undo.block<3, 3>(0, 0))).angle());
  EXPECT_LT(std::abs(residual.dot(mean_normal)), 0.003);
  EXPECT_LT(residual.norm(), 0.025);
  EXPECT_LT(Eigen::AngleAxisd(Eigen::Matrix3d(undo.block<3, 3>(0, 0))).angle(), 0.00175);
  EXPECT_LT(fit.rms_m, 1.2 * kSigma);
  FitCaseOptions whole = o;
  whole.hole_h_from = whole.hole_h_to = 2;  // no gaps: every region is scanned
  whole.top_h = 2;
  const auto e = regionErrors(fit.fitted.vertices, c, whole, &fit.supported);
  std::printf("fitted: %zu scanned vertices, rms %.2f mm\n", e[0].count, 1e3 * e[0].rms_m);
  EXPECT_GT(e[0].count, c.design_mesh.vertices.size() * 9 / 10);
  EXPECT_LT(e[0].rms_m, 0.003);
}

}  // namespace
}  // namespace sailshape
