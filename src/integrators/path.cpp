#include "integrators/path.h"

#include "integrators/builtins.h"
#include "integrators/path_step.h"

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

// The shared vertex step (path_step.h) with BSDF sampling and the throughput roulette.
Spectrum PathIntegrator::Li(const Ray& cameraRay, const SurfaceHit* firstHit, const Scene& scene, SampledWavelengths& lambda,
                            Sampler& sampler) const {
  BSDFSampling strategy;
  return tracePath(scene, cameraRay, firstHit, lambda, sampler, maxDepth_, strategy);
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
