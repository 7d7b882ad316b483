#include "photon/photon_tracer.h"

#include <atomic>
#include <chrono>

#include "core/roulette.h"
#include "bsdfs/lambertian.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "spectral/spectral.h"

namespace pl {

namespace {

constexpr uint64_t kGlobalStream = 0x67bd, kCausticStream = 0xca57;

// Traces one photon path, appending what it stores. In caustic mode the path ends at the first
// non-specular hit and is stored only if it went through at least one specular bounce.
[[gnu::flatten]] void tracePath(const Scene& scene, const PhotonTracingOptions& o, uint64_t index, uint64_t count, bool causticMode,
               std::vector<Photon>* out) {
  Rng rng(0);
  SampledWavelengths lambda;
  EmittedRay e = emitPhoton(scene, o.seed, index, count, causticMode ? kCausticStream : kGlobalStream, &rng, o.spectral, &lambda);
  // What a stored photon carries: in spectral mode the XYZ of its wavelengths' values (the map
  // converts to linear sRGB when it reads them), so that gathers are the same in both modes.
  auto stored = [&](const Spectrum& flux) { return o.spectral ? spectralToXYZ(flux, lambda.lambda) : flux; };
  Spectrum flux = e.flux;
  if (isBlack(flux) || !isFinite(flux)) return;
  Ray ray = e.ray;
  ray.tmin = scene.epsilon();  // area-light photons start on the emitting triangle
  bool onlySpecular = true;
  for (int depth = 0; depth <= o.maxDepth; ++depth) {
    SurfaceHit hit;
    if (!scene.intersect(ray, &hit)) return;
    flux *= scene.transmittance(hit, ray.d, lambda);
    Vec3 wo = -ray.d;
    if (!hit.bsdf->isSpecular()) {
      // kDirect at the first hit, kCaustic after specular bounces only, kIndirect otherwise;
      // in integer arithmetic, since depth == 0 is unpredictable.
      bool first = depth == 0;
      auto type = Photon::Type(first * Photon::kDirect + (!first & onlySpecular) * Photon::kCaustic);
      if (causticMode) {
        if (type == Photon::kCaustic) out->push_back(Photon(hit.p, wo, stored(flux), type, rng.uniform()));
        return;
      }
      out->push_back(Photon(hit.p, wo, stored(flux), type, rng.uniform()));
      onlySpecular = false;
    }
    BSDFSample bs;
    Vec3 woLocal = hit.shading.toLocal(wo);
    Vec2 u(rng.uniform(), rng.uniform());
    float uc = rng.uniform();
    // Diffuse hits, most of them, call Lambertian (final) directly, inlined here, without the
    // virtual call (docs explanation/performance.md, Photon maps).
    const BSDFContext bc = bsdfContext(hit, lambda, TransportMode::Importance);
    bool sampled = hit.bsdf->bsdfClass() == BSDFClass::kLambertian ? static_cast<const Lambertian*>(hit.bsdf)->sample(woLocal, bc, u, uc, &bs)
                                            : hit.bsdf->sample(woLocal, bc, u, uc, &bs);
    if (!sampled) return;
    if (bs.terminatesSecondary) lambda.terminateSecondary();
    Vec3 wi = hit.shading.toWorld(bs.wi);
    if (hit.shadingDiffers()) {
      // A direction the shading normal allows but the geometry does not would leak through the
      // surface; and a flux scattered with a shading normal needs Veach's adjoint correction.
      if (leaksLight(hit, wo, wi, woLocal, bs.wi)) return;
      bs.weight *= shadingNormalCorrection(woLocal, bs.wi, hit.shading.toLocal(hit.ng), TransportMode::Importance);
    }
    // Russian roulette by albedo (core/roulette.h), at every bounce.
    const float q = roulette::albedo(maxComponent(bs.weight));
    if (!roulette::survives(q, [&] { return rng.uniform(); })) return;
    flux *= bs.weight * (1.0f / q);
    if (!isFinite(flux)) return;  // a non-finite BSDF weight ends the path: it never reaches a map
    ray = scene.spawnRay(hit, wi);
  }
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

PhotonMap traceMap(const Scene& scene, const PhotonTracingOptions& o, uint64_t count, bool causticMode,
                   PhotonMaps* stats) {
  auto t0 = std::chrono::steady_clock::now();
  // Fixed chunks of paths, each into its own buffer, concatenated in chunk order: the map is
  // the same whatever the thread count.
  const uint64_t chunkSize = 4096;
  size_t chunks = size_t((count + chunkSize - 1) / chunkSize);
  std::vector<std::vector<Photon>> buffers(chunks);
  // Buffers are allocated by this thread, before the workers trace into them. Allocated by the
  // workers, they came from glibc's per-thread arenas, whose growth and trimming (mprotect,
  // madvise) serialise with the other thread's page faults: two threads traced at 43% of the
  // bare Embree rate instead of 57% (docs: explanation/performance.md). They are allocated a wave at a time
  // (256 chunks per thread, ~0.5 s of tracing), not all at once: each allocation is an mmap of
  // its own (~7 µs, as is its munmap), so reserving 10⁸ paths' 24 000 buffers up front took
  // 0.17 s before the first path, and freeing them when a budget stopped the tracing another
  // 0.18 s, both past the budget. The wave's end costs at most a chunk (~2 ms) per thread.
  const int threads = resolveThreads(o.threads);
  const size_t wave = 256 * size_t(threads);
  std::atomic<bool> stopped{false};
  for (size_t first = 0; first < chunks && !stopped; first += wave) {
    const size_t last = std::min(chunks, first + wave);
    for (size_t c = first; c < last; ++c) buffers[c].reserve(causticMode ? chunkSize / 4 : 3 * chunkSize);
    parallelFor(last - first, threads, [&](size_t k, int) {
      if (o.budget && o.budget->expired()) {  // a chunk is ~2 ms of tracing
        stopped = true;
        return;
      }
      const size_t c = first + k;
      uint64_t end = std::min(count, (c + 1) * chunkSize);
      // Appended through a vector of this thread's own, published once: neighbouring chunks'
      // vector headers share a cache line.
      std::vector<Photon> photons = std::move(buffers[c]);
      for (uint64_t i = c * chunkSize; i < end; ++i) tracePath(scene, o, i, count, causticMode, &photons);
      buffers[c] = std::move(photons);
    });
  }
  stats->traceSeconds += since(t0);
  PhotonMap map;
  if (stopped) {
    stats->complete = false;
    return map;
  }
  auto t1 = std::chrono::steady_clock::now();
  // Chunks in order: the same map whatever the thread count.
  if (!map.build(std::move(buffers), o.budget)) stats->complete = false;
  map.setFluxIsXYZ(o.spectral);
  stats->buildSeconds += since(t1);
  return map;
}

}  // namespace

EmittedRay emitPhoton(const Scene& scene, uint64_t seed, uint64_t index, uint64_t count, uint64_t stream, Rng* rng,
                      bool spectral, SampledWavelengths* lambda) {
  *rng = Rng::hashed(mix64(seed ^ (stream << 32) ^ stream), index);  // photon i's stream: (seed, map, i)
  SampledWavelengths own;
  if (!lambda) lambda = &own;
  *lambda = spectral ? SampledWavelengths::sample(rng->uniform()) : SampledWavelengths();
  const AliasTable& lights = scene.lightDistribution();
  if (lights.size() == 0 || lights.total() <= 0) return EmittedRay{Ray{}, Spectrum(0.0f)};
  float pmf;
  size_t l = lights.sample(rng->uniform(), &pmf);
  Vec2 u1(rng->uniform(), rng->uniform()), u2(rng->uniform(), rng->uniform());
  EmittedRay e = scene.lights()[l]->sampleLe(u1, u2, *lambda);
  e.flux *= 1.0f / (pmf * float(count));  // one division, not three
  return e;
}

PhotonMaps tracePhotons(const Scene& scene, const PhotonTracingOptions& o) {
  // Each emitted path stores one 20-byte photon or more in a closed scene, plus 4 bytes of
  // kd-tree index: refuse a count the machine cannot hold before tracing for minutes.
  checkMemory(mulSaturate(o.globalPaths + o.causticPaths, sizeof(Photon) + sizeof(uint32_t)),
              std::to_string(o.globalPaths + o.causticPaths) + " photon paths");
  uint64_t rays0 = Scene::raysTraced();
  PhotonMaps maps;
  if (o.globalPaths) maps.global = traceMap(scene, o, o.globalPaths, false, &maps);
  if (o.causticPaths && maps.complete) maps.caustic = traceMap(scene, o, o.causticPaths, true, &maps);
  if (!maps.complete) maps.global = PhotonMap();  // nothing half-traced is ever used
  maps.rays = Scene::raysTraced() - rays0;
  return maps;
}

}  // namespace pl
