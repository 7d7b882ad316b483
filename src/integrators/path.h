#pragma once
#include "integrators/integrator.h"

namespace pl {

// Unidirectional path tracing, the ground truth every other method is compared against.
// Next-event estimation at every non-delta vertex, combined with BSDF sampling of emitters by
// multiple importance sampling (power heuristic), Russian roulette from the 4th bounce on.
// Solves L(x, ωo) = Le + ∫ f(ωo, ωi) L(x', −ωi) |cosθi| dωi without bias (up to maxDepth).
class PathIntegrator final : public PixelIntegrator {
 public:
  explicit PathIntegrator(int maxDepth) : maxDepth_(maxDepth) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  const char* name() const override { return "path"; }

 private:
  int maxDepth_;
};

}  // namespace pl
