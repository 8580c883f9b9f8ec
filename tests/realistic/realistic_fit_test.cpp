// The design fit on a realistic one-unit scan (tests/support/realistic_*): a square-top main
// flying 3 % deeper and 2° + 10°·f more twisted than its design, on a boat, swept by one unit
// from the leeward deck through the emulator's ray caster and sensor model. The scan's gaps
// are the scanner's own (grazing angles, range, the boom's and mast's shadows).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "analysis/design/design_compare.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "tests/support/fit_case.hpp"
#include "tests/support/realistic_scene.hpp"
#include "tests/support/realistic_sweep.hpp"

namespace sailshape::realistic {
namespace {

TEST(RealisticFit, OneUnitScanOfTheSailFlyingDeeperAndMoreTwisted) {
  Config config = drawConfig(freshSeed(), SailKind::SquareTopMain, UnitPlace::DeckLeeward);
  std::printf("%s\n", config.summary().c_str());
  const SailDesign design = config.design;
  config.design = deeperAndMoreTwisted(design);
  const Scan scan = sweepScene(config, buildScene(config), 2);
  const Cloud sail = sailSamples(scan.cloud);
  // The design's mesh as fine as the 10 m sail's 80 × 40 (12.5 cm rows, 9 cm columns) whatever
  // the sail's size: a mesh's own chord error (l²κ/8) must stay well under the noise.
  const int rows = std::max(80, static_cast<int>(std::ceil(design.luff_m / 0.125)));
  const int columns = std::max(40, static_cast<int>(std::ceil(design.foot_m / 0.09)));
  const Mesh design_mesh = generateSailMesh(design, rows, columns);
  const DesignFit fit = fitDesign(design_mesh, sail.points);
  for (const auto& w : fit.warnings) std::printf("warning: %s\n", w.c_str());

  const DesignDistance truth(generateSailMesh(config.design, 320, 160));
  double scanned2 = 0, inferred2 = 0, design_inferred2 = 0;
  size_t scanned = 0, inferred = 0, within_3_sigma = 0;
  for (size_t v = 0; v < design_mesh.vertices.size(); ++v) {
    const double d = truth.signedDistance(fit.fitted.vertices[v]);
    if (fit.supported[v]) {
      scanned2 += d * d;
      ++scanned;
    } else {
      const double d0 = truth.signedDistance(design_mesh.vertices[v]);
      inferred2 += d * d;
      design_inferred2 += d0 * d0;
      within_3_sigma += std::abs(d) <= 3 * fit.sigma_m[v] ? 1 : 0;
      ++inferred;
    }
  }
  const double scanned_rms = std::sqrt(scanned2 / std::max<size_t>(1, scanned));
  // The samples' own offset from the flying sail, averaged over the neighbourhoods the fit
  // averages over: the mean signed distance of the samples near each supported vertex.
  double bias2 = 0;
  size_t biased = 0;
  {
    const KdTree tree(sail.points);
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    for (size_t v = 0; v < design_mesh.vertices.size(); ++v) {
      if (!fit.supported[v]) continue;
      tree.nearest(fit.fitted.vertices[v], 16, idx, d2);
      double mean = 0;
      for (uint32_t i : idx) mean += truth.signedDistance(sail.points[i]);
      mean /= static_cast<double>(idx.size());
      bias2 += mean * mean;
      ++biased;
    }
  }
  const double sample_bias_rms = std::sqrt(bias2 / std::max<size_t>(1, biased));
  std::printf("the samples' own local mean offset from the flying sail: rms %.1f mm\n", 1e3 * sample_bias_rms);
  const double inferred_rms = std::sqrt(inferred2 / std::max<size_t>(1, inferred));
  const double design_rms = std::sqrt(design_inferred2 / std::max<size_t>(1, inferred));
  std::printf("%zu scan points, %zu sail samples; coverage %.3f, rms to samples %.1f mm (noise %.1f mm)\n",
              scan.cloud.size(), sail.size(), fit.coverage, 1e3 * fit.rms_m, 1e3 * fit.noise_m);
  std::printf("scanned %zu vertices rms %.1f mm; inferred %zu rms %.1f mm (design alone %.1f mm), %zu within 3σ\n",
              scanned, 1e3 * scanned_rms, inferred, 1e3 * inferred_rms, 1e3 * design_rms, within_3_sigma);
  // One unit on the leeward deck sees the lower sail well and the upper at grazing angles or
  // out of range (coverage 2-45 % over seeds): the fit has samples on a part of the sail.
  ASSERT_GT(scanned, 0u);
  // Where scanned, through the samples as on an even scan (issue 37: 3 mm RMS) on top of what
  // the samples themselves are off: the sensor's systematic range error (SPEC §3: up to 0.3 %
  // of the range, several mm at 10-20 m) moves whole neighbourhoods, and no fit through them
  // can take it out.
  EXPECT_LT(scanned_rms, std::hypot(0.003, sample_bias_rms));
  // Where inferred (most of the sail, metres from the last samples, beyond issue 37's 12 % of
  // the height), σ says how far the fit may be off: most vertices lie within 3σ of the flying
  // sail, whatever the scan saw.
  ASSERT_GT(inferred, 0u);
  EXPECT_GT(static_cast<double>(within_3_sigma), 0.8 * static_cast<double>(inferred));
  // And the fit is closer to the flying sail than the design alone. How much closer depends
  // on how much of the change the scan saw: the constant part of the twist and the camber
  // change in the lower sail carry over, the rest of the twist (10°·f) grows where no sample
  // was. The 15 and 40 mm targets are the known-answer tests' (design_fit_test.cpp),
  // with the whole sail below 88 % of the height scanned.
  EXPECT_LT(inferred_rms, design_rms);
}

}  // namespace
}  // namespace sailshape::realistic
