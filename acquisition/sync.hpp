#pragma once
// Synchronised units: a master sends a UDP trigger datagram and each unit starts
// its sweep on it, recording when it arrived; the spread of start times is
// reported. Datagram: "SAILSHAPE-TRIGGER <id> <sender steady-clock seconds>".
#include <cstdint>
#include <string>
#include <vector>

#include "acquisition/sweep.hpp"

namespace sailshape {

struct TriggerEndpoint {
  std::string address = "127.0.0.1";
  uint16_t port = 0;
};

// A bound UDP socket waiting for the trigger (bind before the master sends).
class TriggerListener {
 public:
  // port 0: any free port (see port()). Throws std::runtime_error naming the address on failure.
  explicit TriggerListener(const TriggerEndpoint& bind_to);
  ~TriggerListener();
  TriggerListener(const TriggerListener&) = delete;
  TriggerListener& operator=(const TriggerListener&) = delete;
  uint16_t port() const { return port_; }

  struct Trigger {
    uint64_t id = 0;
    double received_s = 0;  // host steady clock at arrival
  };
  // Waits for a valid trigger datagram (others are ignored); throws std::runtime_error on timeout.
  Trigger wait(double timeout_s);

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
};

// Sends one trigger datagram to each endpoint. Throws std::runtime_error naming a failing endpoint.
void sendTrigger(const std::vector<TriggerEndpoint>& to, uint64_t id);

struct SynchronisedSweeps {
  std::vector<Sweep> sweeps;        // one per unit, in order (empty sweep + error for a unit that failed)
  std::vector<std::string> errors;  // per unit: empty, or why its sweep failed
  std::vector<double> trigger_received_s;
  double start_spread_s = 0;        // max − min of the sweeps' start times (units that started)
};

struct SyncOptions {
  SweepOptions sweep;               // wait_for_start is set by runSynchronisedSweeps
  std::vector<std::string> capture_paths;  // per unit (empty, or one per unit): raw telegram captures
  double ready_timeout_s = 120;     // for every unit to be homed and streaming
  uint64_t trigger_id = 1;
};

// Runs one sweep per unit in parallel; when all stand ready at their start angle, sends the trigger over
// UDP on loopback, and every unit starts its sweep on receipt. A unit that fails is reported in `errors`;
// the others still run.
SynchronisedSweeps runSynchronisedSweeps(const std::vector<UnitConfig>& units, const SyncOptions& options = {},
                                         const Progress& progress = {});

}  // namespace sailshape
