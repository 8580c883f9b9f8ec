#pragma once
// A one-line progress bar on stderr for the CLI (plain stage lines when stderr
// is not a terminal).
#include <chrono>
#include <string>

#include "analysis/core/progress.hpp"

namespace sailshape::cli {

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled = true);
  ~ProgressBar();
  Progress progress();
  void finish();

 private:
  void update(std::string_view stage, double fraction);
  bool enabled_, tty_;
  std::string stage_;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace sailshape::cli
