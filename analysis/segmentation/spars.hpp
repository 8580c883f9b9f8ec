#pragma once
// Finding the rig's spars (mast, boom, pole) in a registered cloud, so that a
// region of interest can leave them out where they really are: a registration
// good to a couple of centimetres puts the crew's measured spar a couple of
// centimetres off the scanned one, which is as much as the gap between a mast
// and the luff beside it.
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"

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
// search_m of its nominal axis: the axis position that the most points fit, less
// the points inside it (a vote over a 2 mm grid of sideways offsets), refined by
// least squares.
// When too few points support any position the nominal spar is returned with
// found = false. Throws InvalidInput for a zero axis, length or radius.
SparFit fitSpar(const Cloud& cloud, const Spar& nominal, const SparFitParams& params = {});

// How far p lies outside the spar's round surface or beyond its end faces (the
// larger of the two): negative inside. Below c means within c of the spar on
// every side, the flat ends included.
double distanceToSpar(const Vec3& p, const Spar& spar);

// The part of offset d across the unit `axis`: its perpendicular off the axis line.
Vec3 acrossAxis(const Vec3& d, const Vec3& axis);

// The longest gap along a spar of `radius_m` its points may leave and still be one run
// of them (two diameters and two bands): the search ends a spar at a wider one, and the
// pipeline gives a spar this much reach beyond its ends.
double sparRunGapM(double radius_m, double sensor_sigma_m);

// Finding spars nobody gave a place for: in a scene analysed without the rig's
// measurements, the mast 2 cm forward of the luff mixes into the neighbourhoods of
// the sail's luff strip; knowing the mast's round surface lets that strip come back
// without the mast's aft face, which lies in the sail's plane extended.
struct SparSearchParams {
  double sensor_sigma_m = 0.004;  // SPEC §3; a point within 2σ of the round surface supports it
  double min_radius_m = 0.01;
  double max_radius_m = 0.25;
  double min_length_radii = 8;    // a spar is long: its supported length is at least this × its radius
  // The supporting points span at least this much of the circumference, and a quarter
  // more than a flat strip could lie within the band at the fitted radius (66° at 9 cm,
  // so 83°). A scanner sees about half the girth; a turntable's fans cross a mast 6 m
  // away at 0.6° in three lines, which span about 90-100° of a 9 cm mast.
  double min_arc_deg = 80;
  size_t min_support = 100;
  // Random two-point samples per spar. A sparse scan's normals are fitted over
  // neighbourhoods wider than a mast, and few pairs give its cylinder: a few hundred
  // samples miss spars of a 5,000-point scene, 2,000 find them.
  int hypotheses = 2000;
  int max_spars = 3;
  unsigned seed = 1;              // the sampling's seed: the same cloud gives the same spars
};

struct SparSearch {
  std::vector<SparFit> spars;     // found ones only, most supported first
  std::vector<std::string> warnings;
};

// Round spars among cloud.points[candidates]: two points and their normals give a
// cylinder (its axis is across both normals); the few hypotheses most candidates fit,
// near-copies left out, are refined by least squares on axis, direction and radius, and
// the refined one most points fit among those that pass as a spar (support, length,
// arc round the axis, not within the band of one plane) wins. Its points are taken
// out and the next spar searched, up to max_spars; a stretch found on the line of an
// earlier spar at its radius joins it (refitted on both, over the gap between).
// `normals` has one per cloud point.
// A found spar's length runs on through the points of `length_from` on its surface
// (the sail cluster, which can have grown over the mast beside its luff) for as long as
// they keep round it, two scan lines' worth of its girth at least; they are not
// searched. Throws InvalidInput for a normals/cloud size mismatch, an index out of range
// or bad parameters.
SparSearch findSpars(const Cloud& cloud, const std::vector<Vec3>& normals, const std::vector<uint32_t>& candidates,
                     const SparSearchParams& params = {}, const std::vector<uint32_t>& length_from = {});

}  // namespace sailshape
