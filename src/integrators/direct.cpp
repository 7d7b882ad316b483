#include "integrators/direct.h"

#include "integrators/builtins.h"

namespace pl {

Spectrum DirectIntegrator::Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const {
  SurfaceHit hit;
  if (!scene.intersect(ray, &hit)) return escapedRadiance(scene, ray.d, lambda, true, 0.0f);
  Spectrum L(0.0f);
  if (hit.light) L += hit.light->L(hit.uv, -ray.d, lambda);
  if (!hit.bsdf->isSpecular()) L += estimateDirect(scene, hit, hit.shading.toLocal(-ray.d), lambda, sampler, false);
  return L;
}

IntegratorEntry directEntry() {
  IntegratorEntry e(
      "direct", "emission seen directly plus one shadow-ray light sample at the first hit (local illumination)",
      IntegratorFamily::Pixel, "spp",
      {params::spp(), params::sampler(DirectIntegrator::kSobolSlots, "camera path", "the pixel's samples")},
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<DirectIntegrator>(p.choice("sampler") == "sobol"); });
  e.converges = Converges::kDirectLighting;
  return e;
}

}  // namespace pl
