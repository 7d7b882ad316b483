// Running one copy of a SIMD-lane kernel (core/lanes_copies.h) in a test, through the
// PHOTONLAB_LANES_ISA override (core/lanes_isa.h).
#pragma once
#include <cstdlib>
#include <vector>

#include "core/lanes_isa.h"

namespace pl::test {

// Runs the kernels' copy for one instruction set while it lives.
struct LanesCopy {
  explicit LanesCopy(const char* isa) { setenv("PHOTONLAB_LANES_ISA", isa, 1); }
  ~LanesCopy() { unsetenv("PHOTONLAB_LANES_ISA"); }
  LanesCopy(const LanesCopy&) = delete;
  LanesCopy& operator=(const LanesCopy&) = delete;
};

// Both copies where this CPU runs both (AVX-512 first); the baseline one everywhere.
inline std::vector<const char*> lanesCopies() {
  if (lanes::cpuHasAvx512()) return {"avx512", "baseline"};
  return {"baseline"};
}

}  // namespace pl::test
