// Resource limits: a request read from a file or the command line (photon counts, resolution,
// image sizes) is checked against the memory actually available before anything is allocated,
// so an impossible request is a clear error instead of an out-of-memory kill.
#pragma once
#include <cstdint>
#include <string>

namespace pl {

// MemAvailable from /proc/meminfo (bytes), or physical memory if that is unreadable. The
// environment variable PHOTONLAB_MEMORY_LIMIT (bytes) lowers it, for tests and shared machines.
uint64_t availableMemory();

// Throws Error("WHAT: needs X GiB, but only Y GiB of memory is available") when `bytes` exceeds
// the available memory. Overflow-safe callers pass saturated products (see mulSaturate).
void checkMemory(uint64_t bytes, const std::string& what);

inline uint64_t mulSaturate(uint64_t a, uint64_t b) {
  return a != 0 && b > UINT64_MAX / a ? UINT64_MAX : a * b;
}

}  // namespace pl
