#pragma once
// A run's warnings, each said once: the same warning raised at several trim steps
// (or for several sections, differing only in its numbers) becomes one line with
// the range of its numbers, how often it came and at which steps.
#include <string>
#include <vector>

namespace sailshape::cli {

struct StepWarning {
  int step = 0;  // the trim step (1-based) that raised it; 0: none (a report's)
  std::string text;
};

// In order of first appearance. "section 0.250: 11 points" and "section 0.750: 8
// points" at steps 1 and 2 give "section 0.250–0.750: 8–11 points (2 times, steps 1–2)";
// a warning raised once keeps its text and its step: "... (step 2)".
std::vector<std::string> summariseWarnings(const std::vector<StepWarning>& warnings);

// Whether two warnings say the same but for their numbers (summariseWarnings makes them one line).
bool sameWarning(const std::string& a, const std::string& b);

}  // namespace sailshape::cli
