#include "core/qmc.h"

namespace pl::qmc {

// Compiled twice, for AVX-512 and for any x86-64, the copy picked when the program loads
// (target_clones). Only integers, no vector comparisons, so GCC's vectoriser, which runs in
// each clone after inlining, gives the AVX-512 clone whole-register code (vpmullq for mix64);
// core/lanes.h says why kernels with comparisons cannot be written this way. Integer
// arithmetic: both clones give sobol2D's points bit for bit.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("arch=x86-64-v4", "default")))
#endif
void sobol2DSlots(uint32_t index, uint64_t key, int count, Vec2* points) {
  uint32_t x[kMaxSlots], y[kMaxSlots];
  for (int k = 0; k < kMaxSlots; ++k) {  // a fixed trip count, for the vectoriser; extra slots unused
    const uint64_t h = mix64(slotSeed(key, k));
    const uint32_t i = owenScramble(index, uint32_t(h));
    x[k] = reverseBits(laineKarras(i, uint32_t(h >> 32)));
    y[k] = reverseBits(laineKarras(sobolSecondReversed(i), uint32_t(mix64(h))));
  }
  for (int k = 0; k < count; ++k) points[k] = Vec2(toUnit(x[k]), toUnit(y[k]));
}

}  // namespace pl::qmc
