#include "integrators/progressive.h"

#include "core/exact_sum.h"
#include "core/parallel.h"
#include "render/visible_probe.h"
#include "spectral/spectral.h"


namespace pl {

std::vector<ParamSpec> progressiveParams(bool photonsPerPixel) {
  return {params::passes(), params::photonsPerPass(photonsPerPixel ? "" : "100000"), params::alpha(),
          params::progressiveRadius(), params::maxDepth(), params::photonTarget(),
          params::aimAreaLights(), params::photonSampling()};
}

ProgressiveOptions progressiveOptions(const ParamSet& p) {
  ProgressiveOptions o;
  o.passes = p.isSet("passes") ? int(p.integer("passes")) : INT32_MAX;
  o.photonsPerPass = p.isSet("photons_per_pass") ? uint64_t(p.integer("photons_per_pass")) : 0;
  o.alpha = p.real("alpha");
  o.radius = float(p.real("radius"));
  o.maxDepth = int(p.integer("max_depth"));
  o.targetView = p.choice("photon_target") != "scene";
  o.aimAreaLights = p.choice("aim_area_lights") == "on";
  o.adaptive = p.choice("photon_sampling") == "adaptive";
  return o;
}

std::string resolveProgressiveRadius(const Scene& scene, int width, int height, ParamSet& params) {
  std::string photons;
  if (!params.isSet("photons_per_pass")) {
    const uint64_t n = defaultPhotonsPerPass(width, height);
    params.resolve("photons_per_pass", double(n));
    photons = "; " + std::to_string(n) + " photons per pass (default: the pixel count)";
  }
  if (params.isSet("radius")) return "initial radius " + formatNumber(float(params.real("radius"))) + " m" + photons;
  DefaultRadius r = defaultRadius(scene, width, height);
  params.resolve("radius", r.radius);
  return "initial radius " + formatNumber(r.radius) + " m (default: " + formatNumber(DefaultRadius::kFootprints) +
         " pixel footprints at the median visible distance " + formatNumber(r.distance) + " m)" + photons;
}

namespace {
// The eye path's next segment from `hit`, as both visible-point walks take it (the same draws in
// the same order: a 2D direction, then the lobe): false when the BSDF gives no direction or the
// throughput dies.
bool scatterEyePath(const Scene& scene, const SurfaceHit& hit, const Vec3& woLocal, SampledWavelengths& lambda, Rng& rng,
                    Spectrum* beta, Ray* ray) {
  BSDFSample s;
  if (!hit.bsdf->sample(woLocal, bsdfContext(hit, lambda), Vec2(rng.uniform(), rng.uniform()), rng.uniform(), &s)) return false;
  if (s.terminatesSecondary) lambda.terminateSecondary();
  *beta *= s.weight;
  if (isBlack(*beta) || !isFinite(*beta)) return false;
  *ray = scene.spawnRay(hit, hit.shading.toWorld(s.wi));
  return true;
}
}  // namespace

Spectrum traceVisiblePoint(const Scene& scene, Ray ray, SampledWavelengths& lambda, Rng& rng, int maxDepth, VisiblePoint* vp) {
  vp->valid = false;
  Spectrum L(0.0f), beta(1.0f);
  for (int depth = 0; depth <= maxDepth; ++depth) {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) {  // the camera ray or a specular chain: the sky in full
      L += beta * escapedRadiance(scene, ray.d, lambda, true, 0.0f);
      break;
    }
    beta *= scene.transmittance(hit, ray.d, lambda);
    Vec3 wo = -ray.d;
    if (hit.light) L += beta * hit.light->L(hit.uv, wo, lambda);
    if (!hit.bsdf->isSpecular()) {
      vp->hit = hit;
      vp->wo = wo;
      vp->beta = beta;
      vp->valid = true;
      break;
    }
    if (!scatterEyePath(scene, hit, hit.shading.toLocal(wo), lambda, rng, &beta, &ray)) break;
  }
  // The progressive film has no per-sample discard: nothing non-finite may enter it.
  if (!isFinite(L)) L = Spectrum(0.0f);
  return L;
}

bool narrowLobe(const SurfaceHit& hit, const Vec3& woLocal, const SampledWavelengths& lambda) {
  if (!hasGlossy(hit.bsdf->flags()) || !(woLocal.z > 0)) return false;
  const Vec3 mirror(-woLocal.x, -woLocal.y, woLocal.z);
  return hit.bsdf->pdf(woLocal, mirror, bsdfContext(hit, lambda)) * kGatherLobe > 1.0f;
}

Spectrum traceGatherPoints(const Scene& scene, Ray ray, SampledWavelengths& lambda, Rng& rng, int maxDepth, VisiblePoint* vp,
                           VisiblePoint* caustic) {
  vp->valid = caustic->valid = false;
  Sampler sampler(rng);
  Spectrum L(0.0f), beta(1.0f);
  bool onlySpecular = true;  // no non-specular vertex yet: emission seen counts in full
  for (int depth = 0; depth <= maxDepth; ++depth) {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) {
      if (onlySpecular) L += beta * escapedRadiance(scene, ray.d, lambda, true, 0.0f);
      break;
    }
    beta *= scene.transmittance(hit, ray.d, lambda);
    const Vec3 wo = -ray.d;
    if (hit.light && onlySpecular) L += beta * hit.light->L(hit.uv, wo, lambda);
    const Vec3 woLocal = hit.shading.toLocal(wo);
    if (!hit.bsdf->isSpecular()) {
      const Spectrum direct = beta * estimateDirectMIS(scene, hit, woLocal, lambda, sampler);
      if (isFinite(direct)) L += direct;  // a non-finite sample is dropped, never accumulated
      // One continuation at most: the pixel has statistics for one caustic point.
      VisiblePoint* here = caustic->valid || depth == maxDepth || !narrowLobe(hit, woLocal, lambda) ? vp : caustic;
      here->hit = hit;
      here->wo = wo;
      here->beta = beta;
      here->valid = true;
      if (here == vp) break;
      onlySpecular = false;
    }
    if (!scatterEyePath(scene, hit, woLocal, lambda, rng, &beta, &ray)) break;
  }
  // The progressive film has no per-sample discard: nothing non-finite may enter it.
  if (!isFinite(L)) L = Spectrum(0.0f);
  return L;
}

void gatherPhotons(const VisiblePoint& vp, const PhotonMap& map, uint8_t accept, double photonsPerPass, double alpha,
                   ProgressiveStats* stats, PhotonMarks* marks) {
  if (!vp.valid) return;
  thread_local std::vector<Neighbour> found;
  float R = float(std::sqrt(stats->R2));
  Vec3 n = glm::dot(vp.hit.ng, vp.wo) >= 0 ? vp.hit.ng : -vp.hit.ng;
  // Photons from the other side count where the BSDF transmits: through a thin translucent wall.
  map.withinRadius(vp.hit.p, n, accept, R, &found, 0.25f * R, hasSmoothTransmission(vp.hit.bsdf->flags()));
  Vec3 wo = vp.hit.shading.toLocal(vp.wo);
  const bool shadingDiffers = vp.hit.shadingDiffers();
  const Vec3 ngLocal = vp.hit.shading.toLocal(vp.hit.ng);
  glm::dvec3 phi(0.0);
  if (marks)
    for (const Neighbour& nb : found) marks->mark(nb.index);
  for (const Neighbour& nb : found) {
    const Photon& ph = map.photons()[nb.index];
    const Vec3 wi = vp.hit.shading.toLocal(ph.wi());
    Spectrum f = vp.hit.bsdf->eval(wo, wi, bsdfContext(vp.hit));
    if (shadingDiffers) f *= sidesAgree(vp.hit, vp.wo, ph.wi(), wo, wi) ? densityShadingCorrection(wi, ngLocal) : 0.0f;
    phi += glm::dvec3(vp.beta * f * map.flux(ph)) * photonsPerPass;  // stored flux is Φ/(pmf·M)
  }
  // The statistics persist over all passes: one non-finite BSDF value would poison the pixel
  // for good, so such a pass's photons are dropped at this point (the radius does not shrink).
  if (!std::isfinite(phi.x) || !std::isfinite(phi.y) || !std::isfinite(phi.z)) return;
  stats->update(double(found.size()), phi, alpha);
}

double meanRadius(const std::vector<ProgressiveStats>& stats) {
  double sum = 0;
  for (auto& s : stats) sum += std::sqrt(s.R2);
  return stats.empty() ? 0.0 : sum / stats.size();
}

namespace {
// A pixel's memory in the largest of the three: two gather points each, and sppm's statistics
// and sums or pppm's eye-pass results and exact sums (core/exact_sum.h), whichever is larger.
constexpr size_t kPassPixelBytes =
    2 * sizeof(VisiblePoint) + sizeof(uint32_t) +
    std::max(2 * sizeof(ProgressiveStats) + 6 * sizeof(double) + 3 * sizeof(float),
             3 * sizeof(ExactSum) + sizeof(Spectrum) + sizeof(SampledWavelengths));
}  // namespace

PassSetup::PassSetup(const Scene& scene, const RenderOptions& io, const ProgressiveOptions& o)
    : RenderSession(scene, io, kPassPixelBytes, "progressive image") {
  initialRadius = o.radius > 0 ? o.radius : defaultRadius(scene, width, height).radius;
  photonsPerPass = o.photonsPerPass > 0 ? o.photonsPerPass : defaultPhotonsPerPass(width, height);
  if (o.targetView) target = visibleEmissionTarget(scene, width, height, initialRadius);
  target.areaLights = o.aimAreaLights;
  progressNote = [this] {
    const double f = visibleFraction();
    return f >= 0 ? "  photons near the view " + percentText(f) : std::string();
  };
  passes.assign(pixels, 0);
}

void finishSpectralVisiblePoint(const SampledWavelengths& ctx, VisiblePoint* vp, Spectrum* L) {
  if (!ctx.spectral) return;
  *L = spectralToRGB(*L, ctx.lambda);
  finishSpectralVisiblePoint(ctx, vp);
}

void finishSpectralVisiblePoint(const SampledWavelengths& ctx, VisiblePoint* vp) {
  if (!ctx.spectral) return;
  // A flat β (no coloured or dispersive surface on the way: the common case) is grey exactly;
  // otherwise the colour of white light through the chain is estimated at the path's wavelengths.
  const Spectrum& b = vp->beta;
  if (vp->valid && (ctx.heroOnly || b.x != b.y || b.y != b.z))
    vp->beta = spectralToRGB(b * spectralEmission(Spectrum(1.0f), ctx), ctx.lambda);
}

PhotonMaps tracePassPhotons(const Scene& scene, uint64_t seed, int pass, uint64_t photons, int threads, int maxDepth,
                            bool spectral, const Budget* budget, const EmissionTarget& target, uint8_t store,
                            const PhotonVisibility* adaptive, float mutationSize) {
  PhotonTracingOptions o;
  o.globalPaths = photons;
  o.causticPaths = 0;
  o.seed = mix64(seed * 0x9e3779b97f4a7c15ULL + uint64_t(pass));
  o.threads = threads;
  o.maxDepth = maxDepth;
  o.spectral = spectral;
  o.budget = budget;
  o.target = target;
  o.store = store;
  o.adaptive = adaptive;
  o.mutationSize = mutationSize;
  return tracePhotons(scene, o);
}

}  // namespace pl
