#pragma once
// Progress reporting for long operations: the CLI draws a bar, the viewer a spinner.
#include <functional>
#include <string_view>

namespace sailshape {

struct Progress {
  // stage: short name ("normals"); fraction in [0, 1] within that stage.
  std::function<void(std::string_view stage, double fraction)> callback;

  void operator()(std::string_view stage, double fraction) const {
    if (callback) callback(stage, fraction);
  }
};

}  // namespace sailshape
