#include "integrators/path.h"

#include "core/roulette.h"
#include "integrators/builtins.h"

namespace pl {

Spectrum PathIntegrator::Li(const Ray& cameraRay, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const {
  SurfaceHit hit;
  const bool found = scene.intersect(cameraRay, &hit);
  return Li(cameraRay, found ? &hit : nullptr, scene, lambda, sampler);
}

// The lanes, where the scene and the options allow them.
void PathIntegrator::preprocess(const Scene& scene, uint64_t, int, const Budget&) {
  lanes_.reset();
  lanesUnused_ = lanesWanted_ ? PathLanes::unsupported(scene) : "lanes off, or spectral, or Sobol' samples";
  if (lanesUnused_.empty()) lanes_ = std::make_unique<PathLanes>(scene);
}

// In lanes: the whole batch (packetSize). Otherwise: a row's neighbouring camera rays start
// together and run nearly parallel: Embree traces them as one coherent packet, which costs less
// per ray than one at a time. The paths then go on one by one; the packet's hits are the one-ray
// query's bit for bit, so the image is the same.
void PathIntegrator::LiPacket(CameraSample* samples, int n, const Scene& scene) const {
  if (lanes_) return lanes_->trace(samples, n, maxDepth_);
  Ray rays[Scene::kPacket];
  bool active[Scene::kPacket] = {}, found[Scene::kPacket];
  SurfaceHit hits[Scene::kPacket];
  for (int k = 0; k < n; ++k) rays[k] = samples[k].ray, active[k] = true;
  scene.intersect(rays, active, true, hits, found);
  for (int k = 0; k < n; ++k)
    samples[k].L = Li(rays[k], found[k] ? &hits[k] : nullptr, scene, *samples[k].lambda, *samples[k].sampler);
}

Spectrum PathIntegrator::Li(const Ray& cameraRay, const SurfaceHit* firstHit, const Scene& scene, SampledWavelengths& lambda,
                            Sampler& sampler) const {
  Spectrum L(0.0f), beta(1.0f);  // beta: path throughput ∏ f·cos/pdf
  float etaScale = 1.0f;          // ∏ η² over refractions (Russian roulette divides it out)
  Ray ray = cameraRay;
  bool specularBounce = true;  // the camera ray counts as "specular": emitters get full weight
  float bsdfPdf = 0.0f;
  Vec3 previousPoint = ray.o;
  SurfaceHit next;
  const SurfaceHit* found = firstHit;  // where the ray met the scene (null: it left)
  for (int depth = 0;; ++depth) {
    if (!found) {
      L += beta * escapedRadiance(scene, ray.d, lambda, specularBounce, bsdfPdf);
      break;
    }
    const SurfaceHit& hit = *found;
    beta *= scene.transmittance(hit, ray.d, lambda);

    // Emission found by BSDF sampling; next-event estimation already counted the same light
    // from the previous vertex, so weight both by MIS.
    if (hit.light) {
      Spectrum Le = hit.light->L(hit.uv, -ray.d, lambda);
      if (specularBounce) {
        L += beta * Le;
      } else if (!isBlack(Le)) {
        float lightPdf = scene.lightDistribution().pmf(size_t(hit.lightIndex)) * hit.light->pdfLi(previousPoint, hit.p);
        L += beta * Le * powerHeuristic(bsdfPdf, lightPdf);
      }
    }
    if (depth >= maxDepth_) break;

    Vec3 wo = hit.shading.toLocal(-ray.d);
    if (!hit.bsdf->isSpecular()) L += beta * estimateDirect(scene, hit, wo, lambda, sampler, true);

    BSDFSample bs;
    Vec2 u = sampler.get2D();
    if (!hit.bsdf->sample(wo, bsdfContext(hit, lambda), u, sampler.get1D(), &bs)) break;
    if (bs.terminatesSecondary) lambda.terminateSecondary();
    Vec3 wi = hit.shading.toWorld(bs.wi);
    if (leaksLight(hit, -ray.d, wi, wo, bs.wi)) break;
    beta *= bs.weight;
    etaScale *= bs.eta * bs.eta;
    specularBounce = bs.delta;
    bsdfPdf = bs.pdf;
    previousPoint = hit.p;
    ray = scene.spawnRay(hit, wi);

    // Russian roulette by throughput (core/roulette.h).
    if (depth >= roulette::kFirstDepth) {
      const float q = roulette::throughput(maxComponent(beta), etaScale);
      if (!roulette::survives(q, [&] { return sampler.get1D(); })) break;
      beta /= q;
    }
    found = scene.intersect(ray, &next) ? &next : nullptr;
  }
  return L;
}

IntegratorEntry pathEntry() {
  return IntegratorEntry(
      "path", "unidirectional path tracing with next-event estimation and MIS: the ground truth",
      IntegratorFamily::Pixel, "spp",
      {params::spp(), params::maxDepth(), params::sampler(PathIntegrator::kSobolSlots, "camera path", "the pixel's samples"),
       params::choice("lanes", "run paths 16 at a time in SIMD lanes where the CPU and the scene allow (AVX-512; RGB, independent "
                      "samples; Lambertian, mirror and glass surfaces, area lights): the same estimator and random numbers, faster. "
                      "Debugging switch: the environment variable PHOTONLAB_LANES_ISA=avx512|baseline picks the kernel's copy",
                      "on", {"on", "off"})},
      [](const ParamSet& p, const RenderOptions& o) {
        return std::make_unique<PathIntegrator>(int(p.integer("max_depth")), p.choice("sampler") == "sobol",
                                                p.choice("lanes") == "on", o.spectral);
      });
}

}  // namespace pl
