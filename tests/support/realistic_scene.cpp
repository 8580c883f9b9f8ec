#include "tests/support/realistic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape::realistic {
namespace {

constexpr double kDeg = kPi / 180.0;

struct Draw {
  std::mt19937_64 rng;
  explicit Draw(uint64_t seed) : rng(seed) {}
  double operator()(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  bool chance(double p) { return (*this)(0.0, 1.0) < p; }
  size_t pick(size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); }
};

bool isMain(SailKind k) { return k == SailKind::PinHeadMain || k == SailKind::SquareTopMain; }
bool isHeadsail(SailKind k) { return k == SailKind::Jib || k == SailKind::Genoa; }

// A hull as a prism, as the emulator's scenes build it: the deck outline (square stern,
// pointed bow from 60 % of the length) at deck_z, the same outline narrowed at the keel line.
Mesh hullMesh(const Boat& b) {
  const double shoulder = b.stern_x_m + 0.6 * (b.bow_x_m - b.stern_x_m);
  const std::vector<std::pair<double, double>> outline{{b.stern_x_m, -b.half_beam_m},
                                                       {shoulder, -b.half_beam_m},
                                                       {b.bow_x_m, 0.0},
                                                       {shoulder, b.half_beam_m},
                                                       {b.stern_x_m, b.half_beam_m}};
  Mesh m;
  const size_t n = outline.size();
  for (const auto& [x, y] : outline) m.vertices.emplace_back(x, y, b.deck_z_m);
  for (const auto& [x, y] : outline) m.vertices.emplace_back(x, 0.4 * y, b.keel_z_m);
  const auto u = [](size_t i) { return static_cast<uint32_t>(i); };
  for (size_t i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({0, u(i), u(i + 1)});
    m.triangles.push_back({u(n), u(n + i + 1), u(n + i)});
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    m.triangles.push_back({u(i), u(n + i), u(n + j)});
    m.triangles.push_back({u(i), u(n + j), u(j)});
  }
  return m;
}

// Flying shape stations at the foot, mid height and head, in plausible ranges per kind:
// camber and draft in %, twist in degrees to the centreline.
std::vector<ProfileStation> drawStations(SailKind kind, Draw& draw) {
  double camber_lo, camber_hi, draft_lo, draft_hi, twist_lo, twist_hi, twist_gain_lo, twist_gain_hi;
  switch (kind) {
    case SailKind::PinHeadMain:
    case SailKind::SquareTopMain:
      camber_lo = 6, camber_hi = 14, draft_lo = 38, draft_hi = 52, twist_lo = 2, twist_hi = 9;
      twist_gain_lo = 8, twist_gain_hi = 20;
      break;
    case SailKind::Jib:
    case SailKind::Genoa:
      camber_lo = 8, camber_hi = 15, draft_lo = 33, draft_hi = 45, twist_lo = 7, twist_hi = 14;
      twist_gain_lo = 6, twist_gain_hi = 14;
      break;
    case SailKind::AsymBow:
    case SailKind::AsymSprit:
      camber_lo = 16, camber_hi = 26, draft_lo = 42, draft_hi = 52, twist_lo = 25, twist_hi = 40;
      twist_gain_lo = 15, twist_gain_hi = 30;
      break;
    case SailKind::SymSpinnaker:
      camber_lo = 18, camber_hi = 28, draft_lo = 45, draft_hi = 55, twist_lo = 55, twist_hi = 70;
      twist_gain_lo = 5, twist_gain_hi = 15;
      break;
    case SailKind::CodeZero:
    default:
      camber_lo = 4, camber_hi = 8, draft_lo = 35, draft_hi = 45, twist_lo = 12, twist_hi = 20;
      twist_gain_lo = 8, twist_gain_hi = 15;
      break;
  }
  const double twist0 = draw(twist_lo, twist_hi), gain = draw(twist_gain_lo, twist_gain_hi);
  std::vector<ProfileStation> out;
  for (double f : {0.0, 0.5, 1.0}) {
    ProfileStation s;
    s.fraction = f;
    // Deepest at mid height, flatter at the foot and the head.
    const double mid = 1.0 - 0.25 * std::abs(2 * f - 1);
    s.camber_pct = draw(camber_lo, camber_hi) * mid;
    s.draft_pct = draw(draft_lo, draft_hi);
    s.twist_deg = std::min(88.0, twist0 + gain * f * draw(0.85, 1.15));
    s.entry_factor = draw(1.6, 2.6);
    s.exit_factor = draw(1.4, 2.4);
    out.push_back(s);
  }
  return out;
}

// The luff the sail is drawn at, before the rig fixes it: 6-35 m full size, 1.8-3 m in the tunnel.
// Mast heights follow from it by each kind's luff / mast ratio.
double mastRatio(SailKind kind) {
  switch (kind) {
    case SailKind::PinHeadMain:
    case SailKind::SquareTopMain: return 0.87;
    case SailKind::Jib: return 0.80;
    case SailKind::Genoa: return 0.85;
    case SailKind::AsymBow: return 1.05;
    case SailKind::AsymSprit: return 1.1;
    case SailKind::SymSpinnaker: return 0.95;
    case SailKind::CodeZero: return 1.05;
  }
  return 1.0;
}

Boat drawBoat(double mast_height, bool tunnel, Draw& draw) {
  Boat b;
  const double H = mast_height, loa = 0.8 * H;
  b.mast_height_m = H;
  b.mast_radius_m = 0.0075 * H;
  b.mast_rake_rad = draw(1.0, 4.0) * kDeg;
  b.bow_x_m = 0.38 * loa;
  b.stern_x_m = -0.62 * loa;
  b.half_beam_m = 0.17 * loa;
  b.keel_z_m = -0.12 * loa;
  b.boom_z_m = 0.08 * H;
  b.boom_radius_m = 0.005 * H;
  b.stay_radius_m = 0.0012 * H;
  b.tunnel = tunnel;
  if (tunnel) {  // the built-in tunnel's chamber (acquisition/tunnel.cpp): 16 × 14 × 3.8 m, floor 0.6 m below deck
    b.chamber_min = Vec3(-8.0, -7.0, -0.6);
    b.chamber_max = Vec3(8.0, 7.0, std::max(3.2, 1.1 * H));
  }
  return b;
}

// Straight-line helpers in the XZ plane for raked luffs: unit vector up a luff raked aft by r.
Vec3 upRaked(double r) { return Vec3(-std::sin(r), 0, std::cos(r)); }

// Sets the design's corners on the rig for its kind; lengths as fractions of the luff.
void rigSail(Config& c, double luff_target, Draw& draw) {
  Boat& b = c.boat;
  SailDesign& d = c.design;
  const double H = b.mast_height_m, loa = b.bow_x_m - b.stern_x_m;
  const double side = d.leeward_port ? 1.0 : -1.0;
  const Vec3 masthead = b.mast_height_m * upRaked(b.mast_rake_rad);
  switch (c.sail) {
    case SailKind::PinHeadMain:
    case SailKind::SquareTopMain: {
      d.type = c.sail == SailKind::PinHeadMain ? SailType::Main : SailType::SquareTopMain;
      d.rake_deg = b.mast_rake_rad / kDeg;
      const double tack_z = b.boom_z_m + b.boom_radius_m + 0.01 * H;
      // Aft of the mast by its radius and a luff track's gap, on a line parallel to the mast.
      d.tack = tack_z * upRaked(b.mast_rake_rad) + (b.mast_radius_m + 0.004 * H) * Vec3(-std::cos(b.mast_rake_rad), 0, -std::sin(b.mast_rake_rad));
      d.luff_m = std::min(luff_target, 0.97 * H - tack_z);
      d.foot_m = d.luff_m * draw(0.30, 0.40);
      if (c.sail == SailKind::PinHeadMain) {
        d.leech_m = d.luff_m * draw(1.02, 1.07);
        d.leech_round_m = d.luff_m * draw(0.0, 0.02);
      } else {
        d.head_width_m = d.foot_m * draw(0.25, 0.40);
        d.leech_m = d.luff_m * draw(0.98, 1.03);
        d.leech_round_m = d.luff_m * draw(0.0, 0.01);
      }
      break;
    }
    case SailKind::Jib:
    case SailKind::Genoa: {
      d.type = SailType::Jib;
      const double stay_top_z = (c.sail == SailKind::Jib ? 0.84 : 0.9) * H;
      const Vec3 top = stay_top_z * upRaked(b.mast_rake_rad);
      const Vec3 base(b.bow_x_m - 0.02 * loa, 0, b.deck_z_m + 0.01 * H);
      const Vec3 stay = top - base;
      const double r = std::atan2(-stay.x(), stay.z());
      d.rake_deg = r / kDeg;
      // The luff 2 cm per 10 m of mast aft of the stay, its tack a pennant's length up it.
      const Vec3 aft(-std::cos(r), 0, -std::sin(r));
      d.tack = base + 0.05 * H * upRaked(r) + 0.002 * H * aft;
      d.luff_m = std::min(luff_target, stay.norm() - 0.07 * H);
      if (c.sail == SailKind::Jib) {
        d.foot_m = d.luff_m * draw(0.27, 0.35);
        d.leech_m = d.luff_m * draw(0.88, 0.95);
      } else {
        d.foot_m = d.luff_m * draw(0.45, 0.58);
        d.leech_m = d.luff_m * draw(0.90, 0.97);
      }
      break;
    }
    case SailKind::AsymBow:
    case SailKind::AsymSprit:
    case SailKind::CodeZero: {
      d.type = SailType::Gennaker;
      const bool sprit = c.sail == SailKind::AsymSprit || (c.sail == SailKind::CodeZero && draw.chance(0.5));
      b.sprit_length_m = sprit ? 0.12 * loa * draw(0.8, 1.2) : 0.0;
      const Vec3 tack(b.bow_x_m + b.sprit_length_m + 0.01 * loa, 0, b.deck_z_m + (sprit ? 0.02 : 0.04) * H);
      const Vec3 head = masthead + Vec3(0.02 * H, 0, -0.02 * H);
      const Vec3 luff = head - tack;
      d.tack = tack;
      d.rake_deg = std::atan2(-luff.x(), luff.z()) / kDeg;
      d.luff_m = luff.norm();
      if (c.sail == SailKind::CodeZero) {
        d.foot_m = d.luff_m * draw(0.45, 0.55);
        d.leech_m = d.luff_m * draw(0.86, 0.93);
        d.luff_round_m = d.luff_m * draw(0.0, 0.006);
        d.luff_sag_m = d.luff_m * draw(0.005, 0.015);
      } else {
        d.foot_m = d.luff_m * draw(0.50, 0.62);
        d.leech_m = d.luff_m * draw(0.84, 0.92);
        d.luff_round_m = d.luff_m * draw(0.02, 0.035);
        d.luff_sag_m = d.luff_m * draw(0.03, 0.06);
      }
      break;
    }
    case SailKind::SymSpinnaker: {
      d.type = SailType::Gennaker;
      // The pole from the mast to windward and forward, the tack on its end, the head at the masthead:
      // the luff leans from the pole's end to the centreline (SailDesign::lean_deg).
      const double pole = 0.35 * loa * draw(0.85, 1.1), angle = draw(15.0, 35.0) * kDeg;
      b.pole = true;
      b.pole_end = Vec3(pole * std::cos(angle), -side * pole * std::sin(angle), b.deck_z_m + 0.12 * H);
      d.tack = b.pole_end + Vec3(0, 0, 0.6 * b.boom_radius_m + 0.005 * H);
      const Vec3 head = masthead + Vec3(0.03 * H, 0, -0.04 * H);
      const Vec3 luff = head - d.tack;
      d.lean_deg = std::atan2(side * luff.y(), luff.z()) / kDeg;
      d.rake_deg = std::asin(-luff.x() / luff.norm()) / kDeg;
      d.luff_m = luff.norm();
      d.leech_m = d.luff_m * draw(0.97, 1.03);
      d.foot_m = d.luff_m * draw(0.60, 0.75);
      d.luff_round_m = d.luff_m * draw(0.01, 0.025);
      d.luff_sag_m = d.luff_m * draw(0.02, 0.05);
      break;
    }
  }
  d.stations = drawStations(c.sail, draw);
  // The forestay: from the stem to 84-90 % up the mast; a headsail's luff lies just aft of it.
  b.stay_base = Vec3(b.bow_x_m - 0.02 * loa, 0, b.deck_z_m + 0.01 * H);
  b.stay_top = (isHeadsail(c.sail) && c.sail == SailKind::Genoa ? 0.9 : 0.84) * H * upRaked(b.mast_rake_rad);
  // The boom under a main's foot, to its clew; amidships and a little to leeward under the other sails.
  const Vec3 boom_root = b.boom_z_m * upRaked(b.mast_rake_rad);
  if (isMain(c.sail)) {
    const Vec3 clew = SailSurface(d).clew();
    b.boom_end = Vec3(clew.x() - 0.01 * H, clew.y(), boom_root.z());
  } else {
    const double boom = 0.3 * H;
    const double swing = draw(5.0, 25.0) * kDeg;
    b.boom_end = boom_root + boom * Vec3(-std::cos(swing), side * std::sin(swing), 0);
  }
}

// The unit's place on the boat (shaft foot position) for `place`.
Vec3 unitPosition(const Config& c, Draw& draw) {
  const Boat& b = c.boat;
  const double side = c.design.leeward_port ? 1.0 : -1.0, loa = b.bow_x_m - b.stern_x_m;
  const double deck = b.deck_z_m, tripod = b.tunnel ? 0.25 * draw(0.6, 1.2) : draw(0.35, 0.9);
  const auto deckAt = [&](double x, double y_side, double lo, double hi) {
    return Vec3(x, y_side * draw(lo, hi) * b.halfBeamAt(x), deck + tripod);
  };
  const double x_deck = isMain(c.sail) ? draw(-0.35, -0.1) * loa : draw(-0.25, 0.05) * loa;
  switch (c.place) {
    case UnitPlace::DeckLeeward: return deckAt(x_deck, side, 0.55, 0.9);
    case UnitPlace::Tunnel: {
      // As the study's tunnel units stood: on the chamber floor beside the model, to leeward, a
      // metre or two off the sail, looking across the model's deck.
      const Vec3 centre = SailSurface(c.design).at(0.4, 0.4);
      const double reach = 0.7 + c.design.luff_m * draw(0.8, 1.6), bearing = draw(-40.0, 40.0) * kDeg;
      Vec3 p = centre + reach * Vec3(std::sin(bearing), side * std::cos(bearing), 0);
      p.x() = std::clamp(p.x(), b.chamber_min.x() + 0.3, b.chamber_max.x() - 0.3);
      p.y() = std::clamp(p.y(), b.chamber_min.y() + 0.3, b.chamber_max.y() - 0.3);
      p.z() = b.chamber_min.z() + draw(0.5, 1.2);
      return p;
    }
    case UnitPlace::DeckWindward: return deckAt(x_deck, -side, 0.55, 0.9);
    case UnitPlace::SternPulpit:
      return Vec3(b.stern_x_m + 0.02 * loa, side * draw(0.0, 0.7) * b.half_beam_m, deck + draw(0.7, 1.0));
    case UnitPlace::MastFoot: {
      const double off = b.mast_radius_m + draw(0.04, 0.08) * loa;
      // Beside the mast on the leeward side deck, looking up the sail's leeward face.
      return Vec3(isMain(c.sail) ? -off : off, side * draw(0.05, 0.1) * loa, deck + draw(0.15, 0.4));
    }
    case UnitPlace::Bow: {
      // On the foredeck, to leeward of the tack: a headsail's luff runs straight over the stem.
      const double x = b.bow_x_m - draw(0.1, 0.2) * loa;
      return Vec3(x, side * draw(0.4, 0.8) * b.halfBeamAt(x), deck + draw(0.3, 0.7));
    }
    case UnitPlace::BoomEnd:
      return b.boom_end + Vec3(0, 0, b.boom_radius_m + draw(0.15, 0.3));
  }
  return Vec3::Zero();
}

// Aims the sweep at the sail as an operator sets it up: the β range over the sail's azimuths from
// the unit and the output α range over its elevations, with margins that take in some of the boat.
void aimSweep(Config& c) {
  const SailSurface surface(c.design);
  UnitSetup& u = c.unit;
  const ScannerSpec spec = scannerSpec(u.model);
  const Vec3 centroid = surface.at(0.4, 0.45);
  const double ref = std::atan2(centroid.y() - u.position.y(), centroid.x() - u.position.x());
  double az_lo = 1e9, az_hi = -1e9, el_lo = 1e9, el_hi = -1e9;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vec3 d = surface.at(i / 40.0, j / 20.0) - u.position;
      double az = std::atan2(d.y(), d.x()) - ref;
      az = std::remainder(az, 2 * kPi);
      az_lo = std::min(az_lo, az);
      az_hi = std::max(az_hi, az);
      const double alpha = std::acos(std::clamp(d.z() / d.norm(), -1.0, 1.0));
      el_lo = std::min(el_lo, alpha);
      el_hi = std::max(el_hi, alpha);
    }
  const double margin = 5 * kDeg;
  u.beta_start_deg = std::remainder(ref + az_lo - margin - u.yaw_rad, 2 * kPi) / kDeg;
  u.sweep_deg = std::min(360.0, (az_hi - az_lo + 2 * margin) / kDeg);
  u.alpha_from_deg = std::max(spec.first_angle_deg, el_lo / kDeg - 5);
  u.alpha_to_deg = std::min(spec.last_angle_deg, el_hi / kDeg + 30);
}

}  // namespace

std::string sailKindName(SailKind kind) {
  switch (kind) {
    case SailKind::PinHeadMain: return "pin-head-main";
    case SailKind::SquareTopMain: return "square-top-main";
    case SailKind::Jib: return "jib";
    case SailKind::Genoa: return "genoa";
    case SailKind::AsymBow: return "asym-bow";
    case SailKind::AsymSprit: return "asym-sprit";
    case SailKind::SymSpinnaker: return "sym-spinnaker";
    case SailKind::CodeZero: return "code-zero";
  }
  return "?";
}

std::string unitPlaceName(UnitPlace place) {
  switch (place) {
    case UnitPlace::DeckLeeward: return "deck-leeward";
    case UnitPlace::DeckWindward: return "deck-windward";
    case UnitPlace::SternPulpit: return "stern-pulpit";
    case UnitPlace::MastFoot: return "mast-foot";
    case UnitPlace::Bow: return "bow";
    case UnitPlace::BoomEnd: return "boom-end";
    case UnitPlace::Tunnel: return "tunnel";
  }
  return "?";
}

SailKind parseSailKind(const std::string& name) {
  std::string names;
  for (SailKind k : kSailKinds) {
    if (sailKindName(k) == name) return k;
    names += (names.empty() ? "" : ", ") + sailKindName(k);
  }
  throw InvalidInput("[parseSailKind] unknown sail kind '" + name + "' (expected " + names + ")");
}

UnitPlace parseUnitPlace(const std::string& name) {
  std::string names;
  for (UnitPlace p : kUnitPlaces) {
    if (unitPlaceName(p) == name) return p;
    names += (names.empty() ? "" : ", ") + unitPlaceName(p);
  }
  throw InvalidInput("[parseUnitPlace] unknown unit place '" + name + "' (expected " + names + ")");
}

double Boat::halfBeamAt(double x) const {
  const double shoulder = stern_x_m + 0.6 * (bow_x_m - stern_x_m);
  if (x <= shoulder) return half_beam_m;
  return half_beam_m * std::max(0.0, (bow_x_m - x) / (bow_x_m - shoulder));
}

Eigen::Isometry3d UnitSetup::pose() const {
  Eigen::Matrix3d shaft_up;
  shaft_up.col(0) = Vec3::UnitZ();  // unit X: the shaft, vertical
  shaft_up.col(1) = Vec3::UnitX();  // unit Y: where the scan plane looks at β = 0 (before the yaw)
  shaft_up.col(2) = Vec3::UnitY();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw_rad, Vec3::UnitZ()).toRotationMatrix() * shaft_up;
  t.translation() = position;
  return t;
}

std::string Config::summary() const {
  char buf[256];
  const Vec3 to_tack = design.tack - unit.position;
  std::snprintf(buf, sizeof buf, "seed %llu: %s, luff %.1f m, %s at %s (%.1f m from the tack)",
                static_cast<unsigned long long>(seed), sailKindName(sail).c_str(), design.luff_m,
                scannerModelName(unit.model).c_str(), unitPlaceName(place).c_str(), to_tack.norm());
  return buf;
}

Config drawConfig(uint64_t seed) {
  Draw draw(seed ^ 0x5ea1157c5ca11e5ULL);
  const SailKind sail = kSailKinds[draw.pick(std::size(kSailKinds))];
  const UnitPlace place = kUnitPlaces[draw.pick(std::size(kUnitPlaces))];
  return drawConfig(seed, sail, place);
}

Config drawConfig(uint64_t seed, SailKind sail, UnitPlace place) {
  Draw draw(seed);
  Config c;
  c.seed = seed;
  c.sail = sail;
  c.place = place;
  const bool tunnel = place == UnitPlace::Tunnel;
  c.design.leeward_port = draw.chance(0.5);
  // Some sails a long way off for an LMS111 (20 m reach): the larger ones are partly out of range.
  c.unit.model = draw.chance(0.65) ? ScannerModel::Lms511 : ScannerModel::Lms111;
  const double luff_target = tunnel ? draw(1.8, 3.0) : std::exp(draw(std::log(6.0), std::log(35.0)));
  // Redraw the shape until the rig gives a sail the generator can make and whose clew clears the deck.
  for (int attempt = 0;; ++attempt) {
    const double H = std::min(tunnel ? 3.0 : 40.0, luff_target / mastRatio(sail));
    c.boat = drawBoat(H, tunnel, draw);
    rigSail(c, luff_target, draw);
    try {
      const SailSurface s(c.design);
      if (s.clew().z() > c.boat.deck_z_m + 0.03 * H && s.head().z() < 1.02 * H) break;
    } catch (const InvalidInput&) {
    }
    if (attempt > 50) throw AnalysisError("[drawConfig] seed " + std::to_string(seed) + ": no valid sail in 50 draws");
  }
  const ScannerSpec spec = scannerSpec(c.unit.model);
  c.unit.resolution_deg = spec.default_resolution_deg;
  c.unit.frequency_hz = spec.default_frequency_hz;
  c.unit.line_step_deg = 0.25;
  c.unit.p_m = draw(0.02, 0.08);
  c.unit.theta_rad = draw(-kPi, kPi);
  c.unit.yaw_rad = draw(-kPi, kPi);
  // A unit stands clear of the sail: beyond the scanner's least range by 0.3 m from every point of it
  // (a genoa sheeted to the rail covers the leeward deck under its foot; a unit there sees nothing).
  const SailSurface surface(c.design);
  const double clearance = spec.min_range_m + 0.3;
  const auto nearestOf = [&](const Vec3& p) {
    Vec3 best = surface.tack();
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 20; ++j)
        if ((surface.at(i / 40.0, j / 20.0) - p).norm() < (best - p).norm()) best = surface.at(i / 40.0, j / 20.0);
    return best;
  };
  Vec3 best_place;
  double best_gap = -1;
  for (int attempt = 0; attempt < 10 && best_gap <= clearance; ++attempt) {
    const Vec3 p = unitPosition(c, draw);
    const double gap = (nearestOf(p) - p).norm();
    if (gap > best_gap) best_gap = gap, best_place = p;
  }
  // Still under the sail (a small boat's boom or genoa foot over the leeward deck): step it sideways,
  // away from the nearest cloth, until clear.
  for (int step = 0; step < 40 && best_gap <= clearance; ++step) {
    Vec3 away = best_place - nearestOf(best_place);
    away.z() = 0;
    if (away.norm() < 1e-6) away = Vec3(0, c.design.leeward_port ? 1 : -1, 0);
    best_place += 0.1 * away.normalized();
    best_gap = (nearestOf(best_place) - best_place).norm();
  }
  c.unit.position = best_place;
  aimSweep(c);
  c.sensor.model = c.unit.model;
  return c;
}

Scene buildScene(const Config& c) {
  const Boat& b = c.boat;
  const double H = b.mast_height_m;
  Scene s;
  s.name = "realistic";
  if (b.tunnel) s.objects = makeChamber(b.chamber_min, b.chamber_max);
  s.objects.push_back({"hull", Material::Paint, hullMesh(b)});
  s.objects.push_back({"mast", Material::Metal, makeCylinder(Vec3(0, 0, b.deck_z_m - 0.01), upRaked(b.mast_rake_rad),
                                                             b.mast_radius_m, H, 24)});
  const Vec3 boom_root = b.boom_z_m * upRaked(b.mast_rake_rad);
  s.objects.push_back({"boom", Material::Metal, makeCylinder(boom_root, b.boom_end - boom_root, b.boom_radius_m,
                                                             (b.boom_end - boom_root).norm(), 16)});
  const Vec3 stay = b.stay_top - b.stay_base;
  // A furled headsail thickens the stay while a spinnaker or main flies.
  const double stay_r = isHeadsail(c.sail) ? b.stay_radius_m : 4 * b.stay_radius_m;
  s.objects.push_back({"forestay", Material::Metal, makeCylinder(b.stay_base, stay, stay_r, stay.norm(), 12)});
  if (b.sprit_length_m > 0)
    s.objects.push_back({"bowsprit", Material::Metal,
                         makeCylinder(Vec3(b.bow_x_m - 0.05 * H, 0, b.deck_z_m + 0.01 * H), Vec3::UnitX(),
                                      0.4 * b.boom_radius_m, b.sprit_length_m + 0.05 * H + 0.01 * H, 12)});
  if (b.pole) {
    const Vec3 root = Vec3(0.5 * b.mast_radius_m, 0, b.pole_end.z());
    s.objects.push_back({"pole", Material::Metal,
                         makeCylinder(root, b.pole_end - root, 0.6 * b.boom_radius_m, (b.pole_end - root).norm(), 12)});
  }
  s.objects.push_back({"sail", Material::Cloth, generateSailMesh(c.design, 120, 60)});
  return s;
}

Truth truthOf(const SailDesign& design) {
  const SailSurface surface(design);
  Truth t;
  t.tack = surface.tack();
  t.clew = surface.clew();
  t.head = surface.head();
  t.peak = surface.peak();
  t.has_peak = design.type == SailType::SquareTopMain;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double a = static_cast<double>(i) / n, b = static_cast<double>(i + 1) / n;
    t.luff_m += (surface.luffPoint(b) - surface.luffPoint(a)).norm();
    t.leech_m += (surface.leechPoint(b) - surface.leechPoint(a)).norm();
    t.foot_m += (surface.at(0, b) - surface.at(0, a)).norm();
    if (t.has_peak) t.top_m += (surface.at(1, b) - surface.at(1, a)).norm();
  }
  for (double f : kSectionFractions) t.sections.push_back(surface.section(f));
  return t;
}

uint64_t freshSeed() {
  uint64_t seed = std::random_device{}() | (static_cast<uint64_t>(std::random_device{}()) << 32);
  if (const char* s = std::getenv("SAILSHAPE_REALISTIC_SEED")) seed = std::strtoull(s, nullptr, 10);
  std::printf("SAILSHAPE_REALISTIC_SEED=%llu\n", static_cast<unsigned long long>(seed));
  return seed;
}

}  // namespace sailshape::realistic
