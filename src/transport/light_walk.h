// The light subpath's walk, written once, for everything that follows light from the lights:
// light tracing (integrators/light.cpp), the bidirectional methods' light subpaths
// (integrators/bidirectional.cpp) and the photon tracer (photon/photon_tracer.cpp).
//
// A light is picked by power and emits a ray (emitLight); at each surface the ray meets, the walk
// hands the vertex to a walker, which keeps what it needs of it (a splat to the camera, a stored
// light vertex, a photon) and says whether the path goes on; then the BSDF is sampled as the
// adjoint (importance transport, Veach 1997, §3.7) with the shading-normal correction
// (Veach 1997, eq. 5.17), and the walker updates its weights and plays its roulette rule.
//
// A walker provides
//   void attenuate(const Spectrum& transmittance)       Beer–Lambert along the edge just walked
//   bool vertex(const SurfaceHit&, const Vec3& wo, int length)          false: the path ends here
//   bool scattered(const SurfaceHit&, const LightScatter&, int length, Draws&)   false: it ends
// `length` counts the edges from the light: the first hit has length 1.
#pragma once
#include "bsdfs/lambertian.h"
#include "lights/light.h"
#include "scene/scene.h"

namespace pl {

// Where a light path starts: the light picked (null when the scene emits nothing), the
// probability it was picked with (by power), and its emitted ray.
struct LightEmission {
  const Light* light = nullptr;
  float pick = 0.0f;
  EmittedRay e{Ray{}, Spectrum(0.0f)};
};

// Draws: the light (1D), a point on it (2D), a direction (2D).
template <class Draws>
LightEmission emitLight(const Scene& scene, Draws& draws, const SampledWavelengths& lambda) {
  LightEmission em;
  const AliasTable& lights = scene.lightDistribution();
  if (lights.size() == 0 || lights.total() <= 0) return em;
  em.light = scene.lights()[lights.sample(draws.get1D(), &em.pick)].get();
  const Vec2 uPosition = draws.get2D();
  const Vec2 uDirection = draws.get2D();
  em.e = em.light->sampleLe(uPosition, uDirection, lambda);
  return em;
}

// One scattering at a light-path vertex.
struct LightScatter {
  Vec3 woLocal, wi;  // wo in the shading frame; wi in the world
  BSDFContext bc;
  BSDFSample bs;     // bs.weight: f·|cosθ|/pdf times the shading-normal correction
};

// Which vertices get the leak test and the shading-normal correction: all of them, or only
// those whose shading normal differs from the geometric one (elsewhere the correction is 1 and
// no direction can leak; skipping them is the photon tracer's saving).
enum class ShadingCheck { kEveryVertex, kWhereNormalsDiffer };

// Samples the BSDF at `hit` (draws: a direction, 2D; a lobe, 1D): the adjoint for light paths
// (importance), as is for camera paths (radiance, where the correction is 1). False: no
// direction, or one that would leak through the surface.
template <class Draws>
bool scatterBSDF(const SurfaceHit& hit, const Vec3& wo, Draws& draws, SampledWavelengths& lambda, TransportMode mode,
                 ShadingCheck check, LightScatter* s) {
  s->woLocal = hit.shading.toLocal(wo);
  s->bc = bsdfContext(hit, lambda, mode);
  const Vec2 u = draws.get2D();
  const float uc = draws.get1D();
  // Most hits are diffuse: Lambertian (final) is called without the virtual call.
  const bool sampled = hit.bsdf->bsdfClass() == BSDFClass::kLambertian
                           ? static_cast<const Lambertian*>(hit.bsdf)->sample(s->woLocal, s->bc, u, uc, &s->bs)
                           : hit.bsdf->sample(s->woLocal, s->bc, u, uc, &s->bs);
  if (!sampled) return false;
  if (s->bs.terminatesSecondary) lambda.terminateSecondary();
  s->wi = hit.shading.toWorld(s->bs.wi);
  if (check == ShadingCheck::kEveryVertex || hit.shadingDiffers()) {
    if (leaksLight(hit, wo, s->wi, s->woLocal, s->bs.wi)) return false;
    s->bs.weight *= shadingNormalCorrection(s->woLocal, s->bs.wi, hit.shading.toLocal(hit.ng), mode);
  }
  return true;
}

// The walk from an emitted ray.
template <class Walker, class Draws>
void walkLightPath(const Scene& scene, Ray ray, Draws& draws, SampledWavelengths& lambda, ShadingCheck check, Walker& walker) {
  ray.tmin = scene.epsilon();  // area lights emit from their own triangle
  for (int length = 1;; ++length) {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) return;
    walker.attenuate(scene.transmittance(hit, ray.d, lambda));
    const Vec3 wo = -ray.d;
    if (!walker.vertex(hit, wo, length)) return;
    LightScatter s;
    if (!scatterBSDF(hit, wo, draws, lambda, TransportMode::Importance, check, &s)) return;
    if (!walker.scattered(hit, s, length, draws)) return;
    ray = scene.spawnRay(hit, s.wi);
  }
}

// Independent draws straight from a stream, for the walks that have no Sampler (the photon
// tracer); the same order as Sampler's independent draws (y before x).
struct StreamDraws {
  Rng& rng;
  float get1D() { return rng.uniform(); }
  Vec2 get2D() {
    const float y = rng.uniform();
    return Vec2(rng.uniform(), y);
  }
};

}  // namespace pl
