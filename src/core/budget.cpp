#include "core/budget.h"

namespace pl {

Budget::Budget(double seconds) : limit_(seconds > 0 ? seconds : 0.0) {
  if (limit_ > 0) watchdog_ = std::thread([this] { watch(); });
}

Budget::~Budget() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

double Budget::elapsedLocked(Clock::time_point now) const {
  double total = std::chrono::duration<double>(now - start_).count() - paused_;
  if (pausedNow_) total -= std::chrono::duration<double>(now - pauseStart_).count();
  return total;
}

double Budget::elapsed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return elapsedLocked(Clock::now());
}

void Budget::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (pausedNow_) return;
  pausedNow_ = true;
  pauseStart_ = Clock::now();
}

void Budget::resume() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!pausedNow_) return;
    paused_ += std::chrono::duration<double>(Clock::now() - pauseStart_).count();
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
    double remaining = limit_ - elapsedLocked(Clock::now());
    if (remaining <= 0) {
      timeUp_.store(true);
      return;
    }
    wake_.wait_for(lock, std::chrono::duration<double>(remaining));
  }
}

}  // namespace pl
