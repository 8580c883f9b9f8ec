#pragma once
// Moving-least-squares smoothing (SPEC §4 step 4): each point is projected onto
// a weighted quadratic fitted to its neighbourhood in a local frame. How far
// each point moved is classed good (< good_m, the sensor σ), fair (< fair_m,
// σ + systematic error) or bad; the neighbourhood must keep bad points near zero.
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"

namespace sailshape {

struct SmoothingParams {
  // Neighbourhood size (its radius is the distance to the k-th neighbour): 200
  // brings 4 mm range noise on a section curve down enough for entry/exit angles
  // over 10 % of a short chord, while a sail curves too gently to be flattened.
  int k_neighbours = 200;
  // Denser than this (points/m², about a 10 m mainsail at 75,000 points), the k
  // nearest span a smaller patch and the noise left in the fitted slopes grows
  // as √density / k (degrees in the end angles under 4 mm noise at 200,000
  // points). There k grows with √density to hold it. 0: k stays fixed.
  double reference_density_per_m2 = 4000;
  // Sparser, the k nearest reach so far that the quadratic flattens the sections'
  // crests: on a 10 m main (280 points/m² at 5,000 points) 200 of them reach
  // 0.48 m, over half the 0.9 m chord at 3/4 height, and the camber reads low.
  // The radius is held to this fraction of the sail's size (√ of its area, from
  // the density) by taking fewer neighbours, down to 40: k ≤ π · ratio² · points,
  // 1.5 % of the sail's points at 0.07, so any cloud under 13,000 points takes fewer
  // than 200. The fraction balances the crest's flattening (a larger one) against
  // the end angles' noise (a smaller one) over sparse clouds; denser clouds are
  // left alone. A cloud noisier for its size than 4 mm (good_m) on that 18 m² sail
  // gains more from averaging: the limit grows as (relative noise)^0.2, so a 1:5
  // wind-tunnel model under 4 mm noise keeps about the neighbourhood it would have
  // without the limit. 0: no limit.
  double max_radius_ratio = 0.07;
  // Those neighbourhoods are sized for the sensor's noise (good_m). A cloud whose
  // measured noise (the RMS off quadratics through 24 neighbours) is under half of
  // that needs less averaging and takes a smaller one: k shrinks with √(noise /
  // (good_m / 2)), down to 40. The quadratic's bias grows with the radius: on a
  // clean 1:5 model mainsail 400 neighbours span half its 18 cm top chord, and
  // its exit angle and twist follow the flattened curve. false: k as above
  // whatever the noise.
  bool adapt_to_noise = true;
  int polynomial_order = 2;     // 1: plane, 2: quadratic
  // 0: a local surface fitted at every point (MLS proper). > 0: inside the
  // surface, quadratics fitted at anchors about anchor_ratio × the
  // neighbourhood radius apart, each point projected onto a blend of its
  // nearest anchors' (the quadratic carries the curvature across the gap);
  // near edges, where neighbourhoods turn one-sided, and for plane fits
  // (polynomial_order 1), every point still gets its own fit. At 0.5, about
  // a fifth of the fits; points land within ~0.1 mm RMS (< 1 mm max) of plain
  // MLS under 4 mm noise.
  double anchor_ratio = 0.5;
  double good_m = 0.004;        // sensor random error σ (SPEC §3)
  double fair_m = 0.009;        // σ + systematic error: 9 mm at model scale, 14 mm full scale
};

struct Smoothing {
  Cloud cloud;                        // smoothed points, attributes carried over
  std::vector<float> displacement_m;  // per point, how far it moved
  size_t good = 0, fair = 0, bad = 0;
  double rms_displacement_m = 0;
  double max_displacement_m = 0;
  double mean_radius_m = 0;           // mean neighbourhood radius used
  size_t k_used = 0;                  // neighbours per fit: k_neighbours, more in a dense cloud
  double measured_noise_m = 0;        // the cloud's noise as measured (adapt_to_noise, max_radius_ratio)
  size_t fitted_surfaces = 0;         // local surfaces fitted (every point's without anchors)
  std::vector<std::string> warnings;
};

Smoothing smoothMls(const Cloud& cloud, const SmoothingParams& params = {}, const Progress& progress = {});

}  // namespace sailshape
