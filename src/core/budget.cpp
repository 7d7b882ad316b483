#include "core/budget.h"

namespace pl {

Budget::Budget(double seconds, Clock* clock) : limit_(seconds > 0 ? seconds : 0.0), clock_(clock) {
  if (limit_ > 0 && !clock_) watchdog_ = std::thread([this] { watch(); });
}

Budget::~Budget() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

double Budget::now() const {
  if (clock_) return clock_->seconds();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - steadyStart_).count();
}

double Budget::elapsedLocked(double now) const {
  double total = now - start_ - paused_;
  if (pausedNow_) total -= now - pauseStart_;
  return total;
}

double Budget::elapsed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return elapsedLocked(now());
}

void Budget::pollClock() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!pausedNow_ && elapsedLocked(now()) >= limit_) timeUp_.store(true);
}

void Budget::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (pausedNow_) return;
  pausedNow_ = true;
  pauseStart_ = now();
}

void Budget::resume() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!pausedNow_) return;
    paused_ += now() - pauseStart_;
    pausedNow_ = false;
  }
  wake_.notify_all();  // the deadline moved
}

// Sleeps until the time is spent (re-computing the deadline whenever a pause ends), then raises
// the flag once.
void Budget::watch() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!done_) {
    if (pausedNow_) {
      wake_.wait(lock);
      continue;
    }
    double remaining = limit_ - elapsedLocked(now());
    if (remaining <= 0) {
      timeUp_.store(true);
      return;
    }
    wake_.wait_for(lock, std::chrono::duration<double>(remaining));
  }
}

}  // namespace pl
