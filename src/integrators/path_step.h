// The camera path's vertex step, written once: at each vertex, emission found by sampling
// (weighted by MIS against next-event estimation from the vertex before), next-event
// estimation, a scattered direction, the throughput update and Russian roulette (Veach 1997,
// §9.2; pbrt-v4's PathIntegrator::Li). What differs between integrators is how the direction is
// drawn and which roulette rule plays; both come from a strategy:
//   - BSDFSampling (below): the BSDF alone and the throughput rule; `path`.
//   - guided.cpp's GuidedSampling: a mixture of the BSDF and a learned guide, the expected
//     contribution rule, and records for the guide's training; `guided`.
// The SIMD lanes (path_lanes_kernel.h) accelerate the first; tests/test_path_lanes.cpp proves
// them pixel for pixel against this step.
//
// A strategy provides
//   void attenuate(const Spectrum& transmittance)        Beer–Lambert along the edge just walked
//   void arrive(const SurfaceHit&, const Ray&)           at a vertex, before next-event estimation
//   bool scatter(const SurfaceHit&, const Vec3& wo, SampledWavelengths&, Sampler&, ScatterSample*)
//                                                        the next direction; false: the path ends
//   void scattered(const PathState&, const SurfaceHit&, const ScatterSample&)   after the update
//   bool survives(PathState&, Sampler&)                  Russian roulette (divides β by q)
#pragma once
#include "core/roulette.h"
#include "core/sampler.h"
#include "render/integrator.h"
#include "scene/scene.h"

namespace pl {

// The path so far.
struct PathState {
  Spectrum L{0.0f};       // radiance gathered
  Spectrum beta{1.0f};    // throughput ∏ f·cos/pdf (over roulette's q)
  float etaScale = 1.0f;  // ∏ η² over refractions (the throughput rule divides it out)
  bool specularBounce = true;  // the camera ray counts as specular: emitters get full weight
  float misPdf = 0.0f;         // BSDF sampling's density for the last direction (MIS)
  Vec3 previousPoint{0.0f};
  int depth = 0;
};

// One scattered direction, as a strategy drew it.
struct ScatterSample {
  Vec3 wiLocal, wiWorld;
  Spectrum weight;     // f·|cosθ|/pdf, pdf the density it was drawn with: the throughput's factor
  float pdf = 0.0f;    // that density
  float misPdf = 0.0f; // BSDF sampling's density for the direction (MIS against the lights)
  float eta = 1.0f;
  bool delta = false;
};

// The path tracer's strategy: directions from the BSDF, roulette by throughput.
struct BSDFSampling {
  void attenuate(const Spectrum&) {}
  void arrive(const SurfaceHit&, const Ray&) {}
  bool scatter(const SurfaceHit& hit, const Vec3& wo, SampledWavelengths& lambda, Sampler& sampler, ScatterSample* s) {
    BSDFSample bs;
    Vec2 u = sampler.get2D();
    if (!hit.bsdf->sample(wo, bsdfContext(hit, lambda), u, sampler.get1D(), &bs)) return false;
    if (bs.terminatesSecondary) lambda.terminateSecondary();
    *s = {bs.wi, hit.shading.toWorld(bs.wi), bs.weight, bs.pdf, bs.pdf, bs.eta, bs.delta};
    return true;
  }
  void scattered(const PathState&, const SurfaceHit&, const ScatterSample&) {}
  bool survives(PathState& p, Sampler& sampler) {
    if (p.depth < roulette::kFirstDepth) return true;
    const float q = roulette::throughput(maxComponent(p.beta), p.etaScale);
    if (!roulette::survives(q, [&] { return sampler.get1D(); })) return false;
    p.beta /= q;
    return true;
  }
};

// The camera path from its ray's first hit (null: the ray left the scene), up to maxDepth
// bounces; returns the radiance it carries (the estimate of L along the camera ray).
template <class Strategy>
Spectrum tracePath(const Scene& scene, const Ray& cameraRay, const SurfaceHit* firstHit, SampledWavelengths& lambda,
                   Sampler& sampler, int maxDepth, Strategy& strategy) {
  PathState p;
  Ray ray = cameraRay;
  p.previousPoint = ray.o;
  SurfaceHit next;
  const SurfaceHit* found = firstHit;
  for (;; ++p.depth) {
    if (!found) {
      p.L += p.beta * escapedRadiance(scene, ray.d, lambda, p.specularBounce, p.misPdf);
      break;
    }
    const SurfaceHit& hit = *found;
    const Spectrum transmittance = scene.transmittance(hit, ray.d, lambda);
    p.beta *= transmittance;
    strategy.attenuate(transmittance);

    // Emission found by sampling; next-event estimation counted the same light from the vertex
    // before, so both are weighted by the power heuristic.
    if (hit.light) {
      Spectrum Le = hit.light->L(hit.uv, -ray.d, lambda);
      if (p.specularBounce) {
        p.L += p.beta * Le;
      } else if (!isBlack(Le)) {
        float lightPdf = scene.lightDistribution().pmf(size_t(hit.lightIndex)) * hit.light->pdfLi(p.previousPoint, hit.p);
        p.L += p.beta * Le * powerHeuristic(p.misPdf, lightPdf);
      }
    }
    if (p.depth >= maxDepth) break;

    const Vec3 wo = hit.shading.toLocal(-ray.d);
    strategy.arrive(hit, ray);
    if (!hit.bsdf->isSpecular()) p.L += p.beta * estimateDirect(scene, hit, wo, lambda, sampler, true);

    ScatterSample s;
    if (!strategy.scatter(hit, wo, lambda, sampler, &s)) break;
    // A direction that crosses the geometric surface against the shading normal's side carries
    // nothing (scene.h).
    if (leaksLight(hit, -ray.d, s.wiWorld, wo, s.wiLocal)) break;
    p.beta *= s.weight;
    p.etaScale *= s.eta * s.eta;
    p.specularBounce = s.delta;
    p.misPdf = s.misPdf;
    p.previousPoint = hit.p;
    strategy.scattered(p, hit, s);
    ray = scene.spawnRay(hit, s.wiWorld);
    if (!strategy.survives(p, sampler)) break;
    found = scene.intersect(ray, &next) ? &next : nullptr;
  }
  return p.L;
}

}  // namespace pl
