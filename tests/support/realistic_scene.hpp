#pragma once
// Realistic one-unit scans (issue 34, item 7): a full-size boat (hull, deck, mast,
// boom, forestay, optional bowsprit and spinnaker pole) scaled to its sail, one
// sail from the parametric generator with a flying shape drawn per seed, and one
// scanner unit at one of seven positions sweeping it as the product does. The
// scan itself is the emulator's: its ray caster and sensor model
// (acquisition/ray_caster, sensor_model), through realistic_sweep.hpp.
// Everything is drawn from one uint64 seed, deterministically. Boat frame
// (SPEC §2): +X forward, +Y port, +Z up, origin at the mast foot on deck, metres.
#include <cstdint>
#include <string>
#include <vector>

#include "acquisition/scene.hpp"
#include "acquisition/sensor_model.hpp"
#include "analysis/design/sail_generator.hpp"

namespace sailshape::realistic {

// The sails a loft measures, each mapped onto the generator's four types:
// a symmetric spinnaker is a gennaker with luff ≈ leech tacked at the pole's end,
// a code zero a flat gennaker with a nearly straight luff, a genoa a jib whose
// clew overlaps the mast.
enum class SailKind { PinHeadMain, SquareTopMain, Jib, Genoa, AsymBow, AsymSprit, SymSpinnaker, CodeZero };
// Where the one unit stands. Tunnel: a scaled model (boat, rig, sail) in a wind-tunnel chamber, the unit
// on the chamber floor beside it to leeward, as the study's tunnel units stood.
enum class UnitPlace { DeckLeeward, DeckWindward, SternPulpit, MastFoot, Bow, BoomEnd, Tunnel };

inline constexpr SailKind kSailKinds[] = {SailKind::PinHeadMain, SailKind::SquareTopMain, SailKind::Jib,
                                          SailKind::Genoa,       SailKind::AsymBow,       SailKind::AsymSprit,
                                          SailKind::SymSpinnaker, SailKind::CodeZero};
inline constexpr UnitPlace kUnitPlaces[] = {UnitPlace::DeckLeeward, UnitPlace::DeckWindward, UnitPlace::SternPulpit,
                                            UnitPlace::MastFoot,    UnitPlace::Bow,          UnitPlace::BoomEnd,
                                            UnitPlace::Tunnel};

std::string sailKindName(SailKind kind);     // "pin-head-main", "square-top-main", "jib", "genoa", "asym-bow", ...
std::string unitPlaceName(UnitPlace place);  // "deck-leeward", "deck-windward", "stern-pulpit", "mast-foot", ...
// The inverses; throw InvalidInput naming the names accepted.
SailKind parseSailKind(const std::string& name);
UnitPlace parseUnitPlace(const std::string& name);

// The boat, every length scaled with the mast (deck at z = 0 unless in the tunnel).
struct Boat {
  double mast_height_m = 12;      // deck to masthead
  double mast_radius_m = 0.09;
  double mast_rake_rad = 0;       // the mast leans aft by this, parallel to the main's luff
  double deck_z_m = 0;
  double stern_x_m = -6, bow_x_m = 4.5, half_beam_m = 1.8, keel_z_m = -1.2;
  double boom_z_m = 1.0, boom_radius_m = 0.06;
  Vec3 boom_end = Vec3(-4, 0, 1);  // the boom runs from the mast to here (swung to leeward)
  Vec3 stay_base = Vec3::Zero(), stay_top = Vec3::Zero();  // forestay
  double stay_radius_m = 0.006;
  double sprit_length_m = 0;      // bowsprit beyond the bow (0: none)
  bool pole = false;              // spinnaker pole from the mast to the tack
  Vec3 pole_end = Vec3::Zero();
  bool tunnel = false;            // a model in a wind-tunnel chamber
  Vec3 chamber_min = Vec3::Zero(), chamber_max = Vec3::Zero();
  // Deck half-width at x (square stern, pointed bow, as the emulator's hulls).
  double halfBeamAt(double x_m) const;
};

struct UnitSetup {
  ScannerModel model = ScannerModel::Lms511;
  Vec3 position = Vec3::Zero();   // scanner origin at β where p = 0 (the shaft's point), boat frame
  double yaw_rad = 0;             // the turntable's β = 0 direction, from +X towards +Y
  double p_m = 0, theta_rad = 0;  // SPEC §2 geometric constants of the unit
  // The sweep: scan lines every line_step_deg of β from beta_start_deg over sweep_deg;
  // beams every resolution_deg of α over [alpha_from_deg, alpha_to_deg] (the scanner's output range).
  double beta_start_deg = 0, sweep_deg = 90, line_step_deg = 0.25;
  double alpha_from_deg = -5, alpha_to_deg = 185, resolution_deg = 1.0 / 6.0;
  double frequency_hz = 25;
  // The unit frame's X axis is the turntable's (vertical) shaft: unit → boat frame.
  Eigen::Isometry3d pose() const;
};

struct Config {
  uint64_t seed = 0;
  SailKind sail = SailKind::PinHeadMain;
  UnitPlace place = UnitPlace::DeckLeeward;
  Boat boat;
  SailDesign design;
  UnitSetup unit;
  SensorModelParams sensor;
  std::string summary() const;  // "seed 123: genoa, luff 11.2 m, lms511 at deck-leeward (7.4 m from the tack)"
};

// Draws sail, unit place, scanner model, boat size, flying shape and sweep from `seed`.
Config drawConfig(uint64_t seed);
// The same, with the sail kind and unit place given (the rest drawn from the seed).
Config drawConfig(uint64_t seed, SailKind sail, UnitPlace place);

// The scene the unit scans: hull, mast, boom, forestay, sprit/pole, the sail ("sail"), and
// the tunnel's chamber for Tunnel.
Scene buildScene(const Config& config);

// What the analysis is judged against, all from SailSurface (the generator's own surface).
struct Truth {
  Vec3 tack, clew, head, peak;
  bool has_peak = false;
  // Edge arc lengths along the generator's own edges: luff tack → head, leech clew → head (peak),
  // foot tack → clew, top head → peak.
  double luff_m = 0, leech_m = 0, foot_m = 0, top_m = 0;
  std::vector<KnownSection> sections;  // at kSectionFractions
};
// A seed drawn fresh each run and printed; SAILSHAPE_REALISTIC_SEED replays one (for the tests).
uint64_t freshSeed();

// The analysis' default sections (SectionParams::count = 3).
inline constexpr double kSectionFractions[] = {0.25, 0.5, 0.75};
Truth truthOf(const SailDesign& design);

}  // namespace sailshape::realistic
