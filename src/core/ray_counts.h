// Rays traced, for benchmarks: a plain add to a thread-local count per ray (no lock, no atomic,
// no thread-local guard on the tracing path), joined to the process's totals when the thread's
// share of a parallel loop ends (core/parallel.h) and read as those totals plus the reading
// thread's own count. After a parallel loop returns, its rays are all in the totals.
#pragma once
#include <atomic>
#include <cstdint>

namespace pl::rays {

struct Counts {
  uint64_t all = 0, shadow = 0;  // every ray; the occlusion (shadow) rays among them
};
inline thread_local Counts local;  // constant-initialised and trivial: accessed directly
inline std::atomic<uint64_t> joinedAll{0}, joinedShadow{0};

inline void add(uint64_t all, uint64_t shadow) {
  local.all += all;
  local.shadow += shadow;
}
// Joins this thread's counts to the totals.
inline void join() {
  if (local.all) joinedAll.fetch_add(local.all, std::memory_order_relaxed);
  if (local.shadow) joinedShadow.fetch_add(local.shadow, std::memory_order_relaxed);
  local = Counts{};
}
inline uint64_t all() { return joinedAll.load(std::memory_order_relaxed) + local.all; }
inline uint64_t shadow() { return joinedShadow.load(std::memory_order_relaxed) + local.shadow; }

}  // namespace pl::rays
