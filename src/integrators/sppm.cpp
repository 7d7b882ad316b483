#include "integrators/sppm.h"

#include "core/parallel.h"
#include "integrators/builtins.h"

namespace pl {

ImageRGB SPPMIntegrator::render(const Scene& scene, const RenderOptions& io, RenderInfo* info) {
  const ProgressiveOptions& o = o_;
  PassSetup setup(scene, io, o);
  const RenderOptions& ro = setup.image;
  const int W = setup.width, H = setup.height, threads = setup.threads;
  const size_t pixels = setup.pixels;
  const float r0 = setup.initialRadius;
  const Budget& budget = setup.budget;
  std::vector<uint32_t>& passes = setup.passes;

  std::vector<VisiblePoint> visible(pixels), causticPoints(pixels);
  std::vector<glm::dvec3> passDirect(pixels);               // this pass's Le + L_direct, until its gather
  std::vector<glm::dvec3> directSum(pixels, glm::dvec3(0.0));  // Σ over the pixel's passes of Le + L_direct
  // A pixel's two sets of statistics: its visible points', and its narrow-lobe points' (caustic
  // photons only), which passes without such a point leave unchanged.
  std::vector<ProgressiveStats> stats(pixels), causticStats(pixels);
  for (auto& s : stats) s.R2 = double(r0) * r0;
  for (auto& s : causticStats) s.R2 = double(r0) * r0;

  auto pass = [&](int p) {
    // 1. Eye pass: new gather points per pixel, and the direct light on the way to them.
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        if (budget.expired()) return;
        size_t i = y * W + x;
        CameraPath eye = beginEyePath(scene, ro, x, int(y), uint64_t(p));
        Rng& rng = eye.rng;
        SampledWavelengths& lambda = eye.lambda;
        const Ray& ray = eye.ray;
        VisiblePoint& vp = visible[i];
        Spectrum L = traceGatherPoints(scene, ray, lambda, rng, o.maxDepth, &vp, &causticPoints[i]);  // finite
        finishSpectralVisiblePoint(lambda, &vp, &L);
        finishSpectralVisiblePoint(lambda, &causticPoints[i]);
        passDirect[i] = glm::dvec3(L);
      }
    });
    // 2. Photon pass (dropped whole if the budget expires: the pixels keep their earlier passes),
    // adaptive: towards this pass's gather points and their radii.
    auto visibility = passVisibility(o, pixels, [&](size_t i, auto& add) {
      add(visible[i], stats[i].R2);
      add(causticPoints[i], causticStats[i].R2);
    });
    PhotonMaps maps = tracePassPhotons(scene, ro.seed, p, setup.photonsPerPass, threads, o.maxDepth, ro.spectral, &budget, setup.target,
                                       kGatheredPhotons, visibility.get(), setup.mutationSize);
    if (!maps.complete) return false;
    // 3. Gather at the visible points (direct light came from estimateDirectMIS); a pixel's pass is
    // complete, and counted, once its gather is done.
    const uint8_t accept = kGatheredPhotons;
    const double n = double(setup.photonsPerPass);
    PhotonMarks marks(maps.global.size());
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        if (budget.expired()) return;
        size_t i = y * W + x;
        gatherPhotons(visible[i], maps.global, accept, n, o.alpha, &stats[i], &marks);
        gatherPhotons(causticPoints[i], maps.global, Photon::kAcceptCaustic, n, o.alpha, &causticStats[i], &marks);
        directSum[i] += passDirect[i];
        ++passes[i];
      }
    });
    setup.countVisibility(maps, accept, marks);
    return true;
  };
  auto image = [&] {
    ImageRGB img(W, H);
    for (size_t i = 0; i < pixels; ++i) {
      if (passes[i] == 0) continue;
      double n = double(passes[i]);
      const double emitted = n * setup.photonsPerPass;
      img.set(int(i % W), int(i / W), Spectrum(directSum[i] / n + stats[i].radiance(emitted) + causticStats[i].radiance(emitted)));
    }
    return img;
  };
  return runPasses(setup, o, info, pass, image, [&] { return meanRadius(stats); });
}

IntegratorEntry sppmEntry() {
  return IntegratorEntry(
      "sppm", "stochastic progressive photon mapping (Hachisuka & Jensen 2009): new visible points every pass",
      IntegratorFamily::Pass, nullptr,
      progressiveParams(true),
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<SPPMIntegrator>(progressiveOptions(p)); },
      resolveProgressiveRadius);
}

}  // namespace pl
