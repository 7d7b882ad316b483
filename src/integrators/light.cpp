#include "integrators/light.h"

#include "core/roulette.h"
#include "integrators/builtins.h"

namespace pl {

void LightTracer::connectToCamera(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, const Spectrum& beta,
                                  LightPathContext& path) const {
  CameraSample cs;
  if (!scene.camera().sampleWi(hit.p, path.width, path.height, scene.cameraTanHalf(), &cs)) return;
  // Reflected towards the camera, or transmitted through a BSDF that transmits, by the geometric
  // normal as well as the shading one: the shadow rays' rule.
  Vec3 woLocal = hit.shading.toLocal(wo), wiLocal = hit.shading.toLocal(cs.wi);
  if (!sidesAgree(hit, wo, cs.wi, woLocal, wiLocal)) return;
  const BSDFContext bc = bsdfContext(hit, path.lambda, TransportMode::Importance);
  Spectrum f = hit.bsdf->eval(woLocal, wiLocal, bc) *
               shadingNormalCorrection(woLocal, wiLocal, hit.shading.toLocal(hit.ng), TransportMode::Importance);
  if (isBlack(f)) return;
  if (!scene.visible(hit, cs.wi, cs.distance)) return;
  path.splat(cs.raster, beta * f * (std::abs(wiLocal.z) * cs.We / cs.pdf));
}

void LightTracer::traceLightPath(const Scene& scene, LightPathContext& path) const {
  Rng& rng = path.rng;
  const AliasTable& lights = scene.lightDistribution();
  if (lights.size() == 0 || lights.total() <= 0) return;
  float pmf;
  const Light& light = *scene.lights()[lights.sample(rng.uniform(), &pmf)];
  Vec2 uPosition(rng.uniform(), rng.uniform()), uDirection(rng.uniform(), rng.uniform());
  EmittedRay e = light.sampleLe(uPosition, uDirection, path.lambda);
  Spectrum beta = e.flux / pmf;  // Le |cosθ| / (pmf pdfPos pdfDir): an estimate of the total power
  if (isBlack(beta) || !isFinite(beta)) return;

  // The emission point itself, seen by the camera: C = Le |cosθy| We / (pmf pdfPos pdf_cam).
  // The environment's emission point is a point of its bounding disc, not of the sky: no light
  // path shows the camera the sky itself (the path tracer's camera rays do).
  if (!light.isDelta() && !light.isInfinite()) {
    CameraSample cs;
    if (scene.camera().sampleWi(e.ray.o, path.width, path.height, scene.cameraTanHalf(), &cs)) {
      SurfaceHit y;
      y.p = e.ray.o;
      y.ng = e.n;
      Spectrum Le = light.L(e.ray.o, cs.wi, path.lambda);
      if (!isBlack(Le) && scene.visible(y, cs.wi, cs.distance))
        path.splat(cs.raster, Le * (std::abs(glm::dot(e.n, cs.wi)) * cs.We / (pmf * e.pdfPos * cs.pdf)));
    }
  }

  Ray ray = e.ray;
  ray.tmin = scene.epsilon();  // area lights emit from their own triangle
  Spectrum throughput(1.0f);   // ∏ f cos / pdf, for Russian roulette (beta carries watts)
  for (int depth = 1; depth <= maxDepth_; ++depth) {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) return;
    const Spectrum transmittance = scene.transmittance(hit, ray.d, path.lambda);
    beta *= transmittance;
    throughput *= transmittance;
    const Vec3 wo = -ray.d;
    if (!hit.bsdf->isSpecular()) connectToCamera(scene, hit, wo, beta, path);
    if (depth == maxDepth_) return;

    BSDFSample bs;
    Vec3 woLocal = hit.shading.toLocal(wo);
    Vec2 u(rng.uniform(), rng.uniform());
    if (!hit.bsdf->sample(woLocal, bsdfContext(hit, path.lambda, TransportMode::Importance), u, rng.uniform(), &bs))
      return;
    if (bs.terminatesSecondary) path.lambda.terminateSecondary();
    Vec3 wi = hit.shading.toWorld(bs.wi);
    if (leaksLight(hit, wo, wi, woLocal, bs.wi)) return;
    Spectrum weight = bs.weight * shadingNormalCorrection(woLocal, bs.wi, hit.shading.toLocal(hit.ng), TransportMode::Importance);
    beta *= weight;
    throughput *= weight;
    // Russian roulette by throughput (core/roulette.h), on ∏ f cos / pdf (beta carries watts).
    if (depth >= roulette::kFirstDepth) {
      const float q = roulette::throughput(maxComponent(throughput));
      if (!roulette::survives(q, [&] { return rng.uniform(); })) return;
      beta /= q;
      throughput /= q;
    }
    if (!isFinite(beta)) return;
    ray = scene.spawnRay(hit, wi);
  }
}

namespace {
// spp as the light-side loop counts it: iterations of W·H light paths.
ParamSpec lightPathsPerPixel() {
  ParamSpec s = params::spp();
  s.doc = "light paths per pixel: each iteration traces W·H paths (the path tracer's work at the same spp)";
  return s;
}
}  // namespace

IntegratorEntry lightEntry() {
  return IntegratorEntry(
      "light", "light tracing: paths from the lights, every diffuse or glossy vertex splatted to the camera",
      IntegratorFamily::LightPaths, "spp",
      {lightPathsPerPixel(), params::maxDepth()},
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<LightTracer>(int(p.integer("max_depth"))); });
}

}  // namespace pl
