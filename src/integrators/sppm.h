#pragma once
#include "integrators/progressive.h"

namespace pl {

// Stochastic progressive photon mapping (Hachisuka & Jensen 2009), arranged as in pbrt-v3.
// Every pass re-traces each pixel's camera ray with fresh jitter to a new visible point, so
// antialiasing, glossy reflection and motion through glass converge too; the statistics
// (N, R, τ) belong to the pixel and are updated with the PPM rules. The gather points are
// traceGatherPoints': the visible point, and where the path went on through a narrow glossy
// lobe, that vertex, which gathers caustic photons into a second set of statistics. Direct
// light is computed on the way each pass (averaged) by a light and a BSDF sample under MIS
// (estimateDirectMIS), so photon passes deposit only photons that bounced at least once.
class SPPMIntegrator final : public PassIntegrator {
 public:
  using PassIntegrator::PassIntegrator;
  ImageRGB render(const Scene& scene, const RenderOptions& image, RenderInfo* info) override;
  const char* name() const override { return "sppm"; }
};

}  // namespace pl
