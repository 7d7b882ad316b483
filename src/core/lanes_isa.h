// Which copy of a SIMD-lane kernel runs (core/lanes_copies.h), and whether lanes pay at all.
//
// The AVX-512 copy runs where the CPU has AVX-512 (x86-64-v4). The baseline copy runs anywhere
// but slowly: without 64-byte registers GCC splits every 16-lane comparison lane by lane, and
// the kernel is slower than one path at a time (an AVX2 copy too; docs: Performance). So
// without AVX-512 the callers run their one-path code instead, unless PHOTONLAB_LANES_ISA
// (avx512 or baseline) asks for a copy: tests use it to check both copies on one machine.
#pragma once
#include <cstdlib>
#include <cstring>

#include "core/common.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define PL_LANES_TARGETS 1  // the avx512 copy is compiled for AVX-512
#else
#define PL_LANES_TARGETS 0
#endif

namespace pl::lanes {

enum class Isa { Avx512, Baseline };

inline bool cpuHasAvx512() {
#if PL_LANES_TARGETS
  return __builtin_cpu_supports("x86-64-v4");
#else
  return false;
#endif
}

// The copy PHOTONLAB_LANES_ISA names, if it is set (an unknown name, or avx512 on a CPU without
// it, is an error). Read on every call, so that a test can switch it between renders.
inline const char* requestedIsa(Isa* isa) {
  const char* name = std::getenv("PHOTONLAB_LANES_ISA");
  if (!name) return nullptr;
  if (std::strcmp(name, "avx512") == 0) {
    if (!cpuHasAvx512()) throw Error("PHOTONLAB_LANES_ISA: this CPU has no AVX-512");
    *isa = Isa::Avx512;
  } else if (std::strcmp(name, "baseline") == 0) {
    *isa = Isa::Baseline;
  } else {
    throw Error(std::string("PHOTONLAB_LANES_ISA: '") + name + "' is neither avx512 nor baseline");
  }
  return name;
}

// The copy to run: the one asked for, else AVX-512 where the CPU has it, else baseline.
inline Isa bestIsa() {
  Isa isa = Isa::Baseline;
  if (requestedIsa(&isa)) return isa;
  return cpuHasAvx512() ? Isa::Avx512 : Isa::Baseline;
}

// Whether lanes beat one path at a time here: the AVX-512 copy, or a copy asked for.
inline bool lanesPay() {
  Isa isa = Isa::Baseline;
  return requestedIsa(&isa) != nullptr || cpuHasAvx512();
}

}  // namespace pl::lanes
