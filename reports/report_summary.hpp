#pragma once
// The report's plain-words summary: the largest differences between flying
// and design, e.g. "the head section is 4.1° more twisted than designed".
#include <string>
#include <vector>

#include "analysis/sections/sections.hpp"

namespace sailshape {

// One section's design and flying parameters with their 1σ uncertainties.
// NaN marks a value that was not measured.
struct ComparedSection {
  double fraction = 0;
  SectionParameters design, design_u, flying, flying_u;
};

// Differences a sailmaker would act on; smaller ones are not worth a sentence
// even when the scan resolves them.
struct SummaryParams {
  double camber_pct = 0.5;   // % of chord
  double draft_pct = 2.0;    // % of chord
  double twist_deg = 1.0;
  double entry_deg = 2.0;
  double exit_deg = 2.0;
  double min_sigmas = 2.0;   // and larger than this many σ of the difference
  size_t max_sentences = 5;
};

struct Summary {
  std::vector<std::string> sentences;  // largest first (relative to the thresholds)
  bool within_design = false;          // nothing passed the thresholds
};

// "foot", "lower", "middle", "upper" or "head" for a height fraction in (0, 1).
std::string heightName(double fraction);

// Names each section by height; a name shared by several sections gets its
// percentage: "the upper section at 67 % height".
std::vector<std::string> sectionNames(const std::vector<double>& fractions);

// Throws InvalidInput for a negative threshold.
Summary summarizeDifferences(const std::vector<ComparedSection>& sections, const SummaryParams& params = {});

}  // namespace sailshape
