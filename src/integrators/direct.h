#pragma once
#include "render/integrator.h"

namespace pl {

// Local illumination: emitted radiance seen directly, plus one shadow-ray light sample at the
// first hit. Mirrors and glass show only what they emit (black).
class DirectIntegrator final : public PixelIntegrator {
 public:
  explicit DirectIntegrator(bool sobol = false) : sobol_(sobol) {}
  Spectrum Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const override;
  const char* name() const override { return "direct"; }
  // --sampler sobol: the jitter, the light pick and the point on the light, each a Sobol' point.
  static constexpr int kSobolSlots = 3;
  int sobolSlots() const override { return sobol_ ? kSobolSlots : 0; }

 private:
  bool sobol_;
};

}  // namespace pl
