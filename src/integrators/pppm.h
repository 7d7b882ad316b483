#pragma once
#include "integrators/progressive.h"

namespace pl {

// Probabilistic progressive photon mapping (Knaus & Zwicker 2011). Pass i is an ordinary,
// independent photon-mapping image (direct light from a light and a BSDF sample under MIS, the
// pass's photon map read at traceGatherPoints' points with a fixed radius r_i and the uniform
// kernel); the radius shrinks globally, r²_{i+1} = r²_i (i + α)/(i + 1), and the passes are
// averaged. Memory stays constant, and passes rendered elsewhere can be merged by averaging
// (weighted by pass count).
class PPPMIntegrator final : public PassIntegrator {
 public:
  using PassIntegrator::PassIntegrator;
  ImageRGB render(const Scene& scene, const RenderOptions& image, RenderInfo* info) override;
  const char* name() const override { return "pppm"; }
};

}  // namespace pl
