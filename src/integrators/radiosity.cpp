#include "integrators/radiosity.h"

#include <chrono>
#include <cmath>

#include "core/parallel.h"
#include "integrators/registry.h"
#include "radiosity/form_factor.h"

namespace pl {

// ---------------------------------------------------------------------------------------------
// Form factors: the upper triangle of pairs in 64×64 tiles. A tile (I, J) computes every pair
// (i in I, j in J, i < j) once and writes F_ij into tile (I, J) and F_ji into tile (J, I), both
// compact in memory; tiles are independent work items.

void computeFormFactors(const Scene& scene, const PatchMesh& mesh, int threads, const Budget& budget, FormFactorMatrix* F) {
  constexpr size_t kTile = 64;
  const size_t n = mesh.size();
  const auto& patches = mesh.patches();
  const size_t tiles = (n + kTile - 1) / kTile;
  std::vector<std::pair<uint32_t, uint32_t>> work;
  for (size_t I = 0; I < tiles; ++I)
    for (size_t J = I; J < tiles; ++J) work.emplace_back(uint32_t(I), uint32_t(J));
  std::vector<uint64_t> rays(resolveThreads(threads), 0);
  std::atomic<bool> stopped{false};
  parallelFor(work.size(), threads, [&](size_t w, int thread) {
    if (budget.expired()) {
      stopped = true;
      return;
    }
    const size_t i0 = work[w].first * kTile, j0 = work[w].second * kTile;
    for (size_t i = i0; i < std::min(n, i0 + kTile); ++i) {
      F->values[i * n + i] = 0.0f;  // a planar patch does not see itself
      for (size_t j = std::max(j0, i + 1); j < std::min(n, j0 + kTile); ++j) {
        FormFactorPair f = formFactors(scene, patches[i], patches[j]);
        F->values[i * n + j] = f.ij;
        F->values[j * n + i] = f.ji;
        rays[thread] += f.rays;
      }
    }
  });
  for (uint64_t r : rays) F->rays += r;
  F->complete = !stopped;
}

std::vector<Spectrum> deltaLightIrradiance(const Scene& scene, const PatchMesh& mesh, int threads) {
  std::vector<Spectrum> E(mesh.size(), Spectrum(0.0f));
  std::vector<const Light*> delta;
  for (const auto& light : scene.lights())
    if (light->isDelta()) delta.push_back(light.get());
  if (delta.empty()) return E;
  parallelFor(mesh.size(), threads, [&](size_t i, int) {
    for (const Light* light : delta) E[i] += directIrradiance(scene, *light, mesh.patches()[i]);
  });
  return E;
}

// ---------------------------------------------------------------------------------------------
// Gauss–Seidel: each sweep updates B_i in patch order from the newest B_j. Converges for ρ < 1
// (the matrix ρF has row sums ≤ max ρ < 1 in a closed scene, less in an open one).

RadiositySolution solveRadiosity(const PatchMesh& mesh, const FormFactorMatrix& F, std::vector<Spectrum> irradiance,
                                 double tolerance, int maxSweeps) {
  const size_t n = mesh.size();
  const auto& patches = mesh.patches();
  RadiositySolution s;
  s.irradiance = std::move(irradiance);
  // Channels apart, padded to a multiple of 8, so that the gathering loop vectorises.
  const size_t padded = (n + 7) / 8 * 8;
  std::vector<float> B[3];
  for (auto& b : B) b.assign(padded, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    Spectrum b = patches[i].exitance + patches[i].reflectance * s.irradiance[i];
    B[0][i] = b.r, B[1][i] = b.g, B[2][i] = b.b;
  }
  for (s.sweeps = 1; s.sweeps <= maxSweeps; ++s.sweeps) {
    double change = 0.0, total = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const float* row = F.row(i);
      float acc[3][8] = {};
      size_t j = 0;
      for (; j + 8 <= n; j += 8)
        for (int c = 0; c < 3; ++c)
          for (int k = 0; k < 8; ++k) acc[c][k] += row[j + k] * B[c][j + k];
      for (; j < n; ++j)
        for (int c = 0; c < 3; ++c) acc[c][0] += row[j] * B[c][j];
      const Patch& p = patches[i];
      double gathered[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 8; ++k) gathered[c] += acc[c][k];
      const float rho[3] = {p.reflectance.r, p.reflectance.g, p.reflectance.b};
      const float M[3] = {p.exitance.r, p.exitance.g, p.exitance.b};
      const float E[3] = {s.irradiance[i].r, s.irradiance[i].g, s.irradiance[i].b};
      for (int c = 0; c < 3; ++c) {
        float updated = M[c] + rho[c] * float(E[c] + gathered[c]);
        change += double(p.area) * std::abs(updated - B[c][i]);
        total += double(p.area) * updated;
        B[c][i] = updated;
      }
    }
    s.unshot = total > 0 ? change / total : 0.0;
    if (s.unshot <= tolerance) {
      s.converged = true;
      break;
    }
  }
  s.sweeps = std::min(s.sweeps, maxSweeps);
  s.radiosity.resize(n);
  for (size_t i = 0; i < n; ++i) s.radiosity[i] = Spectrum(B[0][i], B[1][i], B[2][i]);
  return s;
}

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

const IntegratorRegistration registration({
    "radiosity", "classic radiosity (Goral et al. 1984): diffuse patches, form factors by ray casting, Gauss-Seidel",
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
    resolvePatchSize});

}  // namespace

}  // namespace pl
