#include "integrators/photon.h"

#include "integrators/builtins.h"
#include "render/visible_probe.h"

namespace pl {

void PhotonIntegrator::preprocess(const Scene& scene, uint64_t seed, int threads, const Budget& budget) {
  // Bound every gather: without a maximum radius a query where no photon can arrive (e.g. the
  // gap between a light and the ceiling, seen from the gap) grows until it collects photons of
  // other surfaces, which is both wrong and slow. Default: 5% of the scene's bounding radius.
  o_.density = resolveDensity(scene, o_.density);
  PhotonTracingOptions t;
  t.globalPaths = o_.photons;
  t.causticPaths = o_.causticPhotons;
  t.seed = seed;
  t.threads = threads;
  t.maxDepth = o_.maxDepth;
  t.spectral = o_.spectral;
  t.budget = &budget;
  if (o_.targetView && o_.width > 0 && o_.height > 0)
    t.target = visibleEmissionTarget(scene, o_.width, o_.height, o_.density.radius > 0 ? o_.density.radius : o_.density.maxRadius);
  t.target.areaLights = o_.aimAreaLights;
  maps_ = tracePhotons(scene, t);
  if (!maps_.complete) {
    // The render loop sees the same expired budget and takes no sample.
    warnings_.push_back(std::string(budget.timeUp() ? "the time budget ran out" : "interrupted") +
                        " while the photon maps were traced or built (" + formatNumber(budget.elapsed()) +
                        " s): no sample was rendered; fewer --photons/--caustic-photons fit in the budget");
    return;
  }
  if (average(scene.totalPower()) <= 0) warnings_.push_back("the lights emit no power: no photons were traced");
  else if (maps_.global.size() == 0 && o_.photons > 0)
    warnings_.push_back("no photon was stored (no diffuse or glossy surface is lit): indirect light is black");
}

DensityEstimation PhotonIntegrator::resolveDensity(const Scene& scene, DensityEstimation de) {
  if (de.radius <= 0 && de.maxRadius <= 0) de.maxRadius = 0.05f * scene.bounds().radius();
  de.planeTolerance = 0.25f * (de.radius > 0 ? de.radius : de.maxRadius);
  return de;
}

void PhotonIntegrator::addInfo(const Scene& scene, const RenderOptions& options, RenderInfo* info) const {
  info->photons = o_.photons + o_.causticPhotons;
  if (gatherRadius_ < 0) gatherRadius_ = meanGatherRadius(scene, options.width, options.height);
  info->meanRadius = gatherRadius_;
}

double PhotonIntegrator::meanGatherRadius(const Scene& scene, int width, int height) const {
  if (o_.density.radius > 0) return o_.density.radius;
  if (maps_.global.size() == 0) return 0.0;
  double sum = 0;
  size_t n = 0;
  for (const ProbePoint& p : probeVisiblePoints(scene, width, height)) {
    GatherStats stats;
    maps_.global.radiance(p.hit, p.wo, o_.density, Photon::kAcceptAll, &stats);
    sum += stats.radius;
    ++n;
  }
  return n ? sum / n : 0.0;
}

// Caustics (L S+ D) at x: from the caustic map, or, without one, from the global map's photons
// flagged as caustic.
Spectrum PhotonIntegrator::causticRadiance(const SurfaceHit& hit, const Vec3& wo, const SampledWavelengths& lambda) const {
  if (o_.causticPhotons > 0) return maps_.caustic.radiance(hit, wo, lambda, o_.density, Photon::kAcceptAll);
  return maps_.global.radiance(hit, wo, lambda, o_.density, Photon::kAcceptCaustic);
}

Spectrum PhotonIntegrator::finalGather(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, SampledWavelengths& lambda,
                                       Sampler& sampler) const {
  Spectrum sum(0.0f);
  Vec3 woLocal = hit.shading.toLocal(wo);
  for (int i = 0; i < o_.finalGather; ++i) {
    BSDFSample bs;
    if (!hit.bsdf->sample(woLocal, bsdfContext(hit, lambda), sampler.get2D(), sampler.get1D(), &bs))
      continue;
    if (bs.terminatesSecondary) lambda.terminateSecondary();
    Spectrum beta = bs.weight;
    Ray ray = scene.spawnRay(hit, hit.shading.toWorld(bs.wi));
    // Follow specular surfaces to the first diffuse or glossy one, and read the whole global
    // map there. Emission found on the way is not added: it is direct light (estimateDirectMIS) or a
    // caustic (caustic map) at x.
    for (int depth = 0; depth < o_.maxDepth; ++depth) {
      SurfaceHit y;
      if (!scene.intersect(ray, &y)) break;
      beta *= scene.transmittance(y, ray.d, lambda);
      if (!y.bsdf->isSpecular()) {
        sum += beta * maps_.global.radiance(y, -ray.d, lambda, o_.density, Photon::kAcceptAll);
        break;
      }
      BSDFSample s;
      if (!y.bsdf->sample(y.shading.toLocal(-ray.d), bsdfContext(y, lambda), sampler.get2D(),
                          sampler.get1D(), &s))
        break;
      if (s.terminatesSecondary) lambda.terminateSecondary();
      beta *= s.weight;
      ray = scene.spawnRay(y, y.shading.toWorld(s.wi));
    }
  }
  return sum / float(o_.finalGather);
}

Spectrum PhotonIntegrator::Li(const Ray& cameraRay, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const {
  Spectrum L(0.0f), beta(1.0f);
  Ray ray = cameraRay;
  for (int depth = 0; depth <= o_.maxDepth; ++depth) {
    SurfaceHit hit;
    // Only the camera ray or a chain of specular bounces gets here: emission, and the sky,
    // count in full.
    if (!scene.intersect(ray, &hit)) {
      if (o_.aov.empty()) L += beta * escapedRadiance(scene, ray.d, lambda, true, 0.0f);
      break;
    }
    beta *= scene.transmittance(hit, ray.d, lambda);
    Vec3 wo = -ray.d;
    if (hit.light && o_.aov.empty()) L += beta * hit.light->L(hit.uv, wo, lambda);
    Vec3 woLocal = hit.shading.toLocal(wo);
    if (hit.bsdf->isSpecular()) {
      BSDFSample s;
      if (!hit.bsdf->sample(woLocal, bsdfContext(hit, lambda), sampler.get2D(), sampler.get1D(), &s))
        break;
      if (s.terminatesSecondary) lambda.terminateSecondary();
      beta *= s.weight;
      ray = scene.spawnRay(hit, hit.shading.toWorld(s.wi));
      continue;
    }
    if (!o_.aov.empty()) {  // debug images: what the global map's estimate used here
      GatherStats stats;
      maps_.global.radiance(hit, wo, o_.density, Photon::kAcceptIndirect, &stats);
      return Spectrum(o_.aov == "photons" ? float(stats.photons) : stats.radius);
    }
    L += beta * estimateDirectMIS(scene, hit, woLocal, lambda, sampler);
    L += beta * causticRadiance(hit, wo, lambda);
    if (o_.finalGather > 0)
      L += beta * finalGather(scene, hit, wo, lambda, sampler);
    else
      L += beta * maps_.global.radiance(hit, wo, lambda, o_.density, Photon::kAcceptIndirect);
    break;
  }
  return L;
}

namespace {

PhotonOptions photonOptions(const ParamSet& p, const RenderOptions& image) {
  PhotonOptions o;
  o.maxDepth = int(p.integer("max_depth"));
  o.photons = uint64_t(p.integer("photons"));
  o.causticPhotons = uint64_t(p.integer("caustic_photons"));
  o.density.k = int(p.integer("k"));
  o.density.radius = float(p.real("radius"));
  o.density.maxRadius = float(p.real("max_radius"));
  o.density.kernel = parseKernel(p.choice("kernel"));
  o.finalGather = int(p.integer("final_gather"));
  o.aov = p.choice("aov") == "radiance" ? "" : p.choice("aov");
  o.spectral = image.spectral;
  o.targetView = p.choice("photon_target") != "scene";
  o.aimAreaLights = p.choice("aim_area_lights") == "on";
  o.width = image.width, o.height = image.height;
  return o;
}

std::vector<ParamSpec> photonParams() {
  const double maxPaths = 4294967295.0;  // photon indices are 32-bit in the kd-tree
  ParamSpec photons{"photons", ParamType::Integer, "emitted photon paths for the global map", "200000"};
  photons.lo = 0, photons.hi = maxPaths;
  ParamSpec caustic{"caustic_photons", ParamType::Integer, "emitted photon paths for the caustic map (0: caustics from the global map)", "200000"};
  caustic.lo = 0, caustic.hi = maxPaths;
  ParamSpec k{"k", ParamType::Integer, "k nearest photons per estimate", "50"};
  k.lo = 1, k.hi = 100000;
  ParamSpec radius{"radius", ParamType::Real, "fixed gather radius in metres instead of k nearest"};
  radius.defaultDoc = "k nearest photons";
  radius.lo = 0, radius.hi = 1e9, radius.openLow = true;
  ParamSpec maxRadius{"max_radius", ParamType::Real, "cap on the k-nearest radius in metres"};
  maxRadius.defaultDoc = "5% of the scene's bounding radius";
  maxRadius.lo = 0, maxRadius.hi = 1e9, maxRadius.openLow = true;
  ParamSpec kernel = params::choice("kernel", "density-estimation kernel", "epanechnikov",
                                    {"uniform", "cone", "epanechnikov", "silverman"});
  ParamSpec gather{"final_gather", ParamType::Integer, "gather rays per first diffuse hit; 0: direct visualisation of the global map", "32"};
  gather.lo = 0, gather.hi = 100000;
  ParamSpec aov = params::choice("aov", "debug image instead of radiance: photons found, or the radius used", "radiance",
                                 {"radiance", "photons", "radius"});
  return {params::spp(), params::maxDepth(), photons, caustic, k, radius, maxRadius, kernel, gather, aov, params::photonTarget(), params::aimAreaLights()};
}

// The estimate's defaults made explicit (resolveDensity), so that the metadata records them.
std::string resolvePhotonDensity(const Scene& scene, int, int, ParamSet& p) {
  DensityEstimation d;
  d.k = int(p.integer("k"));
  d.radius = float(p.real("radius"));
  d.maxRadius = float(p.real("max_radius"));
  d = PhotonIntegrator::resolveDensity(scene, d);
  if (d.maxRadius > 0) p.resolve("max_radius", d.maxRadius);
  return d.radius > 0 ? "fixed radius " + formatNumber(d.radius) + " m"
                      : std::to_string(d.k) + " nearest photons within at most " + formatNumber(d.maxRadius) + " m";
}

}  // namespace

IntegratorEntry photonEntry() {
  IntegratorEntry e(
      "photon", "Jensen's two-pass photon mapping: global and caustic maps, final gathering",
      IntegratorFamily::Pixel, "spp",
      photonParams(),
      [](const ParamSet& p, const RenderOptions& image) { return std::make_unique<PhotonIntegrator>(photonOptions(p, image)); },
      resolvePhotonDensity);
  // The maps' noise and their gathers' radius fall with the photon counts, not the samples.
  e.refinement = {"spp", "photons", "caustic_photons"};
  return e;
}

}  // namespace pl
