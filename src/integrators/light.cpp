#include "integrators/light.h"

#include "core/roulette.h"
#include "integrators/builtins.h"
#include "transport/light_walk.h"

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
  StreamDraws draws{path.rng};
  const LightEmission emitted = emitLight(scene, draws, path.lambda);
  if (!emitted.light) return;
  const Light& light = *emitted.light;
  const EmittedRay& e = emitted.e;
  const float pmf = emitted.pick;
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

  // The walk (transport/light_walk.h): every non-specular vertex connected to the camera.
  struct Walker {
    const LightTracer& tracer;
    const Scene& scene;
    LightPathContext& path;
    Spectrum beta;
    Spectrum throughput{1.0f};  // ∏ f cos / pdf, for Russian roulette (beta carries watts)
    void attenuate(const Spectrum& transmittance) {
      beta *= transmittance;
      throughput *= transmittance;
    }
    bool vertex(const SurfaceHit& hit, const Vec3& wo, int length) {
      if (!hit.bsdf->isSpecular()) tracer.connectToCamera(scene, hit, wo, beta, path);
      return length < tracer.maxDepth_;
    }
    bool scattered(const SurfaceHit&, const LightScatter& s, int length, StreamDraws& draws) {
      beta *= s.bs.weight;
      throughput *= s.bs.weight;
      // Russian roulette by throughput (core/roulette.h), on ∏ f cos / pdf.
      if (length >= roulette::kFirstDepth) {
        const float q = roulette::throughput(maxComponent(throughput));
        if (!roulette::survives(q, [&] { return draws.get1D(); })) return false;
        beta /= q;
        throughput /= q;
      }
      return isFinite(beta);
    }
  } walker{*this, scene, path, beta};
  if (maxDepth_ < 1) return;
  walkLightPath(scene, e.ray, draws, path.lambda, ShadingCheck::kEveryVertex, walker);
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
