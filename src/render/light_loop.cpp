// The render loop of light-side integrators (LightPathIntegrator, render/integrator.h).
#include <atomic>

#include "render/integrator.h"
#include "render/session.h"

namespace pl {

ImageRGB LightPathIntegrator::render(const Scene& scene, const RenderOptions& options, RenderInfo* info) {
  RenderSession session(scene, options, 2 * 3 * sizeof(double), "splat film");
  const RenderOptions& o = session.options();
  const int W = session.width, H = session.height, threads = session.threads;
  const uint64_t pathsPerIteration = uint64_t(W) * H;
  const Budget& budget = session.budget;
  preprocess(scene, o.seed, threads, budget);

  // Chunks of 4096 paths, each with its splat buffer; blocks of 64 chunks are traced in parallel
  // and added to the iteration's film in chunk order (bounded memory, any thread count).
  const uint64_t chunkSize = 4096, blockChunks = 64;
  const uint64_t chunks = (pathsPerIteration + chunkSize - 1) / chunkSize;
  const uint64_t stream = mix64(o.seed ^ 0x6c69676874ULL);  // "light": apart from the camera-side streams
  SplatFilm total(W, H), iteration(W, H);
  std::vector<SplatBuffer> buffers;
  int done = 0;
  auto infoAt = [&](bool last) {
    RenderInfo st = session.info(last);
    st.spp = done;
    st.meanWork = done;
    st.photons = uint64_t(done) * pathsPerIteration;
    st.nonFiniteSamples = total.nonFinite();
    return st;
  };
  auto estimate = [&] { return total.image(done > 0 ? 1.0 / done : 0.0); };

  // Iteration s (a slice's are s = A, A + K, ... below B) keyed as the whole render keys it.
  auto runIteration = [&](int s) {
    iteration.clear(threads);
    std::atomic<bool> cut{false};
    for (uint64_t first = 0; first < chunks && !cut; first += blockChunks) {
      const uint64_t count = std::min(blockChunks, chunks - first);
      buffers.resize(size_t(count));
      parallelFor(size_t(count), threads, [&](size_t k, int) {
        SplatBuffer& buffer = buffers[k];
        buffer.clear();
        if (budget.expired()) {  // a chunk is a few ms of tracing
          cut = true;
          return;
        }
        const uint64_t begin = (first + k) * chunkSize, end = std::min(pathsPerIteration, begin + chunkSize);
        for (uint64_t i = begin; i < end; ++i) {
          LightPathContext path{W, H, SampledWavelengths(), Rng::keyed(stream, i, uint64_t(s)), &buffer};
          if (o.spectral) path.lambda = SampledWavelengths::sample(path.rng.uniform());
          traceLightPath(scene, path);
        }
      });
      if (cut) return false;  // this iteration is dropped whole
      iteration.add(buffers, threads);
    }
    total.add(iteration, threads);
    ++done;
    return true;
  };
  session.run(session.units(unitTarget(o.spp, o.timeLimit)), runIteration, infoAt, estimate);
  if (info) {
    *info = infoAt(true);
    if (o.sliced()) {
      info->slice = makeSlice(o, W, H, {}, total.sums(), std::vector<uint32_t>(size_t(W) * H, uint32_t(done)));
    }
  }
  return estimate();
}

}  // namespace pl
