#include "render/renderer.h"

#include <optional>

#include "core/budget.h"
#include "core/parallel.h"
#include "render/camera_path.h"
#include "render/iteration_film.h"
#include "render/session.h"
#include "spectral/spectral.h"

namespace pl {

void resolveResolution(const Camera& camera, RenderOptions& o) {
  float aspect = camera.aspectRatio > 0 ? camera.aspectRatio : 1.0f;
  if (o.width <= 0 && o.height <= 0) o.width = 512;
  if (o.width <= 0) o.width = std::max(1, int(std::lround(o.height * aspect)));
  if (o.height <= 0) o.height = std::max(1, int(std::lround(o.width / aspect)));
}

ImageRGB renderPixels(const Scene& scene, PixelIntegrator& integrator, RenderOptions options, RenderInfo* stats) {
  TrainingHook* training = integrator.training();
  if (training && options.sliced())
    throw Error(std::string(integrator.name()) + " learns between iterations: slices of its render would not add up");
  RenderSession session(scene, options,
                        training ? IterationFilm::kBytesPerPixel : 3 * sizeof(ExactSum) + 3 * sizeof(float) + 2 * sizeof(uint32_t),
                        "image");
  const RenderOptions& o = session.options();
  const int W = session.width, H = session.height;
  const size_t pixels = session.pixels;
  const Budget& budget = session.budget;
  // Exact sums (core/exact_sum.h): float accumulation drifts over thousands of samples, and
  // double accumulation depends on the grouping, which would keep slices of a render
  // (--sample-range) from merging into the bits of the whole. A learning integrator's samples go
  // to its iteration film instead.
  std::vector<ExactSum> sum(training ? 0 : pixels * 3);
  std::optional<IterationFilm> iterations;
  if (training) iterations.emplace(W, H);
  // Samples per pixel. All equal, except after a pass the budget cut short: the pixels it
  // reached have one more sample, and each pixel's estimate is its own mean.
  std::vector<uint32_t> count(pixels, 0);
  std::vector<uint64_t> nonFinite(size_t(H), 0);
  std::vector<uint32_t> nanCount(o.nanAov ? pixels : 0, 0);  // per pixel, for --aov nan
  auto estimate = [&] {
    ImageRGB image = iterations && !o.nanAov ? iterations->image() : ImageRGB(W, H);
    if (iterations && !o.nanAov) return image;
    for (size_t i = 0; i < pixels; ++i) {
      if (count[i] == 0) continue;  // the budget ended before this pixel's first sample: black
      if (o.nanAov) {
        image.set(int(i % W), int(i / W), Spectrum(float(nanCount[i]) / count[i]));
        continue;
      }
      for (int c = 0; c < 3; ++c) image.data[i * 3 + c] = pixelMean(sum[i * 3 + c], count[i]);
    }
    return image;
  };
  auto infoAt = [&](bool last) {
    RenderInfo st = session.info(last);
    PixelCounts counts = summarizeCounts(count);
    st.spp = counts.all;
    st.meanWork = counts.mean;
    for (auto n : nonFinite) st.nonFiniteSamples += n;
    integrator.addInfo(scene, o, &st);
    return st;
  };
  integrator.preprocess(scene, o.seed, session.threads, budget);

  // --sampler sobol: a pixel's samples are the points of its own scrambled sequences, indexed by
  // the sample number (so that slices of a render draw the same points as the whole).
  const int sobolSlots = integrator.sobolSlots();
  const uint64_t sobolKey = mix64(o.seed ^ 0x736f626f6c706978ULL);
  // Whole rows per work item: each pixel is touched by one thread per pass, in sample order, so
  // the sums are identical whatever the thread count. Pixels go to the integrator packetSize()
  // at a time (neighbours in reading order), for integrators that trace their rays together;
  // each keeps its own stream and sampler. An item holds as many rows as fit in one packet (one
  // row for most integrators; several for the path tracer's lanes, whose packets stay fuller the
  // more paths they draw from: docs explanation/determinism.md), a grouping fixed by the image's
  // width alone. The budget is polled per packet.
  const int rowsPerItem = std::max(1, std::min(integrator.packetSize() / W, H));
  const int items = (H + rowsPerItem - 1) / rowsPerItem;
  auto samplePass = [&](int s) {
    parallelFor(size_t(items), session.threads, [&](size_t item, int thread) {
      const int y0 = int(item) * rowsPerItem, rows = std::min(rowsPerItem, H - y0);
      const int itemPixels = W * rows;
      const int packet = std::max(1, std::min(integrator.packetSize(), itemPixels));
      std::vector<CameraPath> paths(static_cast<size_t>(packet));
      std::vector<std::optional<Sampler>> samplers(static_cast<size_t>(packet));
      std::vector<PixelIntegrator::CameraSample> samples(static_cast<size_t>(packet));
      // Pixel i of the item is (i mod W, y0 + i div W), image pixel y0·W + i.
      for (int i0 = 0; i0 < itemPixels; i0 += packet) {
        if (budget.expired()) return;
        const int n = std::min(packet, itemPixels - i0);
        for (int k = 0; k < n; ++k) {
          const int x = (i0 + k) % W, y = y0 + (i0 + k) / W;
          const uint64_t pixel = uint64_t(y) * W + x;
          paths[k] = beginCameraPath(scene, o, x, int(y), uint64_t(s));
          Sampler& sampler = samplers[k].emplace(paths[k].rng, sobolSlots > 0, mix64(sobolKey ^ pixel), uint32_t(s), sobolSlots);
          jitterFromSampler(scene, x, int(y), W, H, sampler, &paths[k].ray);
          samples[k] = {paths[k].ray, &paths[k].lambda, &sampler, Spectrum(0.0f), thread,
                        iterations ? iterations->pixelValue(pixel) : 0.0f};
        }
        integrator.LiPacket(samples.data(), n, scene);
        for (int k = 0; k < n; ++k) {
          const int y = y0 + (i0 + k) / W;
          const uint64_t pixel = uint64_t(y0) * W + uint64_t(i0 + k);
          Spectrum L = samples[k].L;
          if (o.spectral) L = spectralToRGB(L, paths[k].lambda.lambda);
          ++count[pixel];
          if (iterations) iterations->count(pixel);
          if (!isFinite(L)) {  // discarded: counted as a zero sample, reported, never on the film
            ++nonFinite[y];
            if (o.nanAov) ++nanCount[pixel];
            continue;
          }
          if (iterations) {
            iterations->add(pixel, L);
          } else {
            ExactSum* p = &sum[pixel * 3];
            p[0].add(L.r), p[1].add(L.g), p[2].add(L.b);
          }
        }
      }
    });
    return true;  // a pass the budget cut short counts: each pixel's estimate is its own mean
  };

  // A learning integrator's passes come in iterations: when one has run its passes, it ends
  // (it joins the image and its report goes to the hook), and the hook trains for the next
  // before that one's first pass.
  Iteration iteration;
  int index = 0, passesLeft = 0;
  double started = 0, trained = 0;
  auto endIteration = [&] {
    IterationReport r = iterations->end();
    r.samples = iteration.samples;
    r.trainingSeconds = trained - started;
    r.elapsed = budget.elapsed();
    r.seconds = r.elapsed - started;
    training->afterIteration(r);
  };
  auto pass = [&](int s) {
    if (!training) return samplePass(s);
    if (passesLeft == 0) {
      if (iterations->running()) {
        endIteration();
        if (iteration.last) return false;
      }
      started = budget.elapsed();
      iteration = training->beforeIteration(scene, index++, o, session.threads, budget);
      trained = budget.elapsed();
      if (iteration.samples <= 0 || budget.expired()) return false;
      passesLeft = iteration.samples;
      iterations->begin(iteration.replaces);
    }
    --passesLeft;
    return samplePass(s);
  };
  session.run(session.units(unitTarget(o.spp, o.timeLimit)), pass, infoAt, estimate);
  if (iterations && iterations->running()) endIteration();
  if (stats) {
    *stats = infoAt(true);
    if (o.sliced()) {
      stats->slice = makeSlice(o, W, H, std::move(sum), {}, std::move(count));
      return stats->slice->mean();
    }
  }
  return estimate();
}

ImageRGB RenderSlice::mean() const {
  ImageRGB image(width, height);
  for (size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] == 0) continue;
    for (int c = 0; c < 3; ++c) {
      const size_t k = i * 3 + c;
      // Formed exactly as the integrators form it (light_loop.cpp, bidirectional.cpp).
      if (splats.empty()) image.data[k] = pixelMean(sums[k], counts[i]);
      else if (sums.empty()) image.data[k] = splatValue(splats[k], 1.0 / counts[i]);
      else image.data[k] = splatValue(splats[k], 1.0 / counts[i]) + pixelMean(sums[k], counts[i]);
    }
  }
  return image;
}

}  // namespace pl

namespace pl {
ImageRGB PixelIntegrator::render(const Scene& scene, const RenderOptions& options, RenderInfo* info) {
  return renderPixels(scene, *this, options, info);
}
}  // namespace pl
