#pragma once
// An X display for VTK's renders. VTK on Debian renders through X only, so a
// machine without a display (CI, a server) gets a private Xvfb for the life of
// this object; with DISPLAY set, nothing is started.
#include <stdexcept>
#include <string>
#include <sys/types.h>

namespace sailshape {

struct DisplayError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class PrivateDisplay {
 public:
  // Starts `Xvfb` (searched on PATH) when DISPLAY is unset or empty and sets
  // DISPLAY for this process. Throws DisplayError when Xvfb is not installed or
  // does not come up within `timeout_ms`.
  explicit PrivateDisplay(int timeout_ms = 10000);
  // Stops the Xvfb it started and restores DISPLAY.
  ~PrivateDisplay();
  PrivateDisplay(const PrivateDisplay&) = delete;
  PrivateDisplay& operator=(const PrivateDisplay&) = delete;

  bool started() const { return pid_ > 0; }
  const std::string& display() const { return display_; }  // ":N"

 private:
  pid_t pid_ = -1;
  std::string display_;
};

// Full path of an executable on PATH, empty when there is none.
std::string findOnPath(const std::string& program);

}  // namespace sailshape
