#pragma once
#include "integrators/progressive.h"

namespace pl {

// Progressive photon mapping (Hachisuka, Ogaki, Jensen 2008). One eye pass stores a hit point
// per pixel (the first diffuse or glossy point, through mirrors and glass); then every photon
// pass adds the photons inside each hit point's radius and shrinks it:
//   N' = N + αM,  R'² = R² (N + αM)/(N + M),  τ' = (τ + Φ_M) R'²/R²,
// and the pixel converges to Le + τ / (π R² N_emitted). All light at the hit point, direct
// included, comes from photons. The hit points never move: no antialiasing.
class PPMIntegrator final : public PassIntegrator {
 public:
  using PassIntegrator::PassIntegrator;
  ImageRGB render(const Scene& scene, const RenderOptions& image, RenderInfo* info) override;
  const char* name() const override { return "ppm"; }
};

}  // namespace pl
