#include "integrators/direct.h"

namespace pl {

Spectrum DirectIntegrator::Li(const Ray& ray, const Scene& scene, Rng& rng) const {
  SurfaceHit hit;
  if (!scene.intersect(ray, &hit)) return Spectrum(0.0f);
  Spectrum L(0.0f);
  if (hit.light) L += hit.light->L(-ray.d);
  if (!hit.bsdf->isDelta()) L += estimateDirect(scene, hit, hit.shading.toLocal(-ray.d), rng, false);
  return L;
}

}  // namespace pl
