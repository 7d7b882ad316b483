// PCG32 (O'Neill 2014) random numbers. Streams are keyed by *what* is being sampled
// (seed, pixel, sample index; later photon index) and never by thread, so an image is
// bit-identical whatever the number of threads.
#pragma once
#include <cstdint>

namespace pl {

// SplitMix64 finaliser: turns structured keys (0, 1, 2, ...) into well-spread 64-bit states.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Rng {
 public:
  explicit Rng(uint64_t seed = 0, uint64_t stream = 0) { reset(seed, stream); }

  // One independent stream per (seed, a, b): e.g. (seed, pixel index, sample index).
  static Rng keyed(uint64_t seed, uint64_t a, uint64_t b) {
    return Rng(mix64(seed ^ mix64(a + 0x9e3779b97f4a7c15ULL)) ^ mix64(b * 0xd1b54a32d192ed03ULL + 1),
               mix64(a) ^ b);
  }

  // A stream started at a hashed position of one sequence: `key` identifies what is sampled
  // (e.g. a photon map), `index` the item (photon i). One hash instead of keyed()'s four and
  // no warm-up steps, for the photon tracer, which starts a stream per emitted photon; PCG's
  // output permutation makes the first number as good as any later one.
  static Rng hashed(uint64_t key, uint64_t index) {
    Rng r;
    r.state_ = mix64(key + index * 0x9e3779b97f4a7c15ULL);
    r.inc_ = (key << 1u) | 1u;
    return r;
  }

  void reset(uint64_t seed, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    nextU32();
    state_ += seed;
    nextU32();
  }

  uint32_t nextU32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }

  // Uniform in [0, 1): 24 random mantissa bits, so 1.0f is never returned.
  float uniform() { return float(nextU32() >> 8) * 0x1p-24f; }

  // The generator's two words, for code that advances many streams side by side in SIMD lanes
  // (core/lanes.h uniforms): state' = state · 6364136223846793005 + increment.
  uint64_t state() const { return state_; }
  uint64_t increment() const { return inc_; }

 private:
  uint64_t state_, inc_;
};

}  // namespace pl
