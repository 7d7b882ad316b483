#include "progressive/sppm.h"

#include "core/parallel.h"

namespace pl {

ImageRGB SPPMIntegrator::render(const Scene& scene, const RenderOptions& io, const ProgressiveOptions& o,
                                const CheckpointFn& checkpoint, PassInfo* info) {
  const PassSetup setup = preparePasses(scene, io, o);
  const RenderOptions& ro = setup.image;
  const int W = setup.width, H = setup.height, threads = setup.threads;
  const size_t pixels = setup.pixels;
  const float r0 = setup.initialRadius;

  std::vector<VisiblePoint> visible(pixels);
  std::vector<glm::dvec3> directSum(pixels, glm::dvec3(0.0));  // Σ over passes of Le + L_direct
  std::vector<ProgressiveStats> stats(pixels);
  for (auto& s : stats) s.R2 = double(r0) * r0;
  int passesDone = 0;

  auto pass = [&](int p) {
    // 1. Eye pass: a new visible point per pixel, and its direct light.
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        size_t i = y * W + x;
        Rng rng = Rng::keyed(ro.seed, i, uint64_t(p));
        // Jitter y before x, stated (as function arguments the order would be unspecified; this is
        // the order GCC chose, so images are unchanged).
        float jy = rng.uniform(), jx = rng.uniform();
        Ray ray = scene.camera().generateRay(x + jx, y + jy, W, H);
        if (o.spectral) beginPath(true, rng.uniform());
        VisiblePoint& vp = visible[i];
        Spectrum L = traceVisiblePoint(scene, ray, rng, o.maxDepth, &vp);
        if (vp.valid) {
          Spectrum direct = vp.beta * estimateDirect(scene, vp.hit, vp.hit.shading.toLocal(vp.wo), rng, false);
          if (isFinite(direct)) L += direct;  // a non-finite sample is dropped, never accumulated
        }
        finishSpectralVisiblePoint(&vp, &L);
        directSum[i] += glm::dvec3(L);
      }
    });
    // 2. Photon pass, 3. gather at the visible points (direct light came from shadow rays).
    PhotonMaps maps = tracePassPhotons(scene, ro.seed, p, o.photonsPerPass, threads, o.maxDepth, o.spectral);
    const uint8_t accept = Photon::kAcceptIndirect | Photon::kAcceptCaustic;
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        size_t i = y * W + x;
        gatherPhotons(visible[i], maps.global, accept, double(o.photonsPerPass), o.alpha, &stats[i]);
      }
    });
    passesDone = p;
  };
  auto image = [&] {
    ImageRGB img(W, H);
    double emittedPaths = double(passesDone) * o.photonsPerPass;
    for (size_t i = 0; i < pixels; ++i)
      img.set(int(i % W), int(i / W), Spectrum(directSum[i] / double(passesDone) + stats[i].radiance(emittedPaths)));
    return img;
  };
  return runPasses(setup, o, checkpoint, info, pass, image, [&] { return meanRadius(stats); });
}

}  // namespace pl
