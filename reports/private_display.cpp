#include "reports/private_display.hpp"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

namespace sailshape {

std::string findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

bool displayOpens(const std::string& display) {
  if (display.empty()) return false;
  Display* x = XOpenDisplay(display.c_str());
  if (!x) return false;
  XCloseDisplay(x);
  return true;
}

PrivateDisplay::PrivateDisplay(int timeout_ms) {
  const char* current = std::getenv("DISPLAY");
  had_previous_ = current != nullptr;
  if (current) previous_ = current;
  if (displayOpens(previous_)) {
    display_ = previous_;
    return;
  }
  const std::string xvfb = findOnPath("Xvfb");
  if (xvfb.empty())
    throw DisplayError(std::string("[PrivateDisplay] ") +
                       (previous_.empty() ? "no DISPLAY is set" : "DISPLAY " + previous_ + " cannot be opened") +
                       " and Xvfb is not installed (apt install xvfb): the report's 3D views need an X display");
  // Display numbers are taken explicitly: Xvfb then holds /tmp/.X<n>-lock and
  // exits at once when another server has it. (-displayfd without a number
  // lets two servers starting together both claim the same display.) The
  // first number depends on the process id, so concurrent reports rarely collide,
  // and moves on with every server this process starts: a later report never
  // reuses the name of a server an earlier one stopped (Mesa's GLX keeps state per
  // display name, and a reused name intermittently fails with "bad X server connection").
  static std::atomic<int> started_before{0};
  const int first = 200 + static_cast<int>(getpid() % 500) + 40 * started_before++;
  std::string last_error;
  for (int attempt = 0; attempt < 40 && pid_ <= 0; ++attempt) {
    const int n = first + attempt;
    const std::string number = std::to_string(n);
    std::string reported;
    if (startXvfb(xvfb, number, timeout_ms, reported)) display_ = ":" + reported;
    else last_error = "display :" + number + " taken or Xvfb failed";
  }
  if (pid_ <= 0)
    throw DisplayError("[PrivateDisplay] " + xvfb + " did not start on any of 40 displays (" + last_error + ")");
  setenv("DISPLAY", display_.c_str(), 1);
}

// Starts Xvfb on `number`; true with pid_ set once it reported the display
// ready on the pipe, false (and the server reaped) when it exited or timed out.
bool PrivateDisplay::startXvfb(const std::string& xvfb, const std::string& number, int timeout_ms,
                               std::string& reported) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0)
    throw DisplayError(std::string("[PrivateDisplay] pipe: ") + std::strerror(errno));
  // -noreset: an X server resets when its last client disconnects, and a client that
  // connects during the reset fails ("bad X server connection", and VTK aborts). Each
  // render window, and the readiness check below, is such a last client.
  std::vector<std::string> args = {xvfb, ":" + number, "-displayfd", "3", "-screen", "0", "1280x1024x24",
                                   "-nolisten", "tcp", "-noreset"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int devnull = open("/dev/null", O_WRONLY | O_CLOEXEC);
  const pid_t parent = getpid();
  // fork + exec rather than posix_spawn: the server must die with this process
  // (PR_SET_PDEATHSIG), also when VTK aborts it. Only async-signal-safe calls in the child.
  const pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    dup2(fds[1], 3);  // dup2 clears close-on-exec
    if (devnull >= 0) dup2(devnull, 1), dup2(devnull, 2);
    execv(xvfb.c_str(), argv.data());
    _exit(127);
  }
  if (devnull >= 0) close(devnull);
  close(fds[1]);
  if (pid < 0) {
    close(fds[0]);
    throw DisplayError("[PrivateDisplay] cannot start " + xvfb + ": " + std::strerror(errno));
  }

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  bool done = false;
  while (!done) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) break;
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
    char buf[32];
    const ssize_t n = read(fds[0], buf, sizeof(buf));
    if (n <= 0) break;  // Xvfb exited without a display (taken, or it failed)
    for (ssize_t i = 0; i < n; ++i) {
      if (buf[i] == '\n') done = true;
      else reported += buf[i];
    }
  }
  close(fds[0]);
  // Ready on the pipe should mean it accepts clients; make sure before VTK, which
  // aborts the process on a display it cannot open, gets to it.
  if (done && !reported.empty() && !displayOpens(":" + reported)) done = false;
  if (!done || reported.empty()) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
    return false;
  }
  pid_ = pid;
  return true;
}


PrivateDisplay::~PrivateDisplay() {
  if (pid_ <= 0) return;
  if (had_previous_) setenv("DISPLAY", previous_.c_str(), 1);
  else unsetenv("DISPLAY");
  kill(pid_, SIGTERM);
  waitpid(pid_, nullptr, 0);
}

}  // namespace sailshape
