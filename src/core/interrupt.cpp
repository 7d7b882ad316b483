#include "core/interrupt.h"

#include <unistd.h>

#include <atomic>
#include <csignal>

namespace pl {
namespace {

std::atomic<bool> gInterrupted{false}, gCooperative{false};
std::atomic<int> gSignal{0};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag must be safe to set from a signal handler");

extern "C" void onInterruptSignal(int sig) {
  if (!gCooperative.load()) _exit(128 + sig);         // nothing to save yet: stop now
  if (gInterrupted.exchange(true)) _exit(128 + sig);  // second signal: stop now
  gSignal = sig;
}

}  // namespace

void installInterruptHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onInterruptSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void setInterruptCooperative(bool cooperative) { gCooperative = cooperative; }
void requestInterrupt() { gInterrupted = true; }
bool interruptRequested() { return gInterrupted.load(std::memory_order_relaxed); }
int interruptSignal() { return gSignal.load(); }
void clearInterrupt() {
  gInterrupted = false;
  gSignal = 0;
}

}  // namespace pl
