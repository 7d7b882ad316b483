#pragma once
#include "render/integrator.h"

namespace pl {

// Whitted (1980) ray tracing: direct light by shadow rays at diffuse and glossy surfaces;
// at mirrors and glass, recursion along *every* specular lobe (reflection weighted by Fresnel,
// refraction by 1 − F), up to maxDepth. No diffuse interreflection, no caustics.
class WhittedIntegrator final : public PixelIntegrator {
 public:
  explicit WhittedIntegrator(int maxDepth) : maxDepth_(maxDepth) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override {
    return trace(ray, scene, lambda, sampler, 0);
  }
  const char* name() const override { return "whitted"; }

 private:
  Spectrum trace(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler, int depth) const;
  int maxDepth_;
};

}  // namespace pl
