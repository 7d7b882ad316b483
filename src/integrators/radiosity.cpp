#include "integrators/radiosity.h"

#include <chrono>
#include <cmath>

#include "core/parallel.h"
#include "integrators/builtins.h"

namespace pl {

// ---------------------------------------------------------------------------------------------
// The integrator: solve once, then show the solution.

void RadiosityIntegrator::preprocess(const Scene& scene, uint64_t, int threads, const Budget& budget) {
  // The patches' irradiance is gathered from point, spot, directional and area lights; the
  // sky's (a visibility integral over each patch's hemisphere) is not computed.
  if (scene.environment())
    throw Error("radiosity: an environment light is not supported; use path, photon, sppm or pppm (or a scene with other lights)");
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  auto start = Clock::now();
  if (!(o_.patchSize > 0)) o_.patchSize = PatchMesh::patchSizeFor(scene, o_.patchBudget);
  mesh_ = std::make_unique<PatchMesh>(scene, o_.patchSize);
  const size_t n = mesh_->size();
  stats_.meshSeconds = since(start);
  for (const std::string& m : mesh_->nonDiffuseMaterials())
    warnings_.push_back("radiosity: material '" + m + "' is not diffuse; the method shows it black");
  stats_.matrixBytes = mulSaturate(mulSaturate(n, n), sizeof(float));
  checkMemory(stats_.matrixBytes,
              "radiosity: the form factors of " + std::to_string(n) + " patches (4n² bytes; a larger --patch-size makes fewer)");
  auto formFactorsStart = Clock::now();
  FormFactorMatrix F(n);
  computeFormFactors(scene, *mesh_, threads, budget, &F);
  stats_.formFactorSeconds = since(formFactorsStart);
  stats_.rays = F.rays;
  if (!F.complete) {
    warnings_.push_back(std::string(budget.timeUp() ? "the time budget ran out" : "interrupted") +
                        " while the form factors were computed (" + formatNumber(budget.elapsed()) +
                        " s): no image; a larger --patch-size (fewer patches) fits in the budget");
    return;
  }
  auto solveStart = Clock::now();
  solution_ = solveRadiosity(*mesh_, F, deltaLightIrradiance(scene, *mesh_, threads), o_.tolerance, o_.maxSweeps);
  stats_.solveSeconds = since(solveStart);
  if (!solution_.converged)
    warnings_.push_back("radiosity: not converged after " + std::to_string(solution_.sweeps) + " sweeps (unshot power " +
                        formatNumber(solution_.unshot) + " of the total; is a reflectance 1 in a closed scene?)");
  vertexRadiosity_ = mesh_->vertexValues(solution_.radiosity);
  reflected_.resize(n);
  for (size_t i = 0; i < n; ++i) reflected_[i] = solution_.radiosity[i] - mesh_->patches()[i].exitance;
  vertexReflected_ = mesh_->vertexValues(reflected_);
  solved_ = true;
  auto rounded = [](double s) { return formatNumber(std::round(s * 100) / 100); };
  notes_.push_back(std::to_string(n) + " patches (size " + formatNumber(o_.patchSize) + " m), meshed in " +
                   rounded(stats_.meshSeconds) + " s; form factors " + rounded(stats_.formFactorSeconds) + " s (" +
                   std::to_string(F.rays) + " visibility rays, " + formatNumber(std::round(stats_.matrixBytes / 1e6)) +
                   " MB); Gauss-Seidel " + rounded(stats_.solveSeconds) + " s (" + std::to_string(solution_.sweeps) +
                   " sweeps, unshot " + formatNumber(float(solution_.unshot)) + ")");
}

Spectrum RadiosityIntegrator::shade(const SurfaceHit& hit, const Vec3& w, const std::vector<Spectrum>& vertexValues,
                                    const std::vector<Spectrum>& patchValues, bool smooth) const {
  Vec3 weights;
  int p = mesh_->locate(hit.primitive, hit.barycentric, w, &weights);
  if (p < 0) return Spectrum(0.0f);
  if (!smooth) return patchValues[p] * kInvPi;
  const uint32_t* c = mesh_->patches()[p].corner;
  return (weights.x * vertexValues[c[0]] + weights.y * vertexValues[c[1]] + weights.z * vertexValues[c[2]]) * kInvPi;
}

Spectrum RadiosityIntegrator::Li(const Ray& ray, const Scene& scene, SampledWavelengths& lambda, Sampler& sampler) const {
  if (!solved_) return Spectrum(0.0f);
  SurfaceHit hit;
  if (!scene.intersect(ray, &hit)) return Spectrum(0.0f);
  const Vec3 wo = -ray.d;
  switch (o_.display) {
    case RadiosityOptions::Display::Flat:
      return shade(hit, wo, vertexRadiosity_, solution_.radiosity, false);
    case RadiosityOptions::Display::Smooth:
      return shade(hit, wo, vertexRadiosity_, solution_.radiosity, true);
    case RadiosityOptions::Display::Gather:
      break;
  }
  // Final gather: L(x) = Le(x) + direct light by one shadow ray + the reflected radiosity
  // (B − M)/π of the point a cosine-sampled ray reaches. Emission one bounce away is the
  // shadow ray's to count, so the gathered ray takes only the reflected part.
  Spectrum L(0.0f);
  if (hit.light) L += hit.light->L(hit.uv, wo, lambda);
  Vec3 weights;
  int p = mesh_->locate(hit.primitive, hit.barycentric, wo, &weights);
  if (p < 0 || isBlack(mesh_->patches()[p].reflectance)) return L;
  const Vec3 woLocal = hit.shading.toLocal(wo);
  L += estimateDirect(scene, hit, woLocal, lambda, sampler, false);
  BSDFSample bs;
  const BSDFContext context = bsdfContext(hit, lambda);
  Vec2 u = sampler.get2D();
  if (!hit.bsdf->sample(woLocal, context, u, sampler.get1D(), &bs)) return L;
  const Vec3 wi = hit.shading.toWorld(bs.wi);
  if (glm::dot(wi, hit.ng) * glm::dot(wo, hit.ng) <= 0) return L;  // below the geometric surface
  SurfaceHit y;
  if (!scene.intersect(scene.spawnRay(hit, wi), &y)) return L;
  return L + bs.weight * shade(y, -wi, vertexReflected_, reflected_, true);
}

ImageRGB RadiosityIntegrator::render(const Scene& scene, const RenderOptions& options, RenderInfo* info) {
  ImageRGB image = PixelIntegrator::render(scene, options, info);
  if (o_.patchesAov && solved_) {
    // One ray through each pixel's centre: each patch flat at B/π, its edges drawn dark.
    RenderOptions o = options;
    resolveResolution(scene.camera(), o);
    ImageRGB patches(o.width, o.height);
    parallelFor(size_t(o.height), resolveThreads(o.threads), [&](size_t y, int) {
      for (int x = 0; x < o.width; ++x) {
        SurfaceHit hit;
        Ray ray = scene.camera().generateRay(x + 0.5f, y + 0.5f, o.width, o.height);
        if (!scene.intersect(ray, &hit)) continue;
        Vec3 weights;
        int p = mesh_->locate(hit.primitive, hit.barycentric, -ray.d, &weights);
        if (p < 0) continue;
        Spectrum L = solution_.radiosity[p] * kInvPi;
        float edge = std::min({weights.x, weights.y, weights.z});
        patches.set(x, int(y), edge < 0.06f ? 0.15f * L : L);
      }
    });
    extra_.push_back({"patches", std::move(patches)});
  }
  return image;
}

// ---------------------------------------------------------------------------------------------
// Registration.
namespace {

ParamSpec patchSize() {
  ParamSpec s{"patch_size", ParamType::Real, "longest patch edge in metres (each triangle is split into n² patches)"};
  s.defaultDoc = "the size whose patch count is closest to `patches` without exceeding it";
  s.lo = 0, s.hi = 1e7, s.openLow = true;
  return s;
}

ParamSpec patchBudget() {
  ParamSpec s{"patches", ParamType::Integer, "patch budget when patch_size is not given (the form factors take 4n² bytes)", "4096"};
  s.lo = 1, s.hi = 1 << 20;
  return s;
}

ParamSpec tolerance() {
  ParamSpec s{"tolerance", ParamType::Real, "stop when a Gauss-Seidel sweep changes less than this fraction of the power", "1e-4"};
  s.lo = 0, s.hi = 1, s.openLow = true;
  return s;
}

ParamSpec display() {
  return params::choice("display",
                        "smooth: B/π interpolated from vertex radiosities; flat: B/π per patch; gather: one final-gather "
                        "bounce (shadow rays for direct light, the solution one bounce away)",
                        "smooth", {"smooth", "flat", "gather"});
}

ParamSpec patchesAov() {
  return params::choice("aov", "patches: also write OUT.patches.ext, the mesh (flat patches, edges drawn)", "radiance",
                        {"radiance", "patches"});
}

std::string resolvePatchSize(const Scene& scene, int, int, ParamSet& params) {
  if (params.isSet("patch_size")) {
    float h = float(params.real("patch_size"));
    return std::to_string(PatchMesh::count(scene, h)) + " patches of at most " + formatNumber(h) + " m";
  }
  size_t budget = size_t(params.integer("patches"));
  float h = PatchMesh::patchSizeFor(scene, budget);
  params.resolve("patch_size", h);
  return std::to_string(PatchMesh::count(scene, h)) + " patches of at most " + formatNumber(h) + " m (default: the budget of " +
         std::to_string(budget) + ")";
}

}  // namespace

IntegratorEntry radiosityEntry() {
  IntegratorEntry e(
      "radiosity", "classic radiosity (Goral et al. 1984): diffuse patches, form factors by ray casting, Gauss-Seidel",
      IntegratorFamily::Pixel, "spp",
      {params::spp(), patchSize(), patchBudget(), tolerance(), display(), patchesAov()},
      [](const ParamSet& p, const RenderOptions& image) {
        if (image.spectral) throw Error("radiosity solves in RGB; --spectral is not supported");
        RadiosityOptions o;
        o.patchSize = float(p.real("patch_size"));  // 0 when unresolved: from the budget in preprocess()
        o.patchBudget = size_t(p.integer("patches"));
        o.tolerance = p.real("tolerance");
        const std::string d = p.choice("display");
        o.display = d == "flat" ? RadiosityOptions::Display::Flat
                    : d == "gather" ? RadiosityOptions::Display::Gather
                                    : RadiosityOptions::Display::Smooth;
        o.patchesAov = p.choice("aov") == "patches";
        return std::make_unique<RadiosityIntegrator>(o);
      },
      resolvePatchSize);
  e.carries = kEveryLightType & ~lightTypeBit(LightType::kInfinite);  // the sky is refused (radiosity.cpp)
  e.refinement = {"patches"};  // its error is the mesh's; the samples only average the display
  return e;
}


}  // namespace pl
