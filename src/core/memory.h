// Resource limits: a request read from a file or the command line (photon counts, resolution,
// image sizes) is checked against the memory actually available before anything is allocated,
// so an impossible request is a clear error instead of an out-of-memory kill.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>

namespace pl {

// MemAvailable from /proc/meminfo (bytes), or physical memory if that is unreadable. The
// environment variable PHOTONLAB_MEMORY_LIMIT (bytes) lowers it, for tests and shared machines.
uint64_t availableMemory();

// Throws Error("WHAT: needs X GiB, but only Y GiB of memory is available") when `bytes` exceeds
// the available memory. Overflow-safe callers pass saturated products (see mulSaturate).
void checkMemory(uint64_t bytes, const std::string& what);

// Page-aligned anonymous memory (mmap), zero pages until first written; throws std::bad_alloc
// when the system refuses. freeLarge(nullptr, n) does nothing.
void* allocateLarge(size_t bytes);
void freeLarge(void* p, size_t bytes);

inline uint64_t mulSaturate(uint64_t a, uint64_t b) {
  return a != 0 && b > UINT64_MAX / a ? UINT64_MAX : a * b;
}

// Uninitialised storage for n trivially copyable T, for the photon map's multi-gigabyte
// scratch arrays: their pages are first touched by the loops that fill them, which poll the
// render's budget, instead of being value-initialised up front, which a budget could not stop
// (docs: Performance, Photon maps). Transparent huge pages were slower to fault in (defrag on
// fault).
template <typename T>
class LargeArray {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  explicit LargeArray(size_t n) : n_(n), bytes_(n * sizeof(T)) { data_ = static_cast<T*>(allocateLarge(bytes_)); }
  ~LargeArray() { freeLarge(data_, bytes_); }
  LargeArray(const LargeArray&) = delete;
  LargeArray& operator=(const LargeArray&) = delete;
  void swap(LargeArray& o) noexcept {
    std::swap(n_, o.n_), std::swap(bytes_, o.bytes_), std::swap(data_, o.data_);
  }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  size_t size() const { return n_; }

 private:
  size_t n_, bytes_;
  T* data_;
};

}  // namespace pl
