#include "reports/private_display.hpp"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

extern char** environ;

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
  // Xvfb writes the display number it picked to this pipe once it accepts clients.
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0)
    throw DisplayError(std::string("[PrivateDisplay] pipe: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 3);  // dup2 clears close-on-exec
  const int devnull = open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (devnull >= 0) {
    posix_spawn_file_actions_adddup2(&actions, devnull, 1);
    posix_spawn_file_actions_adddup2(&actions, devnull, 2);
  }
  std::vector<std::string> args = {xvfb, "-displayfd", "3", "-screen", "0", "1280x1024x24", "-nolisten", "tcp"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, xvfb.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (devnull >= 0) close(devnull);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    throw DisplayError("[PrivateDisplay] cannot start " + xvfb + ": " + std::strerror(rc));
  }
  pid_ = pid;

  std::string number;
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
    if (n <= 0) break;  // Xvfb exited without a display
    for (ssize_t i = 0; i < n; ++i) {
      if (buf[i] == '\n') done = true;
      else number += buf[i];
    }
  }
  close(fds[0]);
  if (!done || number.empty()) {
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
    throw DisplayError("[PrivateDisplay] " + xvfb + " did not report a display within " + std::to_string(timeout_ms) +
                       " ms");
  }
  display_ = ":" + number;
  setenv("DISPLAY", display_.c_str(), 1);
}

PrivateDisplay::~PrivateDisplay() {
  if (pid_ <= 0) return;
  if (had_previous_) setenv("DISPLAY", previous_.c_str(), 1);
  else unsetenv("DISPLAY");
  kill(pid_, SIGTERM);
  waitpid(pid_, nullptr, 0);
}

}  // namespace sailshape
