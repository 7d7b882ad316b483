// Where a path's random numbers come from (--sampler), for every integrator that traces paths
// sample by sample: the camera paths of the pixel integrators (render/renderer.cpp) and both
// subpaths of the bidirectional ones.
//   independent  its own random stream (core/rng.h), draw after draw;
//   sobol        its first `slots` draws (each a 1D or a 2D sample: the jitter, a light pick, a
//                direction, a lobe choice, a roulette) are points of Owen-scrambled Sobol'
//                sequences (core/qmc.h) indexed by the sample (a pixel's sample number, a
//                light path's iteration), one sequence per (path, draw), so that the samples
//                of one pixel are stratified draw by draw; later draws are the stream's.
// Each point is uniform on its own, so an estimator stays unbiased with either; only how the
// samples of one pixel are spread over the integrand differs.
#pragma once
#include <cstdint>
#include <string>

#include "core/qmc.h"
#include "core/rng.h"

namespace pl {

class Sampler {
 public:
  // `key` names the path (its pixel, its light path index; hashed), `index` its sample number.
  // At most qmc::kMaxSlots slots; their points are made at once, here.
  Sampler(Rng& rng, bool sobol, uint64_t key, uint32_t index, int slots)
      : rng_(rng), sobol_(sobol && slots > 0), slots_(slots) {
    if (slots > qmc::kMaxSlots) throw Error("Sampler: more than " + std::to_string(qmc::kMaxSlots) + " Sobol' slots");
    if (sobol_) qmc::sobol2DSlots(index, key, slots, points_);
  }
  // Independent draws from `rng` alone.
  explicit Sampler(Rng& rng) : Sampler(rng, false, 0, 0, 0) {}

  PL_HOT_INLINE float get1D() { return sobol_ && slot_ < slots_ ? next().x : rng_.uniform(); }
  PL_HOT_INLINE Vec2 get2D() {
    if (sobol_ && slot_ < slots_) return next();
    const float y = rng_.uniform();  // y first, as every image so far and the SIMD lanes draw them
    return Vec2(rng_.uniform(), y);
  }
  bool sobol() const { return sobol_; }
  // The stream independent draws come from (integrators/path_lanes.cpp draws from it in lanes).
  const Rng& rng() const { return rng_; }

 private:
  Vec2 next() { return points_[slot_++]; }
  Rng& rng_;
  bool sobol_;
  int slots_;
  int slot_ = 0;
  Vec2 points_[qmc::kMaxSlots];  // slot k: point `index` of the sequence seeded qmc::slotSeed(key, k)
};

}  // namespace pl
