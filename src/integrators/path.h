#pragma once
#include <memory>

#include "render/integrator.h"
#include "integrators/path_lanes.h"

namespace pl {

// Unidirectional path tracing, the ground truth every other method is compared against.
// Next-event estimation at every non-delta vertex, combined with BSDF sampling of emitters by
// multiple importance sampling (power heuristic), Russian roulette from the 4th bounce on.
// Solves L(x, ωo) = Le + ∫ f(ωo, ωi) L(x', −ωi) |cosθi| dωi without bias (up to maxDepth).
// --sampler sobol draws each path's first random numbers from Owen-scrambled Sobol' points over
// the pixel's samples (core/sampler.h).
//
// `lanes` (the default): where the CPU, the scene and the options allow (PathLanes::unsupported: AVX-512, RGB,
// independent samples), a batch of rows' paths run 16 at a time in SIMD lanes (integrators/path_lanes.h),
// the same estimator with the same random numbers; elsewhere, and with lanes off, one at a time.
class PathIntegrator final : public PixelIntegrator {
 public:
  // Every argument given: the defaults are the registry's declaration (path.cpp), nowhere else.
  PathIntegrator(int maxDepth, bool sobol, bool lanes, bool spectral)
      : maxDepth_(maxDepth), sobol_(sobol), lanesWanted_(lanes && !sobol && !spectral) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  void LiPacket(CameraSample* samples, int n, const Scene& scene) const override;
  void preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) override;
  int packetSize() const override { return lanes_ ? kLanesBatch : Scene::kPacket; }
  // Whether the last render's scene ran in lanes, and if not, why (empty: it did).
  const std::string& lanesUnused() const { return lanesUnused_; }
  // The most camera samples handed to the lanes at once: as many whole rows as fit (a longer
  // row in pieces). The fewer paths a batch holds, the emptier its last packets run as paths
  // end (the batch size measured: docs explanation/performance.md).
  static constexpr int kLanesBatch = 1024;
  const char* name() const override { return "path"; }
  int sobolSlots() const override { return sobol_ ? kSobolSlots : 0; }
  // --sampler sobol's draws per path: the jitter, then four per non-specular vertex (light pick,
  // point on the light, BSDF direction, lobe choice), which reaches the second vertex's direct
  // light and direction; more slots cost time and bought no error (docs: Performance).
  static constexpr int kSobolSlots = 8;

 private:
  // The path from its camera ray's first hit (null: the ray left the scene).
  Spectrum Li(const Ray& ray, const SurfaceHit* firstHit, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const;
  int maxDepth_;
  bool sobol_;
  bool lanesWanted_;
  std::unique_ptr<PathLanes> lanes_;  // built by preprocess where the scene allows
  std::string lanesUnused_;
};

}  // namespace pl
