#pragma once
#include "integrators/integrator.h"

namespace pl {

// Unidirectional path tracing, the ground truth every other method is compared against.
// Next-event estimation at every non-delta vertex, combined with BSDF sampling of emitters by
// multiple importance sampling (power heuristic), Russian roulette from the 4th bounce on.
// Solves L(x, ωo) = Le + ∫ f(ωo, ωi) L(x', −ωi) |cosθi| dωi without bias (up to maxDepth).
// --sampler sobol draws each path's first random numbers from Owen-scrambled Sobol' points over
// the pixel's samples (core/sampler.h).
class PathIntegrator final : public PixelIntegrator {
 public:
  explicit PathIntegrator(int maxDepth, bool sobol = false) : maxDepth_(maxDepth), sobol_(sobol) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  void LiPacket(CameraSample* samples, int n, const Scene& scene) const override;
  const char* name() const override { return "path"; }
  int sobolSlots() const override { return sobol_ ? kSobolSlots : 0; }
  // --sampler sobol's draws per path: the jitter, then four per non-specular vertex (light pick,
  // point on the light, BSDF direction, lobe choice), which reaches the second vertex's direct
  // light and direction. On the Cornell box (128², 256 spp), 16 and 32 slots gave the error of
  // 8 within 2–5%, and cost 3% and 8% more time than 8 (each point is ~150 instructions).
  static constexpr int kSobolSlots = 8;

 private:
  // The path from its camera ray's first hit (null: the ray left the scene).
  Spectrum Li(const Ray& ray, const SurfaceHit* firstHit, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const;
  int maxDepth_;
  bool sobol_;
};

}  // namespace pl
