// Deterministic parallel loop: work items are claimed from an atomic counter, but every
// item's result depends only on its index, so the output never depends on scheduling. The
// threads are a persistent pool, started on first use and grown to the largest count asked
// for, so that a loop of short parallel steps (a progressive pass, a light-path iteration) does
// not start and join threads at every step.
#pragma once
#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "core/ray_counts.h"

namespace pl {

inline int resolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace detail {
// Runs job(0) on the caller's thread and job(1), ..., job(n) on n pool threads, and returns when
// all have returned (core/parallel.cpp). False, with nothing run, when the pool is taken: by
// another thread's loop, or by the loop this one is nested in.
bool runOnPool(int n, const std::function<void(int)>& job);
}  // namespace detail

template <typename Fn>  // fn(size_t item, int threadIndex), threadIndex in [0, threads)
void parallelFor(size_t count, int threads, Fn&& fn) {
  threads = std::max(1, std::min<int>(threads, int(count)));
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex errorMutex;
  auto worker = [&](int t) {
    try {
      for (size_t i; (i = next.fetch_add(1)) < count;) fn(i, t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(errorMutex);
      if (!error) error = std::current_exception();
      next = count;
    }
    rays::join();  // before the loop returns: its rays are in the totals whichever thread asks
  };
  if (threads == 1) {
    worker(0);
  } else {
    if (!detail::runOnPool(threads - 1, worker)) {  // then threads of its own, as many
      std::vector<std::thread> pool;
      for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
      worker(0);
      for (auto& th : pool) th.join();
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace pl
