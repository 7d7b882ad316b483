#include "core/memory.h"

#include <sys/mman.h>
#include <unistd.h>

#include <new>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/common.h"

namespace pl {

uint64_t availableMemory() {
  uint64_t bytes = 0;
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  uint64_t kib;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") {
      bytes = kib * 1024;
      break;
    }
  }
  if (bytes == 0) bytes = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGE_SIZE));
  if (const char* limit = std::getenv("PHOTONLAB_MEMORY_LIMIT")) {
    char* end = nullptr;
    unsigned long long v = std::strtoull(limit, &end, 10);
    if (end != limit && v < bytes) bytes = v;
  }
  return bytes;
}

void checkMemory(uint64_t bytes, const std::string& what) {
  uint64_t available = availableMemory();
  if (bytes <= available) return;
  char buf[160];
  std::snprintf(buf, sizeof buf, ": needs %.3g GiB, but only %.3g GiB of memory is available", double(bytes) / (1u << 30),
                double(available) / (1u << 30));
  throw Error(what + buf);
}

void* allocateLarge(size_t bytes) {
  if (bytes == 0) return nullptr;
  void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  return p;
}

void freeLarge(void* p, size_t bytes) {
  if (p && bytes) munmap(p, bytes);
}

}  // namespace pl
