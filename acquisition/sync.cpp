#include "acquisition/sync.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "analysis/core/errors.hpp"

#include "acquisition/turntable.hpp"

namespace sailshape {

namespace {
constexpr const char* kTag = "SAILSHAPE-TRIGGER";

sockaddr_in endpointAddress(const TriggerEndpoint& e, const char* who) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(e.port);
  if (inet_pton(AF_INET, e.address.c_str(), &a.sin_addr) != 1)
    throw std::runtime_error(std::string("[") + who + "] not an IPv4 address: '" + e.address + "'");
  return a;
}
}  // namespace

TriggerListener::TriggerListener(const TriggerEndpoint& bind_to) {
  const sockaddr_in a = endpointAddress(bind_to, "TriggerListener");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("[TriggerListener] socket: ") + std::strerror(errno));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("[TriggerListener] cannot bind " + bind_to.address + ":" + std::to_string(bind_to.port) +
                             ": " + why);
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(bound.sin_port);
}

TriggerListener::~TriggerListener() {
  if (fd_ >= 0) ::close(fd_);
}

TriggerListener::Trigger TriggerListener::wait(double timeout_s) {
  const double end = hostTimeSeconds() + timeout_s;
  for (;;) {
    const double left = end - hostTimeSeconds();
    if (left <= 0)
      throw std::runtime_error("[TriggerListener] no trigger on port " + std::to_string(port_) + " within " +
                               std::to_string(timeout_s) + " s");
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::ceil(left * 1000))) <= 0) continue;
    char buf[256];
    const ssize_t n = ::recv(fd_, buf, sizeof buf - 1, 0);
    const double now = hostTimeSeconds();
    if (n <= 0) continue;
    buf[n] = 0;
    std::istringstream in(buf);
    std::string tag;
    uint64_t id = 0;
    if (in >> tag >> id && tag == kTag) return {id, now};
  }
}

void sendTrigger(const std::vector<TriggerEndpoint>& to, uint64_t id) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error(std::string("[sendTrigger] socket: ") + std::strerror(errno));
  char msg[96];
  const int len = std::snprintf(msg, sizeof msg, "%s %llu %.6f", kTag, static_cast<unsigned long long>(id),
                                hostTimeSeconds());
  for (const TriggerEndpoint& e : to) {
    sockaddr_in a;
    try {
      a = endpointAddress(e, "sendTrigger");
    } catch (...) {
      ::close(fd);
      throw;
    }
    if (::sendto(fd, msg, static_cast<size_t>(len), 0, reinterpret_cast<const sockaddr*>(&a), sizeof a) != len) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw std::runtime_error("[sendTrigger] to " + e.address + ":" + std::to_string(e.port) + ": " + why);
    }
  }
  ::close(fd);
}

SynchronisedSweeps runSynchronisedSweeps(const std::vector<UnitConfig>& units, const SyncOptions& options,
                                         const Progress& progress) {
  const size_t n = units.size();
  validateSweepOptions(options.sweep);
  if (!(options.ready_timeout_s > 0 && std::isfinite(options.ready_timeout_s)))
    throw InvalidInput("[runSynchronisedSweeps] ready_timeout_s must be > 0 (got " + formatFixed(options.ready_timeout_s, 3) +
                       ")");
  if (!options.capture_paths.empty() && options.capture_paths.size() != n)
    throw InvalidInput("[runSynchronisedSweeps] capture_paths must name one capture per unit (" + std::to_string(n) +
                       " units, got " + std::to_string(options.capture_paths.size()) + ")");
  SynchronisedSweeps out;
  out.sweeps.resize(n);
  out.errors.resize(n);
  out.trigger_received_s.assign(n, 0.0);
  std::vector<std::unique_ptr<TriggerListener>> listeners;
  std::vector<TriggerEndpoint> endpoints;
  for (size_t i = 0; i < n; ++i) {
    listeners.push_back(std::make_unique<TriggerListener>(TriggerEndpoint{"127.0.0.1", 0}));
    endpoints.push_back({"127.0.0.1", listeners.back()->port()});
  }
  std::mutex m;
  std::condition_variable cv;
  size_t ready = 0, finished_early = 0;
  std::vector<std::thread> threads;
  const double wait_s = options.ready_timeout_s + 10;
  for (size_t i = 0; i < n; ++i) {
    threads.emplace_back([&, i] {
      SweepOptions o = options.sweep;
      if (i < options.capture_paths.size()) o.capture_path = options.capture_paths[i];
      o.wait_for_start = [&, i] {
        {
          std::lock_guard<std::mutex> lock(m);
          ++ready;
        }
        cv.notify_all();
        const TriggerListener::Trigger t = listeners[i]->wait(wait_s);
        out.trigger_received_s[i] = t.received_s;
        return t.received_s;
      };
      try {
        Progress unit_progress;
        if (i == 0) unit_progress = progress;  // one bar: the first unit's
        out.sweeps[i] = runSweep(units[i], o, unit_progress);
      } catch (const std::exception& e) {
        out.errors[i] = e.what();
        std::lock_guard<std::mutex> lock(m);
        ++finished_early;
        cv.notify_all();
      }
    });
  }
  {
    std::unique_lock<std::mutex> lock(m);
    cv.wait_for(lock, std::chrono::duration<double>(options.ready_timeout_s),
                [&] { return ready + finished_early >= n; });
  }
  // Trigger whoever is ready (units still setting up receive it when they get there, late; the spread shows it).
  try {
    sendTrigger(endpoints, options.trigger_id);
  } catch (const std::exception& e) {
    for (size_t i = 0; i < n; ++i)
      if (out.errors[i].empty()) out.errors[i] = e.what();
  }
  for (std::thread& t : threads) t.join();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (size_t i = 0; i < n; ++i) {
    if (!out.errors[i].empty()) continue;
    lo = std::min(lo, out.sweeps[i].start_time_s);
    hi = std::max(hi, out.sweeps[i].start_time_s);
  }
  out.start_spread_s = hi >= lo ? hi - lo : 0.0;
  return out;
}

}  // namespace sailshape
