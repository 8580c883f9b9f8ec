#pragma once
// Mixed pixels (SPEC §3): a beam straddling an edge returns a range between the
// surfaces it straddles. Behind a sail's edge, with another sail or a wall beyond
// it, such samples hang in the air between the two: a main's head seen against the
// gennaker behind it grows a fringe centimetres deep, which the outlier filters take
// for sail, and the corner moves out with it by decimetres.
//
// They are found on the scan's own grid, from the samples' scan angles and the
// scanner's position: along each scan line (α) and across the lines (β), a range
// step off the surface's own slope on both sides is an edge (a short stretch of
// large steps the same way, as a transition through several mixed samples makes,
// is measured against the slopes beyond it), and a short run of samples between
// two edges stepping the same way (nearer on one side, farther on the other) lies
// between two surfaces: mixed. A thin object in front of its background (nearer
// than both sides) or a gap onto it (farther than both) stays, and so does an edge
// against the sky, where nothing lies beyond. A steep surface steps evenly and is
// no edge.
#include "analysis/core/cloud.hpp"
#include "analysis/segmentation/cleaning.hpp"

namespace sailshape {

struct MixedPixelParams {
  double sensor_sigma_m = 0.004;  // range noise (1σ); AnalysisParams sets it from its own
  // An edge: a range step off the slope on either side by more than this many σ
  // of a second difference of ranges (√6 σ).
  double jump_sigmas = 5.0;
  // Or, without a slope beside it, steeper than a surface seen at this incidence
  // (SPEC §3: no return at grazing angles).
  double max_incidence_deg = 80.0;
  // A run between two edges stepping the same way is mixed when it spans at most
  // this angle: the transition across an edge lasts about the beam's footprint
  // (exit window over range plus divergence, 8-19 mrad at 3.6 m for SPEC's
  // scanners), and a sail's own strip between a nearer and a farther object is
  // far wider.
  double max_run_rad = 0.02;
  // This many samples missing in a row (no return) still leave their neighbours adjacent.
  int max_missing = 2;
};

// Needs the samples' scan angles (α, β) and the cloud's viewpoint; without them
// every point is kept, with a warning saying why. `kept` and `removed` index the
// cloud, ascending.
Cleaning removeMixedPixels(const Cloud& cloud, const MixedPixelParams& params = {});

// Throws InvalidInput naming the parameter.
void checkMixedPixelParams(const MixedPixelParams& params);

// A scan line as the mixed-pixel grid reads it off the angles: its samples and
// their mean turntable angle β.
struct ScanLine {
  double beta_rad = 0;
  std::vector<uint32_t> samples;
};
// The cloud's scan lines by ascending β; none without finite scan angles.
std::vector<ScanLine> scanLines(const Cloud& cloud);
// The turntable's step between the cloud's scan lines (rad), their median; 0 with
// fewer than two lines.
double scanLineStepRad(const Cloud& cloud);

}  // namespace sailshape
