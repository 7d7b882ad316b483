// Deterministic parallel loop: work items are claimed from an atomic counter, but every
// item's result depends only on its index, so the output never depends on scheduling.
#pragma once
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace pl {

inline int resolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

template <typename Fn>  // fn(size_t item, int threadIndex)
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
  };
  if (threads == 1) {
    worker(0);
  } else {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
    worker(0);
    for (auto& th : pool) th.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace pl
