#include "integrators/pppm.h"

#include "core/parallel.h"
#include "integrators/builtins.h"

namespace pl {

ImageRGB PPPMIntegrator::render(const Scene& scene, const RenderOptions& io, RenderInfo* info) {
  const ProgressiveOptions& o = o_;
  PassSetup setup(scene, io, o);
  const RenderOptions& ro = setup.image;
  const int W = setup.width, H = setup.height, threads = setup.threads;
  const size_t pixels = setup.pixels;
  const float r0 = setup.initialRadius;
  const Budget& budget = setup.budget;
  std::vector<uint32_t>& passes = setup.passes;
  // Pass p's radius, r²_{p+1} = r²_p (p + α)/(p + 1) from r²_1 = r0²: advanced pass by pass, so
  // that a slice (--pass-range, which may skip passes) uses the radius the whole render has.
  double r2 = double(r0) * r0;
  int radiusPass = 1;  // the pass r2 belongs to
  auto advanceTo = [&](int p) {
    for (; radiusPass < p; ++radiusPass) r2 = pppmNextRadius2(r2, radiusPass, o.alpha);
  };
  advanceTo(ro.sliced() ? ro.rangeBegin + 1 : 1);
  double lastRadius = ro.sliced() && ro.rangeBegin > 0 ? std::sqrt(r2) : r0;
  // Exact sums (core/exact_sum.h), so that slices merge into the whole render's bits.
  std::vector<ExactSum> sum(pixels * 3);

  // A pass's gather points and what their eye paths picked up on the way, kept from the eye pass
  // to the gather.
  std::vector<VisiblePoint> visible(pixels), causticPoints(pixels);
  std::vector<Spectrum> passL(pixels);
  std::vector<SampledWavelengths> passLambda(pixels);

  auto pass = [&](int p) {
    advanceTo(p);
    // 1. Eye pass: the pixels' gather points, and the emission and direct light on the way.
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        if (budget.expired()) return;
        size_t i = y * W + x;
        CameraPath eye = beginEyePath(scene, ro, x, int(y), uint64_t(p));
        passL[i] = traceGatherPoints(scene, eye.ray, eye.lambda, eye.rng, o.maxDepth, &visible[i], &causticPoints[i]);
        passLambda[i] = eye.lambda;
      }
    });
    // 2. Photon pass (dropped whole if the budget expires), adaptive: towards this pass's gather
    // points at its radius.
    auto visibility = passVisibility(o, pixels, [&](size_t i, auto& add) {
      add(visible[i], r2);
      add(causticPoints[i], r2);
    });
    PhotonMaps maps = tracePassPhotons(scene, ro.seed, p, setup.photonsPerPass, threads, o.maxDepth, ro.spectral, &budget, setup.target,
                                       kGatheredPhotons, visibility.get(), setup.mutationSize);
    if (!maps.complete) return false;
    // 3. Gather at the pass's radius.
    DensityEstimation de;
    de.kernel = Kernel::Uniform;
    de.radius = float(std::sqrt(r2));
    de.planeTolerance = 0.25f * de.radius;
    const uint8_t accept = kGatheredPhotons;
    PhotonMarks marks(maps.global.size());
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        if (budget.expired()) return;
        size_t i = y * W + x;
        const VisiblePoint &vp = visible[i], &caustic = causticPoints[i];
        const SampledWavelengths& lambda = passLambda[i];
        Spectrum L = passL[i];
        // The maps' radiance is uplifted on a spectral path.
        GatherStats marking;
        marking.marks = &marks;
        if (vp.valid) L += vp.beta * maps.global.radiance(vp.hit, vp.wo, lambda, de, accept, &marking);
        if (caustic.valid) L += caustic.beta * maps.global.radiance(caustic.hit, caustic.wo, lambda, de, Photon::kAcceptCaustic, &marking);
        if (ro.spectral) L = spectralToRGB(L, lambda.lambda);
        if (isFinite(L)) sum[i * 3].add(L.r), sum[i * 3 + 1].add(L.g), sum[i * 3 + 2].add(L.b);  // non-finite: dropped
        ++passes[i];
      }
    });
    setup.countVisibility(maps, accept, marks);
    lastRadius = de.radius;
    return true;
  };
  // Each pass is an independent image; a pixel's estimate is the mean over its passes.
  auto image = [&] {
    ImageRGB img(W, H);
    for (size_t i = 0; i < pixels; ++i)
      if (passes[i] > 0)
        for (int c = 0; c < 3; ++c) img.data[i * 3 + c] = pixelMean(sum[i * 3 + c], passes[i]);
    return img;
  };
  ImageRGB result = runPasses(setup, o, info, pass, image, [&] { return lastRadius; });
  if (info && ro.sliced()) {
    info->slice = makeSlice(ro, W, H, std::move(sum), {}, passes);
  }
  return result;
}

IntegratorEntry pppmEntry() {
  return IntegratorEntry(
      "pppm", "probabilistic progressive photon mapping (Knaus & Zwicker 2011): independent passes, global radius schedule",
      IntegratorFamily::Pass, "passes",
      progressiveParams(true),
      [](const ParamSet& p, const RenderOptions&) { return std::make_unique<PPPMIntegrator>(progressiveOptions(p)); },
      resolveProgressiveRadius);
}

}  // namespace pl
