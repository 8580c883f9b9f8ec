#include "viewer/worker.hpp"

namespace sailshape::viewer {

Worker::~Worker() {
  cancel();
  join();
}

void Worker::join() {
  if (thread_.joinable()) thread_.join();
}

void Worker::start(std::string name, std::function<void(const Progress&)> job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status_.state == JobState::Running)
      throw std::logic_error("[Worker::start] \"" + status_.name + "\" is still running; cannot start \"" + name + "\"");
  }
  join();  // the previous job has ended; reap its thread
  cancel_ = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.state = JobState::Running;
    status_.name = std::move(name);
    status_.stage.clear();
    status_.fraction = 0;
    status_.error.clear();
    ++status_.generation;
  }
  thread_ = std::thread([this, job = std::move(job)] {
    Progress progress;
    progress.callback = [this](std::string_view stage, double fraction) {
      if (cancel_) throw Cancelled();
      std::lock_guard<std::mutex> lock(mutex_);
      status_.stage.assign(stage.begin(), stage.end());
      status_.fraction = fraction;
    };
    JobState end = JobState::Succeeded;
    std::string error;
    try {
      job(progress);
      if (cancel_) end = JobState::Cancelled;  // the job ended without another checkpoint
    } catch (const Cancelled&) {
      end = JobState::Cancelled;
    } catch (const std::exception& e) {
      end = JobState::Failed;
      error = e.what();
    } catch (...) {
      end = JobState::Failed;
      error = "unknown exception";
    }
    std::lock_guard<std::mutex> lock(mutex_);
    status_.state = end;
    status_.error = std::move(error);
  });
}

void Worker::cancel() { cancel_ = true; }

void Worker::wait() { join(); }

JobStatus Worker::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

}  // namespace sailshape::viewer
