#include "reports/report_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), fmt, a, b, c);
  return buf;
}

struct Candidate {
  double score;  // |difference| / threshold
  std::string sentence;
};

}  // namespace

std::string heightName(double f) {
  if (f < 0.2) return "foot";
  if (f < 0.4) return "lower";
  if (f < 0.6) return "middle";
  if (f < 0.8) return "upper";
  return "head";
}

std::vector<std::string> sectionNames(const std::vector<double>& fractions) {
  std::map<std::string, int> uses;
  for (double f : fractions) ++uses[heightName(f)];
  std::vector<std::string> names;
  for (double f : fractions) {
    const std::string name = heightName(f);
    names.push_back(uses[name] == 1 ? "the " + name + " section"
                                    : "the " + name + " section at " + format("%.0f", 100 * f) + " % height");
  }
  return names;
}

Summary summarizeDifferences(const std::vector<ComparedSection>& sections, const SummaryParams& p) {
  for (double t : {p.camber_pct, p.draft_pct, p.twist_deg, p.entry_deg, p.exit_deg, p.min_sigmas})
    if (!(t >= 0)) throw InvalidInput("[summarizeDifferences] thresholds must be >= 0 (got " + format("%g", t) + ")");
  std::vector<double> fractions;
  for (const auto& s : sections) fractions.push_back(s.fraction);
  const std::vector<std::string> names = sectionNames(fractions);

  std::vector<Candidate> found;
  for (size_t i = 0; i < sections.size(); ++i) {
    const ComparedSection& s = sections[i];
    auto consider = [&](double design, double flying, double ud, double uf, double threshold, auto&& say) {
      if (!std::isfinite(design) || !std::isfinite(flying)) return;
      const double d = flying - design;
      const double sigma = std::hypot(std::isfinite(ud) ? ud : 0.0, std::isfinite(uf) ? uf : 0.0);
      if (std::abs(d) < threshold || std::abs(d) <= p.min_sigmas * sigma) return;
      found.push_back({threshold > 0 ? std::abs(d) / threshold : std::abs(d), say(d, design, flying)});
    };
    const std::string& who = names[i];
    consider(s.design.twist_deg, s.flying.twist_deg, s.design_u.twist_deg, s.flying_u.twist_deg, p.twist_deg,
             [&](double d, double, double) {
               return who + format(" is %.1f° ", std::abs(d)) + (d > 0 ? "more" : "less") + " twisted than designed";
             });
    consider(s.design.camber_pct, s.flying.camber_pct, s.design_u.camber_pct, s.flying_u.camber_pct, p.camber_pct,
             [&](double d, double design, double flying) {
               return who + " is " + (d > 0 ? "deeper" : "flatter") +
                      format(" than designed (%.1f %% camber against %.1f %%)", flying, design);
             });
    consider(s.design.draft_pct, s.flying.draft_pct, s.design_u.draft_pct, s.flying_u.draft_pct, p.draft_pct,
             [&](double d, double design, double flying) {
               return who + format(" has its deepest point %.0f %% of the chord ", std::abs(d)) +
                      (d > 0 ? "further aft" : "further forward") +
                      format(" than designed (at %.0f %% against %.0f %%)", flying, design);
             });
    consider(s.design.entry_deg, s.flying.entry_deg, s.design_u.entry_deg, s.flying_u.entry_deg, p.entry_deg,
             [&](double d, double, double) {
               return who + format(" has a %.1f° ", std::abs(d)) + (d > 0 ? "rounder" : "finer") +
                      " entry than designed";
             });
    consider(s.design.exit_deg, s.flying.exit_deg, s.design_u.exit_deg, s.flying_u.exit_deg, p.exit_deg,
             [&](double d, double, double) {
               return who + format(" has a leech %.1f° ", std::abs(d)) + (d > 0 ? "more closed" : "more open") +
                      " than designed";
             });
  }
  std::stable_sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  Summary out;
  out.within_design = found.empty();
  for (size_t i = 0; i < found.size() && i < p.max_sentences; ++i) {
    std::string s = found[i].sentence;
    s[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
    out.sentences.push_back(s + ".");
  }
  return out;
}

}  // namespace sailshape
