#pragma once
// Finding the rig's spars (mast, boom, pole) in a registered cloud, so that a
// region of interest can leave them out where they really are: a registration
// good to a couple of centimetres puts the crew's measured spar a couple of
// centimetres off the scanned one, which is as much as the gap between a mast
// and the luff beside it.
#include <string>
#include <vector>

#include "analysis/cloud.hpp"

namespace sailshape {

// A straight round spar: axis from `base` along unit `axis` for length_m.
struct Spar {
  std::string name;
  Vec3 base = Vec3::Zero(), axis = Vec3::UnitZ();
  double length_m = 0, radius_m = 0;
};

struct SparFitParams {
  double search_m = 0.05;       // how far from its nominal place the spar may be found, sideways
  double sensor_sigma_m = 0.004;  // SPEC §3; a point within 2σ of the round surface supports it
  size_t min_support = 30;      // fewer supporting points: the spar is reported as not found
};

struct SparFit {
  Spar spar;                    // the nominal spar moved sideways to where the cloud has it
  bool found = false;
  Vec3 offset = Vec3::Zero();   // fitted minus nominal axis position, perpendicular to the axis, m
  size_t support = 0;           // points on the fitted surface (within 2σ)
  double rms_m = 0;             // RMS distance of those points from the surface
  std::string message;          // why it was not found
};

// Looks for the spar's round surface (radius and direction as given) within
// search_m of its nominal axis: the axis position that the most points fit
// (a vote over a 2 mm grid of sideways offsets), refined by least squares.
// When too few points support any position the nominal spar is returned with
// found = false. Throws InvalidInput for a zero axis, length or radius.
SparFit fitSpar(const Cloud& cloud, const Spar& nominal, const SparFitParams& params = {});

// How far p lies outside the spar's round surface or beyond its end faces (the
// larger of the two): negative inside. Below c means within c of the spar on
// every side, the flat ends included.
double distanceToSpar(const Vec3& p, const Spar& spar);

}  // namespace sailshape
