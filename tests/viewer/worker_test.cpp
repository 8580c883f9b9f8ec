#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>

#include "viewer/worker.hpp"

namespace sailshape::viewer {
namespace {

// A one-shot gate the test opens to let a job continue (no sleeps, no timing).
class Gate {
 public:
  void open() {
    std::lock_guard<std::mutex> lock(m_);
    open_ = true;
    cv_.notify_all();
  }
  void wait() {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [&] { return open_; });
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool open_ = false;
};

TEST(Worker, RunsAJobAndDeliversItsResultOnce) {
  Task<int> task;
  EXPECT_EQ(task.status().state, JobState::Idle);
  task.start("sum", [](const Progress& p) {
    int sum = 0;
    for (int i = 1; i <= 100; ++i) {
      sum += i;
      p("summing", i / 100.0);
    }
    return sum;
  });
  task.wait();
  const JobStatus st = task.status();
  EXPECT_EQ(st.state, JobState::Succeeded);
  EXPECT_EQ(st.name, "sum");
  EXPECT_EQ(st.stage, "summing");
  EXPECT_DOUBLE_EQ(st.fraction, 1.0);
  EXPECT_EQ(task.take(), std::optional<int>(5050));
  EXPECT_EQ(task.take(), std::nullopt);
}

TEST(Worker, ProgressIsVisibleWhileTheJobRuns) {
  Gate reported, finish;
  Task<int> task;
  task.start("slow", [&](const Progress& p) {
    p("normals", 0.25);
    reported.open();
    finish.wait();
    return 1;
  });
  reported.wait();
  const JobStatus st = task.status();
  EXPECT_EQ(st.state, JobState::Running);
  EXPECT_TRUE(task.busy());
  EXPECT_EQ(st.stage, "normals");
  EXPECT_DOUBLE_EQ(st.fraction, 0.25);
  EXPECT_EQ(task.take(), std::nullopt);
  EXPECT_THROW(task.start("second", [](const Progress&) { return 2; }), std::logic_error);
  finish.open();
  task.wait();
  EXPECT_EQ(task.take(), std::optional<int>(1));
}

TEST(Worker, CancelStopsTheJobAtItsNextProgressReport) {
  Gate started;
  std::atomic<int> steps_after_cancel{0};
  std::atomic<bool> cancelled{false};
  Task<int> task;
  task.start("endless", [&](const Progress& p) {
    started.open();
    for (;;) {
      p("smoothing", 0.5);  // throws Cancelled once cancel() was called
      if (cancelled) ++steps_after_cancel;
    }
    return 0;
  });
  started.wait();
  // Cancel first, then raise the test's flag: a step counted after the flag is
  // one whose progress report came after cancel() took effect (or the single
  // report already past its check when cancel() was called). The other order
  // counts the steps the job legitimately runs between the flag and cancel().
  task.cancel();
  cancelled = true;
  task.wait();
  EXPECT_EQ(task.status().state, JobState::Cancelled);
  EXPECT_LE(steps_after_cancel.load(), 1);
  EXPECT_EQ(task.take(), std::nullopt);
  // The worker is free again.
  task.start("after", [](const Progress&) { return 7; });
  task.wait();
  EXPECT_EQ(task.take(), std::optional<int>(7));
}

TEST(Worker, AFailingJobReportsItsMessage) {
  Task<int> task;
  task.start("bad", [](const Progress&) -> int { throw std::runtime_error("[analyzeSail] empty cloud"); });
  task.wait();
  const JobStatus st = task.status();
  EXPECT_EQ(st.state, JobState::Failed);
  EXPECT_EQ(st.error, "[analyzeSail] empty cloud");
  EXPECT_EQ(task.take(), std::nullopt);
}

TEST(Worker, GenerationTellsJobsApart) {
  Worker w;
  w.start("a", [](const Progress&) {});
  w.wait();
  const uint64_t first = w.status().generation;
  w.start("b", [](const Progress&) {});
  w.wait();
  EXPECT_EQ(w.status().generation, first + 1);
  EXPECT_EQ(w.status().name, "b");
}

TEST(Worker, DestructorCancelsARunningJob) {
  Gate started;
  std::atomic<bool> unwound{false};
  {
    Worker w;
    w.start("endless", [&](const Progress& p) {
      struct Flag {
        std::atomic<bool>& f;
        ~Flag() { f = true; }
      } flag{unwound};
      started.open();
      for (;;) p("x", 0);
    });
    started.wait();
  }
  EXPECT_TRUE(unwound);
}

}  // namespace
}  // namespace sailshape::viewer
