// A render's time budget and its stop signal. Equal-time comparisons are only fair if every
// method stops when its time is up, wherever it is: in photon tracing, in the kd-tree build, in
// the middle of a pass over the pixels. So the budget is not checked at pass boundaries only:
// a watchdog thread raises a flag when the time is spent, and every loop that can run for long
// polls it between small units of work (a pixel, a chunk of photon paths, a radix-sort pass,
// 2¹⁶ reads of nanoflann's build). SIGINT and SIGTERM (core/interrupt.h) raise it too.
// Polling is one relaxed atomic load, so it costs nothing measurable per pixel.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "core/interrupt.h"

namespace pl {

// Where a budget reads the time: the steady clock unless one is injected. Tests inject a clock
// whose time advances by a fixed step at every reading (SteppingClock), so that a budget ends
// after a known amount of polled work whatever the machine's speed.
class Clock {
 public:
  virtual ~Clock() = default;
  virtual double seconds() = 0;  // monotonic
};

// Each reading returns the previous one plus `step` (thread-safe): time is the work polled.
class SteppingClock final : public Clock {
 public:
  explicit SteppingClock(double step) : step_(step) {}
  double seconds() override { return double(ticks_.fetch_add(1, std::memory_order_relaxed) + 1) * step_; }
  uint64_t readings() const { return ticks_.load(); }

 private:
  double step_;
  std::atomic<uint64_t> ticks_{0};
};

class Budget {
 public:
  // seconds ≤ 0: no time limit (an interrupt still stops the work). With `clock`, time is read
  // from it at every poll (no watchdog thread); otherwise from the steady clock, whose deadline a
  // watchdog thread raises.
  explicit Budget(double seconds = 0.0, Clock* clock = nullptr);
  ~Budget();
  Budget(const Budget&) = delete;
  Budget& operator=(const Budget&) = delete;

  // Stop now: the time is spent, or SIGINT/SIGTERM arrived.
  bool expired() const {
    if (clock_ && limit_ > 0 && !timeUp_.load(std::memory_order_relaxed)) pollClock();
    return timeUp_.load(std::memory_order_relaxed) || interruptRequested();
  }
  bool timeUp() const { return timeUp_.load(std::memory_order_relaxed); }
  double limit() const { return limit_; }
  // How far past the limit (or past an interrupt) a piece of work that does not poll may run:
  // max(0.25 s, 3% of the limit) as equal-time comparisons require, and at most 0.5 s (the
  // allowance without a limit) so that an interrupt takes effect well within 1 s.
  double granularity() const { return limit_ > 0 ? std::min(0.5, std::max(0.25, 0.03 * limit_)) : 0.5; }
  // Seconds since construction, minus the time spent in excluding().
  double elapsed() const;
  // Runs fn without counting its time (checkpoints write images: that is neither part of the
  // measured time nor of the budget).
  template <typename Fn>
  void excluding(Fn&& fn) {
    struct Resume {
      Budget* b;
      ~Resume() { b->resume(); }
    } resume{this};
    pause();
    fn();
  }

 private:
  void pause();
  void resume();
  double now() const;  // seconds on the clock read
  double elapsedLocked(double now) const;
  void watch();
  void pollClock() const;

  const double limit_;
  Clock* const clock_;
  const std::chrono::steady_clock::time_point steadyStart_ = std::chrono::steady_clock::now();
  const double start_ = now();
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  double paused_ = 0.0;            // seconds excluded so far
  bool pausedNow_ = false;
  double pauseStart_ = 0.0;
  bool done_ = false;
  mutable std::atomic<bool> timeUp_{false};
  std::thread watchdog_;
};

// Thrown from deep inside work that has no partial result worth keeping (nanoflann's tree
// build) when its budget expires; caught where the work was started.
struct BudgetExpired : std::exception {
  const char* what() const noexcept override { return "time budget spent or interrupted"; }
};

}  // namespace pl
