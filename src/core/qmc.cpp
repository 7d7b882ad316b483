#include "core/qmc.h"

namespace pl::qmc {

// Compiled twice, for AVX-512 and for any x86-64, the copy picked when the program loads
// (target_clones). sobol2D inlined is only integers, no vector comparisons, so GCC's
// vectoriser, which runs in each clone after inlining, gives the AVX-512 clone whole-register
// code (vpmullq for mix64); core/lanes.h says why kernels with comparisons cannot be written
// this way. Integer arithmetic: both clones give sobol2D's points bit for bit.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("arch=x86-64-v4", "default")))
#endif
void sobol2DSlots(uint32_t index, uint64_t key, int count, Vec2* points) {
  Vec2 all[kMaxSlots];
  for (int k = 0; k < kMaxSlots; ++k) all[k] = sobol2D(index, slotSeed(key, k));  // a fixed trip count, for the vectoriser
  for (int k = 0; k < count; ++k) points[k] = all[k];
}

}  // namespace pl::qmc
