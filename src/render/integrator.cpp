#include "render/integrator.h"

namespace pl {

Spectrum estimateDirect(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, const SampledWavelengths& lambda,
                        Sampler& sampler, bool mis) {
  const AliasTable& dist = scene.lightDistribution();
  if (dist.size() == 0 || dist.total() <= 0) return Spectrum(0.0f);
  float pmf;
  size_t index = dist.sample(sampler.get1D(), &pmf);
  const Light& light = *scene.lights()[index];
  Vec2 u = sampler.get2D();
  LightSample ls;
  if (!light.sampleLi(hit.p, u, lambda, &ls)) return Spectrum(0.0f);
  Vec3 wi = hit.shading.toLocal(ls.wi);
  const BSDFContext bc = bsdfContext(hit, lambda);
  const BSDFEval e = hit.bsdf->evaluate(woLocal, wi, bc, false);
  const Spectrum& f = e.f;
  if (isBlack(f)) return Spectrum(0.0f);
  // A light below the geometric surface reaches it only through a BSDF that transmits, and then
  // only if the shading normal agrees.
  if (!sidesAgree(hit, hit.shading.toWorld(woLocal), ls.wi, woLocal, wi)) return Spectrum(0.0f);
  if (!scene.visible(hit, ls.wi, ls.distance)) return Spectrum(0.0f);
  float lightPdf = pmf * ls.pdf;
  float weight = 1.0f;
  if (mis && !light.isDelta()) weight = powerHeuristic(lightPdf, e.pdf);
  return f * ls.Li * (std::abs(wi.z) * weight / lightPdf);
}

Spectrum estimateDirectMIS(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, SampledWavelengths& lambda,
                           Sampler& sampler) {
  Spectrum L = estimateDirect(scene, hit, woLocal, lambda, sampler, true);
  BSDFSample bs;
  const Vec2 u = sampler.get2D();
  if (!hit.bsdf->sample(woLocal, bsdfContext(hit, lambda), u, sampler.get1D(), &bs)) return L;
  if (bs.terminatesSecondary) lambda.terminateSecondary();
  const Vec3 wi = hit.shading.toWorld(bs.wi);
  if (leaksLight(hit, hit.shading.toWorld(woLocal), wi, woLocal, bs.wi)) return L;
  SurfaceHit next;
  if (!scene.intersect(scene.spawnRay(hit, wi), &next))
    return L + bs.weight * escapedRadiance(scene, wi, lambda, bs.delta, bs.pdf);
  if (!next.light) return L;
  const Spectrum Le = next.light->L(next.uv, -wi, lambda);
  if (isBlack(Le)) return L;
  // A delta lobe (a smooth coat over a rough base) is found only by sampling: weight 1.
  const float lightPdf = scene.lightDistribution().pmf(size_t(next.lightIndex)) * next.light->pdfLi(hit.p, next.p);
  const float weight = bs.delta ? 1.0f : powerHeuristic(bs.pdf, lightPdf);
  return L + bs.weight * scene.transmittance(next, wi, lambda) * Le * weight;
}

}  // namespace pl
