#include "cli/warning_summary.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <set>

namespace sailshape::cli {
namespace {

// A warning cut into its words and its numbers: `literals` has one more entry
// than `numbers`, and literals[k] comes before numbers[k]. A number stands on
// its own ("0.250", "-3", "16"), not inside a name ("lms511", "step1-main").
struct Pieces {
  std::vector<std::string> literals;
  std::vector<std::string> numbers;
};

bool partOfName(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-'; }

Pieces cut(const std::string& text) {
  Pieces p;
  std::string literal;
  size_t i = 0;
  while (i < text.size()) {
    const bool sign = text[i] == '-' && i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1]));
    const bool starts = (sign || std::isdigit(static_cast<unsigned char>(text[i]))) && (i == 0 || !partOfName(text[i - 1]));
    if (!starts) {
      literal += text[i++];
      continue;
    }
    size_t end = i + (sign ? 1 : 0);
    while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
    if (end + 1 < text.size() && text[end] == '.' && std::isdigit(static_cast<unsigned char>(text[end + 1]))) {
      ++end;
      while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
    }
    // "lms511x" or "3D": digits running into a name are part of it.
    if (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) {
      literal += text.substr(i, end - i);
      i = end;
      continue;
    }
    p.literals.push_back(literal);
    literal.clear();
    p.numbers.push_back(text.substr(i, end - i));
    i = end;
  }
  p.literals.push_back(literal);
  return p;
}

struct Group {
  Pieces first;
  std::vector<std::pair<std::string, std::string>> ranges;  // per number: lowest and highest as written
  std::set<int> steps;
  int count = 0;
};

// "step 2", "steps 1–3" or "steps 1, 3".
std::string stepsText(const std::set<int>& steps) {
  if (steps.size() == 1) return "step " + std::to_string(*steps.begin());
  const bool contiguous = *steps.rbegin() - *steps.begin() + 1 == static_cast<int>(steps.size());
  if (contiguous) return "steps " + std::to_string(*steps.begin()) + "–" + std::to_string(*steps.rbegin());
  std::string s = "steps ";
  for (int k : steps) s += (s.size() > 6 ? ", " : "") + std::to_string(k);
  return s;
}

}  // namespace

bool sameWarning(const std::string& a, const std::string& b) { return cut(a).literals == cut(b).literals; }

std::vector<std::string> summariseWarnings(const std::vector<StepWarning>& warnings) {
  std::vector<Group> groups;
  for (const StepWarning& w : warnings) {
    Pieces p = cut(w.text);
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.first.literals == p.literals; });
    if (g == groups.end()) {
      Group fresh;
      for (const std::string& n : p.numbers) fresh.ranges.emplace_back(n, n);
      fresh.first = std::move(p);
      groups.push_back(std::move(fresh));
      g = groups.end() - 1;
    } else {
      for (size_t k = 0; k < p.numbers.size(); ++k) {
        const double v = std::strtod(p.numbers[k].c_str(), nullptr);
        auto& [low, high] = g->ranges[k];
        if (v < std::strtod(low.c_str(), nullptr)) low = p.numbers[k];
        if (v > std::strtod(high.c_str(), nullptr)) high = p.numbers[k];
      }
    }
    ++g->count;
    if (w.step > 0) g->steps.insert(w.step);
  }

  std::vector<std::string> lines;
  for (const Group& g : groups) {
    std::string line = g.first.literals[0];
    for (size_t k = 0; k < g.ranges.size(); ++k) {
      const auto& [low, high] = g.ranges[k];
      line += low == high ? low : low + "–" + high;
      line += g.first.literals[k + 1];
    }
    std::string where;
    if (g.count > 1) where = std::to_string(g.count) + " times";
    if (!g.steps.empty()) where += (where.empty() ? "" : ", ") + stepsText(g.steps);
    if (!where.empty()) line += " (" + where + ")";
    lines.push_back(line);
  }
  return lines;
}

}  // namespace sailshape::cli
