#include "integrators/integrator.h"

namespace pl {

Spectrum estimateDirect(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, const SampledWavelengths& lambda,
                        Rng& rng, bool mis) {
  return estimateDirectWeighted(scene, hit, woLocal, lambda, rng, [&](float lightPdf, const Vec3& wi, const Vec3&) {
    return mis ? powerHeuristic(lightPdf, hit.bsdf->pdf(woLocal, wi, BSDFContext(hit.uv, lambda))) : 1.0f;
  });
}

}  // namespace pl
