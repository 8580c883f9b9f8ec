#pragma once
// Long work (loading a scan, running the pipeline) on one background thread so
// the window stays responsive. The job reports progress through the pipeline's
// Progress callback; cancel() makes the next progress report throw Cancelled,
// which unwinds the job at its next checkpoint.
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "analysis/core/progress.hpp"

namespace sailshape::viewer {

struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

enum class JobState { Idle, Running, Succeeded, Failed, Cancelled };

struct JobStatus {
  JobState state = JobState::Idle;
  std::string name;        // what runs ("analysis of scan 3")
  std::string stage;       // the pipeline stage last reported
  double fraction = 0;     // within that stage, [0, 1]
  std::string error;       // the exception's message when Failed
  uint64_t generation = 0; // increments with every start(): tells one job's end from the next
};

class Worker {
 public:
  Worker() = default;
  ~Worker();  // cancels a running job and waits for it
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Runs `job` on the worker thread. Throws std::logic_error while a job runs.
  void start(std::string name, std::function<void(const Progress&)> job);
  void cancel();
  void wait();  // blocks until the running job (if any) has ended
  JobStatus status() const;
  bool busy() const { return status().state == JobState::Running; }

 private:
  void join();

  mutable std::mutex mutex_;
  JobStatus status_;
  std::atomic<bool> cancel_{false};
  std::thread thread_;
};

// A job with a typed result: the UI starts it, polls status() each frame and
// takes the result once, on the frame it becomes available.
template <class T>
class Task {
 public:
  void start(std::string name, std::function<T(const Progress&)> job) {
    auto slot = std::make_shared<std::optional<T>>();
    worker_.start(std::move(name), [slot, job = std::move(job)](const Progress& p) { *slot = job(p); });
    slot_ = std::move(slot);
  }
  void cancel() { worker_.cancel(); }
  void wait() { worker_.wait(); }
  JobStatus status() const { return worker_.status(); }
  bool busy() const { return worker_.busy(); }
  // The result of a job that succeeded, once; nullopt otherwise.
  std::optional<T> take() {
    if (!slot_ || worker_.status().state != JobState::Succeeded) return std::nullopt;
    std::optional<T> out = std::move(*slot_);
    slot_.reset();
    return out;
  }

 private:
  Worker worker_;
  std::shared_ptr<std::optional<T>> slot_;
};

}  // namespace sailshape::viewer
