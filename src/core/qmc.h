// Quasi-Monte Carlo points for estimators that take many samples of one integral (a pixel's
// samples, a light path index's iterations): the Sobol' (0,2)-sequence in two dimensions with
// hash-based Owen scrambling (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//
// An Owen-scrambled point is uniform on [0,1)² on its own, so an estimator stays unbiased; the
// first 2^k points of one scrambled sequence still fall one in each of the 2^k elementary
// intervals of every shape (the (0,2) property), so a smooth 2D integrand converges faster than
// with independent points. Higher dimensions are padded: each pair of dimensions gets its own
// scramble and its own shuffle of the index (itself an Owen scramble, which keeps every
// power-of-two prefix a permutation of the same points), so that pairs are independent of one
// another while each is stratified.
#pragma once
#include <cstdint>

#include "core/common.h"
#include "core/rng.h"

namespace pl::qmc {

inline uint32_t reverseBits(uint32_t x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}

// Laine and Karras' permutation: each bit flips by a function of the bits below it only, which
// after the bit reversal below is Owen's nested scramble (each bit by the bits above it).
inline uint32_t laineKarras(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// Owen's nested uniform scramble of a 32-bit binary fraction.
inline uint32_t owenScramble(uint32_t x, uint32_t seed) { return reverseBits(laineKarras(reverseBits(x), seed)); }

// The Sobol' sequence's second dimension (its first is the van der Corput sequence, the bit
// reversal of the index). Its direction numbers are the rows of Pascal's triangle mod 2
// (v_k = v_{k−1} ^ (v_{k−1} >> 1)), so the j-th binary digit of point i is the XOR of index
// bits k with C(k, j) odd, which by Lucas' theorem are the k whose bits contain j's: a
// superset sum over 5-bit positions, five shift-and-mask steps instead of a loop over the
// index's 32 bits. Returned with digit j in bit j (reversed); sobolSecond() as a fraction.
inline uint32_t sobolSecondReversed(uint32_t index) {
  uint32_t w = index;  // bit k: index bit k; becomes the XOR over the supersets of k
  w ^= (w >> 1) & 0x55555555u;
  w ^= (w >> 2) & 0x33333333u;
  w ^= (w >> 4) & 0x0f0f0f0fu;
  w ^= (w >> 8) & 0x00ff00ffu;
  w ^= (w >> 16) & 0x0000ffffu;
  return w;
}
inline uint32_t sobolSecond(uint32_t index) { return reverseBits(sobolSecondReversed(index)); }

inline float toUnit(uint32_t x) { return float(x >> 8) * 0x1p-24f; }  // [0, 1), as Rng::uniform()

// Point `index` of the scrambled, shuffled 2D sequence named by `seed`: the index Owen-scrambled
// (the shuffle), then both coordinates. Written without the reversals that cancel:
// owenScramble(reverseBits(i)) = reverseBits(laineKarras(i)), and likewise for the second
// coordinate, whose digits sobolSecondReversed() already gives in reversed order.
inline Vec2 sobol2D(uint32_t index, uint64_t seed) {
  const uint64_t h = mix64(seed);
  const uint32_t i = owenScramble(index, uint32_t(h));
  const uint32_t x = reverseBits(laineKarras(i, uint32_t(h >> 32)));
  const uint32_t y = reverseBits(laineKarras(sobolSecondReversed(i), uint32_t(mix64(h))));
  return Vec2(toUnit(x), toUnit(y));
}

// The points `index` of `count` sequences at once, sequence k seeded slotSeed(key, k): what a
// Sampler's slots hold (core/sampler.h), each as sobol2D gives it. One loop over the slots,
// vectorised (qmc.cpp), instead of a call per draw: a point is over a hundred instructions of
// hashing, which one at a time showed in a bdpt iteration's profile (docs: Performance).
constexpr int kMaxSlots = 8;
inline uint64_t slotSeed(uint64_t key, int slot) { return key ^ (uint64_t(slot) * 0x9e3779b97f4a7c15ULL); }
void sobol2DSlots(uint32_t index, uint64_t key, int count, Vec2* points);

}  // namespace pl::qmc
