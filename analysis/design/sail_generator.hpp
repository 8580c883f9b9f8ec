#pragma once
// Parametric sails in the boat frame (SPEC §2, §7): triangular and square-top
// mainsails, jibs and asymmetric spinnakers. A sail is a family of sections:
// section f (0 foot … 1 head) runs from the luff point at arc fraction f to the
// leech point at arc fraction f, and its mean line has the camber, draft and
// entry/exit slopes of the stations interpolated at f. The same generator makes
// design shapes and flying shapes (a flying shape is a design whose parameters
// moved with trim), and synthetic scans with known answers for the tests.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"

namespace sailshape {

enum class SailType { Main, SquareTopMain, Jib, Gennaker };

std::string sailTypeName(SailType type);
// "main", "square-top", "jib", "gennaker"; throws InvalidInput otherwise.
SailType parseSailType(const std::string& name);

// Shape at one height; stations are interpolated smoothly (monotone cubic) in f.
struct ProfileStation {
  double fraction = 0;        // section fraction f in [0, 1]
  double camber_pct = 10;     // maximum depth, % of chord
  double draft_pct = 45;      // position of maximum depth from the luff, % of chord
  double twist_deg = 10;      // chord angle to the centreline in the XY plane
  double entry_factor = 2.0;  // luff slope = factor · camber / draft (2: parabolic entry), in (0, 3]
  double exit_factor = 2.0;   // leech slope = factor · camber / (1 − draft), in (0, 3]
};

struct SailDesign {
  SailType type = SailType::Main;
  double luff_m = 10.0;        // straight tack → head distance
  double leech_m = 10.5;       // straight clew → head (peak for square tops) distance
  double foot_m = 3.6;         // straight tack → clew distance
  double head_width_m = 0.0;   // head → peak (square tops only)
  Vec3 tack{0.0, 0.0, 1.0};
  double rake_deg = 3.0;       // luff tilt aft from vertical
  double luff_round_m = 0.0;   // luff curve, forward, at mid luff (gennakers)
  double luff_sag_m = 0.0;     // luff sag to leeward at mid luff (gennakers)
  double leech_round_m = 0.0;  // roach, outwards at mid leech
  bool leeward_port = true;    // camber and twist towards +Y (starboard tack)
  // The whole sail leaned about the boat's X axis through the tack, its head towards leeward by
  // this angle: a symmetric spinnaker tacked to windward on its pole with its head at the masthead.
  double lean_deg = 0.0;
  std::vector<ProfileStation> stations{{0.0, 9, 45, 8, 2, 2}, {0.5, 11, 45, 14, 2, 2}, {1.0, 8, 50, 22, 2, 2}};
};

// Ready-made designs of each type (metres), for the demo, the emulator and tests.
SailDesign exampleDesign(SailType type);

// Throws InvalidInput naming the offending field.
void validateDesign(const SailDesign& design);

// The design at `scale` (a wind-tunnel model of it): every length and the tack
// position scaled, shape stations (percentages and angles) unchanged.
SailDesign scaleDesign(SailDesign design, double scale);

// The parameters a section of the design has, by construction.
struct KnownSection {
  double fraction = 0;
  Vec3 luff_point = Vec3::Zero(), leech_point = Vec3::Zero();
  double chord_m = 0, camber_pct = 0, draft_pct = 0, twist_deg = 0, entry_deg = 0, exit_deg = 0;
};

class SailSurface {
 public:
  explicit SailSurface(const SailDesign& design);
  const SailDesign& design() const { return design_; }
  // Point at section fraction f ∈ [0, 1] and chord fraction u ∈ [0, 1].
  Vec3 at(double f, double u) const;
  Vec3 luffPoint(double f) const;
  Vec3 leechPoint(double f) const;
  ProfileStation stationAt(double f) const;  // interpolated shape at f
  KnownSection section(double f) const;
  Vec3 tack() const { return luffPoint(0); }
  Vec3 clew() const { return leechPoint(0); }
  Vec3 head() const { return luffPoint(1); }
  Vec3 peak() const { return leechPoint(1); }  // equals head for triangular sails

 private:
  Vec3 depthDirection(double f) const;  // unit offset direction of section f's mean line

  SailDesign design_;
  std::vector<Vec3> luff_, leech_;  // arc-length uniform polylines, foot → head
  // Rotation of each section's plane about its chord (on a uniform f grid), so
  // that the plane holds the surface normal at maximum camber, as SPEC §5 cuts it.
  std::vector<double> plane_roll_rad_;
};

// Triangle mesh of the design (rows along f, columns along u; a triangular
// sail's head row collapses to one vertex).
Mesh generateSailMesh(const SailDesign& design, int rows = 80, int columns = 40);

struct ScanSimulation {
  size_t points = 50'000;           // on the sail
  double noise_sigma_m = 0.0;       // range noise along the ray from the viewpoint
  uint64_t seed = 1;
  Vec3 viewpoint{-8.0, -9.0, 5.0};  // scanner position, boat frame
};

// Points spread uniformly over the sail's area, with range noise.
Cloud sampleSail(const SailDesign& design, const ScanSimulation& sim);

// The sail in a scene: mast, boom and a deck at the same point density.
struct SceneCloud {
  Cloud cloud;
  std::vector<char> is_sail;  // per point
};
SceneCloud sampleSailScene(const SailDesign& design, const ScanSimulation& sim);

}  // namespace sailshape
