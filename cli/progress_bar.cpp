#include "cli/progress_bar.hpp"

#include <unistd.h>

#include <cstdio>

namespace sailshape::cli {

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { finish(); }

Progress ProgressBar::progress() {
  Progress p;
  if (enabled_) p.callback = [this](std::string_view stage, double fraction) { update(stage, fraction); };
  return p;
}

void ProgressBar::update(std::string_view stage, double fraction) {
  const int percent = static_cast<int>(fraction * 100.0 + 0.5);
  const auto now = std::chrono::steady_clock::now();
  const bool new_stage = stage != stage_;
  if (!new_stage && percent == last_percent_) return;
  if (!tty_) {
    if (new_stage) std::fprintf(stderr, "%.*s...\n", static_cast<int>(stage.size()), stage.data());
  } else if (new_stage || percent == 100 || now - last_draw_ > std::chrono::milliseconds(50)) {
    const int width = 30, filled = percent * width / 100;
    std::string bar(static_cast<size_t>(filled), '#');
    bar.resize(width, '-');
    std::fprintf(stderr, "\r  %-20.*s [%s] %3d%%", static_cast<int>(stage.size()), stage.data(), bar.c_str(), percent);
    std::fflush(stderr);
    last_draw_ = now;
  }
  stage_ = std::string(stage);
  last_percent_ = percent;
}

void ProgressBar::finish() {
  if (enabled_ && tty_ && !stage_.empty()) std::fprintf(stderr, "\r%60s\r", "");
  stage_.clear();
}

}  // namespace sailshape::cli
