#include "render/renderer.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>

#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "spectral/spectral.h"

namespace pl {

void resolveResolution(const Camera& camera, RenderOptions& o) {
  float aspect = camera.aspectRatio > 0 ? camera.aspectRatio : 1.0f;
  if (o.width <= 0 && o.height <= 0) o.width = 512;
  if (o.width <= 0) o.width = std::max(1, int(std::lround(o.height * aspect)));
  if (o.height <= 0) o.height = std::max(1, int(std::lround(o.width / aspect)));
}

namespace {

class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}
  void update(double fraction, double elapsed) {
    if (!enabled_ || (elapsed - last_ < 0.1 && fraction < 1)) return;  // at most 10 updates/s
    last_ = elapsed;
    int width = 40, filled = int(fraction * width);
    double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %6.1fs  ETA %6.1fs", filled, "########################################",
                 width - filled, "", 100 * fraction, elapsed, eta);
    std::fflush(stderr);
  }
  ~Progress() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  double last_ = -1;
};

}  // namespace

ImageRGB render(const Scene& scene, Integrator& integrator, RenderOptions o, RenderStats* stats) {
  resolveResolution(scene.camera(), o);
  const int W = o.width, H = o.height;
  const int threads = resolveThreads(o.threads);
  checkMemory(mulSaturate(uint64_t(W) * uint64_t(H), 3 * sizeof(double) + 3 * sizeof(float) + sizeof(uint32_t)),
              std::to_string(W) + "x" + std::to_string(H) + " image");
  // Double-precision sums: float accumulation drifts over thousands of samples.
  std::vector<double> sum(size_t(W) * H * 3, 0.0);
  std::vector<uint64_t> nonFinite(size_t(H), 0);
  std::vector<uint32_t> nanCount(o.nanAov ? size_t(W) * H : 0, 0);  // per pixel, for --aov nan
  RenderClock clock;
  auto estimate = [&](int taken) {
    ImageRGB image(W, H);
    if (o.nanAov) {
      for (size_t i = 0; i < nanCount.size(); ++i) image.set(int(i % W), int(i / W), Spectrum(float(nanCount[i]) / taken));
      return image;
    }
    for (size_t i = 0; i < sum.size(); ++i) image.data[i] = float(sum[i] / taken);
    return image;
  };
  auto fillStats = [&](RenderStats* st, int taken, bool interrupted) {
    st->spp = taken;
    st->seconds = clock.elapsed();
    st->nonFiniteSamples = 0;
    for (auto n : nonFinite) st->nonFiniteSamples += n;
    st->interrupted = interrupted;
  };
  integrator.preprocess(scene, o.seed, threads);
  Progress progress(o.progress);

  int taken = 0;
  bool interrupted = false;
  int target = o.spp > 0 ? o.spp : (o.timeLimit > 0 ? INT32_MAX : 1);
  for (int s = 0; s < target; ++s) {
    // One row per work item: each pixel is touched by one thread per pass, in sample order,
    // so the sums are identical whatever the thread count.
    parallelFor(size_t(H), threads, [&](size_t y, int) {
      for (int x = 0; x < W; ++x) {
        uint64_t pixel = uint64_t(y) * W + x;
        Rng rng = Rng::keyed(o.seed, pixel, uint64_t(s));
        float jx = rng.uniform(), jy = rng.uniform();
        Ray ray = scene.camera().generateRay(x + jx, float(y) + jy, W, H);
        Spectrum L;
        if (o.spectral) {
          Vec3 lambda = beginPath(true, rng.uniform());
          L = spectralToRGB(integrator.Li(ray, scene, rng), lambda);
          spectralContext().active = false;
        } else {
          L = integrator.Li(ray, scene, rng);
        }
        if (!isFinite(L)) {  // discarded: counted as a zero sample, reported, never on the film
          ++nonFinite[y];
          if (o.nanAov) ++nanCount[pixel];
          continue;
        }
        double* p = &sum[pixel * 3];
        p[0] += L.r, p[1] += L.g, p[2] += L.b;
      }
    });
    taken = s + 1;
    double t = clock.elapsed();
    progress.update(o.spp > 0 ? double(taken) / o.spp : std::min(1.0, t / o.timeLimit), t);
    interrupted = interruptRequested();
    bool last = taken == target || (o.timeLimit > 0 && t >= o.timeLimit) || interrupted;
    if (o.checkpoint && (isCheckpoint(taken) || last)) {
      clock.excluding([&] {
        RenderStats st;
        fillStats(&st, taken, interrupted);
        o.checkpoint(estimate(taken), st);
      });
    }
    if (last) break;
  }

  if (stats) fillStats(stats, taken, interrupted);
  return estimate(taken);
}

}  // namespace pl
