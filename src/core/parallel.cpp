#include "core/parallel.h"

#include <condition_variable>

namespace pl::detail {

namespace {

thread_local bool insideJob = false;  // a pool thread, or a caller running its share

class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : threads_) t.join();
  }

  bool run(int n, const std::function<void(int)>& job) {
    if (insideJob) return false;
    std::unique_lock<std::mutex> owner(owner_, std::try_to_lock);
    if (!owner.owns_lock()) return false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      while (int(threads_.size()) < n) {
        const int index = int(threads_.size()) + 1;
        threads_.emplace_back([this, index] { work(index); });
      }
      job_ = &job;
      workers_ = remaining_ = n;
      ++generation_;
    }
    wake_.notify_all();
    insideJob = true;
    job(0);
    insideJob = false;
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return remaining_ == 0; });
    job_ = nullptr;
    return true;
  }

 private:
  // Thread `index` runs every job that asks for at least `index` threads.
  void work(int index) {
    insideJob = true;
    uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (index > workers_) continue;
      const std::function<void(int)>* job = job_;
      lock.unlock();
      (*job)(index);  // parallelFor's worker: it catches what fn throws
      lock.lock();
      if (--remaining_ == 0) done_.notify_one();
    }
  }

  std::mutex owner_;  // one loop at a time
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> threads_;
  const std::function<void(int)>* job_ = nullptr;
  uint64_t generation_ = 0;
  int workers_ = 0, remaining_ = 0;
  bool stop_ = false;
};

}  // namespace

bool runOnPool(int n, const std::function<void(int)>& job) {
  static Pool pool;
  return pool.run(n, job);
}

}  // namespace pl::detail
