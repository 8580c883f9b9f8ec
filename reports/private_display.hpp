#pragma once
// An X display for VTK's renders. VTK on Debian renders through X only (and
// aborts the process when it cannot open the display), so a machine without a
// usable display (CI, a server, an ssh session whose DISPLAY is gone) gets a
// private Xvfb for the life of this object; with a display that opens, nothing
// is started.
#include <stdexcept>
#include <string>
#include <sys/types.h>

namespace sailshape {

struct DisplayError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class PrivateDisplay {
 public:
  // Starts `Xvfb` (searched on PATH) when DISPLAY is unset, empty or cannot be
  // opened, and sets DISPLAY for this process. Throws DisplayError when Xvfb is
  // not installed or does not come up within `timeout_ms`.
  explicit PrivateDisplay(int timeout_ms = 10000);
  // Stops the Xvfb it started and restores DISPLAY as it was.
  ~PrivateDisplay();
  PrivateDisplay(const PrivateDisplay&) = delete;
  PrivateDisplay& operator=(const PrivateDisplay&) = delete;

  bool started() const { return pid_ > 0; }
  const std::string& display() const { return display_; }  // ":N"

 private:
  bool startXvfb(const std::string& xvfb, const std::string& number, int timeout_ms, std::string& reported);

  pid_t pid_ = -1;
  std::string display_;
  std::string previous_;  // DISPLAY before, empty when unset
  bool had_previous_ = false;
};

// True when an X connection to `display` (":0", ...) opens.
bool displayOpens(const std::string& display);

// Full path of an executable on PATH, empty when there is none.
std::string findOnPath(const std::string& program);

}  // namespace sailshape
