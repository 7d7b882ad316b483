#include "integrators/ppm.h"

#include "core/parallel.h"
#include "integrators/builtins.h"

namespace pl {

ImageRGB PPMIntegrator::render(const Scene& scene, const RenderOptions& io, RenderInfo* info) {
  const ProgressiveOptions& o = o_;
  PassSetup setup(scene, io, o);
  const RenderOptions& ro = setup.image;
  const int W = setup.width, H = setup.height, threads = setup.threads;
  const size_t pixels = setup.pixels;
  const float r0 = setup.initialRadius;
  const Budget& budget = setup.budget;
  std::vector<uint32_t>& passes = setup.passes;

  // Eye pass, once. If the budget expires in it, no photon pass follows.
  std::vector<VisiblePoint> hitPoints(pixels);
  std::vector<glm::dvec3> emitted(pixels, glm::dvec3(0.0));
  std::vector<ProgressiveStats> stats(pixels);
  parallelFor(size_t(H), threads, [&](size_t y, int) {
    for (int x = 0; x < W; ++x) {
      if (budget.expired()) return;
      size_t i = y * W + x;
      CameraPath eye = beginEyePath(scene, ro, x, int(y), 0);
      Rng& rng = eye.rng;
      SampledWavelengths& lambda = eye.lambda;
      const Ray& ray = eye.ray;
      Spectrum L = traceVisiblePoint(scene, ray, lambda, rng, o.maxDepth, &hitPoints[i]);
      finishSpectralVisiblePoint(lambda, &hitPoints[i], &L);
      emitted[i] = glm::dvec3(L);
      stats[i].R2 = double(r0) * r0;
    }
  });

  auto pass = [&](int p) {
    // Adaptive: towards the hit points and their current radii.
    auto visibility = passVisibility(o, pixels, [&](size_t i, auto& add) { add(hitPoints[i], stats[i].R2); });
    PhotonMaps maps = tracePassPhotons(scene, ro.seed, p, setup.photonsPerPass, threads, o.maxDepth, ro.spectral, &budget, setup.target,
                                       Photon::kAcceptAll, visibility.get(), setup.mutationSize);
    if (!maps.complete) return false;  // the budget expired: this pass is dropped whole
    PhotonMarks marks(maps.global.size());
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        if (budget.expired()) return;
        size_t i = y * W + x;
        gatherPhotons(hitPoints[i], maps.global, Photon::kAcceptAll, double(setup.photonsPerPass), o.alpha, &stats[i], &marks);
        ++passes[i];
      }
    });
    setup.countVisibility(maps, Photon::kAcceptAll, marks);
    return true;
  };
  auto image = [&] {
    ImageRGB img(W, H);
    for (size_t i = 0; i < pixels; ++i)
      if (passes[i] > 0)
        img.set(int(i % W), int(i / W), Spectrum(emitted[i] + stats[i].radiance(double(passes[i]) * setup.photonsPerPass)));
    return img;
  };
  return runPasses(setup, o, info, pass, image, [&] { return meanRadius(stats); });
}

IntegratorEntry ppmEntry() {
  return IntegratorEntry(
      "ppm", "progressive photon mapping (Hachisuka et al. 2008): fixed hit points, shrinking radii",
      IntegratorFamily::Pass, nullptr,
      progressiveParams(false),
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<PPMIntegrator>(progressiveOptions(p)); },
      resolveProgressiveRadius);
}

}  // namespace pl
