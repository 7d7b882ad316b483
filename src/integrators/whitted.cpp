#include "integrators/whitted.h"

#include "integrators/builtins.h"

namespace pl {

Spectrum WhittedIntegrator::trace(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler, int depth) const {
  SurfaceHit hit;
  if (!scene.intersect(ray, &hit)) return escapedRadiance(scene, ray.d, lambda, true, 0.0f);
  const Spectrum T = scene.transmittance(hit, ray.d, lambda);
  Spectrum L(0.0f);
  if (hit.light) L += hit.light->L(hit.uv, -ray.d, lambda);
  Vec3 wo = hit.shading.toLocal(-ray.d);
  if (!hit.bsdf->isSpecular()) return T * (L + estimateDirect(scene, hit, wo, lambda, sampler, false));
  if (depth >= maxDepth_) return T * L;
  // Every specular lobe the BSDF has, reflection first; each contributes weight × probability
  // (e.g. F·1 for reflection, (1−F)/η² for refraction). Both are found before either is traced,
  // with the wavelengths a dispersive lobe leaves.
  BSDFSample lobes[2];
  int count = 0;
  for (BSDFFlags lobe : {kSpecularReflection, kSpecularTransmission}) {
    BSDFSample s;
    if (!(hit.bsdf->flags() & lobe) || !hit.bsdf->specularLobe(wo, bsdfContext(hit, lambda), lobe, &s)) continue;
    if (s.terminatesSecondary) lambda.terminateSecondary();
    lobes[count++] = s;
  }
  for (int i = 0; i < count; ++i) {
    Spectrum w = lobes[i].weight * lobes[i].pdf;
    if (isBlack(w)) continue;
    L += w * trace(scene.spawnRay(hit, hit.shading.toWorld(lobes[i].wi)), scene, lambda, sampler, depth + 1);
  }
  return T * L;
}

IntegratorEntry whittedEntry() {
  IntegratorEntry e(
      "whitted", "Whitted ray tracing: shadow rays at diffuse surfaces, recursion along every specular lobe",
      IntegratorFamily::Pixel, "spp",
      {params::spp(), params::maxDepth()},
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<WhittedIntegrator>(int(p.integer("max_depth"))); });
  e.converges = Converges::kDirectLighting;  // at diffuse surfaces; specular chains are followed
  return e;
}

}  // namespace pl
