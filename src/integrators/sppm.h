#pragma once
#include "integrators/progressive.h"

namespace pl {

// Stochastic progressive photon mapping (Hachisuka & Jensen 2009), arranged as in pbrt-v3.
// Every pass re-traces each pixel's camera ray with fresh jitter to a new visible point, so
// antialiasing, glossy reflection and motion through glass converge too; the statistics
// (N, R, τ) belong to the pixel and are updated with the PPM rules. Direct light is computed
// at the visible point each pass (averaged) by a light and a BSDF sample under MIS
// (estimateDirectMIS), so photon passes deposit only photons that bounced at least once
// (caustic and indirect).
class SPPMIntegrator final : public PassIntegrator {
 public:
  using PassIntegrator::PassIntegrator;
  ImageRGB render(const Scene& scene, const RenderOptions& image, RenderInfo* info) override;
  const char* name() const override { return "sppm"; }
};

}  // namespace pl
