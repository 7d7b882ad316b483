#pragma once
#include "integrators/integrator.h"

namespace pl {

// Local illumination: emitted radiance seen directly, plus one shadow-ray light sample at the
// first hit. Mirrors and glass show only what they emit (black).
class DirectIntegrator final : public PixelIntegrator {
 public:
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  const char* name() const override { return "direct"; }
};

}  // namespace pl
