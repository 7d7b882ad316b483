// `photonlab bench`: the ceiling (bare Embree incoherent rays on the scene) and what the path
// tracer achieves against it, single-threaded and on all cores.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <malloc.h>
#include <set>

#include <nlohmann/json.hpp>

#include "bench/least_path_loop.h"
#include "core/parallel.h"
#include "io/metrics.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "photon/photon_tracer.h"
#include "spectral/spectral.h"
#include "integrators/radiosity.h"
#include "integrators/registry.h"
#include "integrators/progressive.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"

namespace pl {

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Embree's ceilings, each query alone on rays generated before timing.
//   closest hit (rtcIntersect1): random origins inside the scene's bounds, uniformly random
//     directions (maximally incoherent), unbounded;
//   occlusion (rtcOccluded1): segments between two random points inside the bounds, as shadow
//     rays are (finite, towards a point); Embree stops at the first hit, so they cost less.
//   closest hit in packets of 8 and 16 (rtcIntersect8, rtcIntersect16) on the same rays, and
//   occlusion in packets of 16 (rtcOccluded16) on the same segments: what a loop that traces
//   eight or sixteen paths' rays together would have as its ceilings.
// A packet (RTCRayHit8, RTCRayHit16) of consecutive rays, every lane starting unhit.
template <typename Packet>
void fillPacket(Packet& rh, const Ray* rays) {
  constexpr int lanes = int(sizeof(rh.ray.tfar) / sizeof(float));
  for (int k = 0; k < lanes; ++k) {
    const Ray& r = rays[k];
    rh.ray.org_x[k] = r.o.x, rh.ray.org_y[k] = r.o.y, rh.ray.org_z[k] = r.o.z;
    rh.ray.dir_x[k] = r.d.x, rh.ray.dir_y[k] = r.d.y, rh.ray.dir_z[k] = r.d.z;
    rh.ray.tnear[k] = 0, rh.ray.tfar[k] = r.tmax, rh.ray.time[k] = 0, rh.ray.mask[k] = 0xFFFFFFFFu;
    rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
  }
}

// Embree's packet calls, by packet width.
void intersectPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit8& rh) {
  rtcIntersect8(valid, scene, context, &rh);
}
void intersectPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16& rh) {
  rtcIntersect16(valid, scene, context, &rh);
}
void occludedPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit8& rh) {
  rtcOccluded8(valid, scene, context, &rh.ray);
}
void occludedPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16& rh) {
  rtcOccluded16(valid, scene, context, &rh.ray);
}

struct EmbreeRates {
  double closest = 0, occlusion = 0, packets8 = 0, packets16 = 0, occlusion16 = 0;  // rays per second
};
// The best of several measurements, rate by rate.
void keepBestRates(EmbreeRates& best, const EmbreeRates& m) {
  best.closest = std::max(best.closest, m.closest);
  best.occlusion = std::max(best.occlusion, m.occlusion);
  best.packets8 = std::max(best.packets8, m.packets8);
  best.packets16 = std::max(best.packets16, m.packets16);
  best.occlusion16 = std::max(best.occlusion16, m.occlusion16);
}

EmbreeRates embreeRaysPerSecond(const Scene& scene, int threads) {
  const size_t chunk = 1 << 16, chunks = 64;
  std::vector<Ray> rays(chunk), segments(chunk);
  Rng rng(7, 1);
  const Bounds& b = scene.bounds();
  Vec3 lo = b.lo + 0.05f * (b.hi - b.lo), ext = 0.9f * (b.hi - b.lo);
  auto inside = [&] { return lo + ext * Vec3(rng.uniform(), rng.uniform(), rng.uniform()); };
  for (auto& r : rays) {
    r.o = inside();
    r.d = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    r.tmax = INFINITY;
  }
  for (auto& r : segments) {
    r.o = inside();
    const Vec3 d = inside() - r.o;
    const float length = std::max(glm::length(d), 1e-6f);
    r.d = d / length;
    r.tmax = length;
  }
  // Hits are counted per chunk and published once: a per-thread counter array incremented per
  // ray shares one cache line between the threads, and that false sharing made the 2-thread
  // ceiling read lower than the 1-thread one.
  std::atomic<uint64_t> hits{0};
  auto rate = [&](bool occlusion) {
    auto t0 = std::chrono::steady_clock::now();
    parallelFor(chunks, threads, [&](size_t, int) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      uint64_t chunkHits = 0;
      for (const Ray& r : occlusion ? segments : rays) {
        RTCRayHit rh;
        rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
        rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
        rh.ray.tnear = 0, rh.ray.tfar = r.tmax, rh.ray.time = 0, rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0, rh.ray.flags = 0;
        if (occlusion) {
          rtcOccluded1(scene.embreeScene(), &context, &rh.ray);
          chunkHits += rh.ray.tfar < 0;
        } else {
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(scene.embreeScene(), &context, &rh);
          chunkHits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
      }
      hits += chunkHits;
    });
    return double(chunk * chunks) / seconds(t0);
  };
  // Packets of 8 or 16 (the packet type's width): closest hit on the rays, or occlusion on the
  // segments.
  auto packetRate = [&](auto packet, bool occlusion) {
    using Packet = decltype(packet);
    constexpr int lanes = int(sizeof(packet.ray.tfar) / sizeof(float));
    auto t0 = std::chrono::steady_clock::now();
    parallelFor(chunks, threads, [&](size_t, int) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      alignas(64) int valid[lanes];
      std::fill(valid, valid + lanes, -1);
      uint64_t chunkHits = 0;
      const std::vector<Ray>& source = occlusion ? segments : rays;
      for (size_t i = 0; i + lanes <= source.size(); i += lanes) {
        Packet rh;
        fillPacket(rh, &source[i]);
        if (occlusion) {
          occludedPacket(valid, scene.embreeScene(), &context, rh);
          for (int k = 0; k < lanes; ++k) chunkHits += rh.ray.tfar[k] < 0;
        } else {
          intersectPacket(valid, scene.embreeScene(), &context, rh);
          for (int k = 0; k < lanes; ++k) chunkHits += rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        }
      }
      hits += chunkHits;
    });
    return double(chunk * chunks) / seconds(t0);
  };
  EmbreeRates r;
  r.closest = rate(false);
  r.occlusion = rate(true);
  r.packets8 = packetRate(RTCRayHit8{}, false);
  r.packets16 = packetRate(RTCRayHit16{}, false);
  r.occlusion16 = packetRate(RTCRayHit16{}, true);
  return r;
}

struct PathRate {
  double samplesPerSecond = 0, raysPerSecond = 0, shadowRaysPerSecond = 0;
  // The share of the ceiling the tracer reaches: the time Embree alone would take for its
  // closest-hit rays and its shadow rays, each kind at its own ceiling, over the time it took.
  double ofCeiling(const EmbreeRates& e) const {
    return (raysPerSecond - shadowRaysPerSecond) / e.closest + shadowRaysPerSecond / e.occlusion;
  }
};

PathRate pathTracerRate(const Scene& scene, int threads, int spp, bool spectral = false, bool lanes = true) {
  RenderOptions o;
  o.width = o.height = 256;
  o.spp = spp;
  o.threads = threads;
  o.spectral = spectral;
  ParamSet p = integratorEntry("path").defaults();
  p.setChoice("lanes", lanes ? "on" : "off");
  auto integrator = makeIntegrator("path", p, o);
  const uint64_t rays0 = Scene::raysTraced(), shadow0 = Scene::shadowRaysTraced();
  RenderInfo stats;
  render(scene, *integrator, o, &stats);
  const double rays = double(Scene::raysTraced() - rays0), shadow = double(Scene::shadowRaysTraced() - shadow0);
  return {256.0 * 256.0 * stats.spp / stats.seconds, rays / stats.seconds, shadow / stats.seconds};
}

// The relMSE (photonlab compare's) that a path-traced image of `seconds` has, without a
// reference: two independent renders (seeds 1 and 2) of half the time each, whose mean is the
// image of `seconds` (relMSEFromHalves). Returns it, and the samples per pixel the mean has.
std::pair<double, int> equalTimeRelMSE(const Scene& scene, int threads, int width, double seconds) {
  ImageRGB half[2];
  int spp = 0;
  for (int k = 0; k < 2; ++k) {
    RenderOptions o;
    o.width = o.height = width;
    o.spp = 0;  // the time alone
    o.timeLimit = seconds / 2;
    o.threads = threads;
    o.seed = uint64_t(k + 1);
    RenderInfo info;
    half[k] = render(scene, *makeIntegrator("path", o), o, &info);
    spp += info.spp;
  }
  return {relMSEFromHalves(half[0], half[1]), spp};
}

// The machine is shared and noisy: report the best of five runs of a measurement (with three,
// a half-second stall of the second core sometimes caught every 2-thread run of a row).
template <typename Measure>
auto bestOf5(Measure measure) {
  auto best = measure();
  for (int i = 0; i < 4; ++i) {
    auto m = measure();
    if (m > best) best = m;
  }
  return best;
}

bool operator>(const PathRate& a, const PathRate& b) { return a.samplesPerSecond > b.samplesPerSecond; }

// The least path tracer (bench/least_path_loop.h) at the path tracer's resolution, depth and spp:
// one path at a time, or 16 in SIMD lanes.
PathRate leastPathRate(const Scene& scene, int threads, int spp, bool simd = false) {
  const LeastPathResult r = (simd ? leastPathLoopSimd : leastPathLoop)(scene, 256, 256, spp, 64, threads, 1);
  return {256.0 * 256.0 * spp / r.seconds, (r.closestRays + r.shadowRays) / r.seconds, r.shadowRays / r.seconds};
}

struct GatherRate {
  double pixelOrder, randomOrder;
};

// k = 50 radiance estimates at the first hits of a 512² image's camera rays, in scanline order
// and in a random permutation of the same points.
GatherRate gatherRate(const Scene& scene, const PhotonMap& map, int threads) {
  struct Query {
    SurfaceHit hit;
    Vec3 wo;
  };
  std::vector<Query> queries;
  const int W = 512;
  for (int y = 0; y < W; ++y)
    for (int x = 0; x < W; ++x) {
      Ray r = scene.camera().generateRay(x + 0.5f, y + 0.5f, W, W);
      Query q;
      if (scene.intersect(r, &q.hit)) q.wo = -r.d, queries.push_back(q);
    }
  DensityEstimation de;
  de.k = 50;
  de.maxRadius = 0.05f * scene.bounds().radius();
  de.planeTolerance = 0.25f * de.maxRadius;
  auto run = [&](const std::vector<Query>& qs) {
    std::vector<float> sink((qs.size() + 1023) / 1024, 0.0f);  // one per chunk, written once (no false sharing)
    auto t0 = std::chrono::steady_clock::now();
    const size_t chunk = 1024;
    parallelFor(sink.size(), threads, [&](size_t c, int) {
      float sum = 0.0f;
      for (size_t i = c * chunk; i < std::min(qs.size(), (c + 1) * chunk); ++i)
        sum += map.radiance(qs[i].hit, qs[i].wo, de, Photon::kAcceptAll).g;
      sink[c] = sum;
    });
    return qs.size() / seconds(t0);
  };
  GatherRate rate;
  rate.pixelOrder = run(queries);
  Rng rng(3, 3);
  for (size_t i = queries.size() - 1; i > 0; --i) std::swap(queries[i], queries[rng.nextU32() % (i + 1)]);
  rate.randomOrder = run(queries);
  return rate;
}

struct TraceRate {
  double raysPerSecond, photonsPerSecond;
};

TraceRate photonTraceRate(const Scene& scene, int threads, uint64_t paths) {
  PhotonTracingOptions o;
  o.globalPaths = paths;
  o.causticPaths = 0;
  o.threads = threads;
  PhotonMaps maps = tracePhotons(scene, o);
  return {maps.rays / maps.traceSeconds, maps.global.size() / maps.traceSeconds};
}

bool operator>(const TraceRate& a, const TraceRate& b) { return a.raysPerSecond > b.raysPerSecond; }

}  // namespace

int runBench(const std::string& scenePath, const std::string& glassScenePath, int threads, int spp) {
  auto scene = loadGltf(scenePath);
  int all = resolveThreads(threads);
  std::printf("photonlab bench: %s (%zu triangles), path tracer at 256x256, %d spp, best of 5\n\n",
              scenePath.c_str(), scene->triangleCount(), spp);
  std::printf("| measure | 1 thread | %d threads |\n|---|---|---|\n", all);
  embreeRaysPerSecond(*scene, all);  // warm-up
  RGBUplift::instance();             // the spectral uplift's tables, built before timing
  // Each ratio's two rates are measured in interleaved rounds, best of five per rate. The
  // machine's clock and load drift over seconds: measured one row after the other, the
  // ceiling once caught a fast period (7.1 M rays/s on one thread) that the tracers, measured
  // a minute later at 6.6-level speed, missed.
  const int columns[2] = {1, all};
  EmbreeRates embree[2];
  PathRate path[2] = {{0, 0}, {0, 0}}, spectral[2] = {{0, 0}, {0, 0}}, scalar[2] = {{0, 0}, {0, 0}};
  PathRate least[2] = {{0, 0}, {0, 0}};
  PathRate leastSimd[2] = {{0, 0}, {0, 0}};
  const std::string leastUnsupported = leastPathLoopUnsupported(*scene);
  TraceRate trace[2] = {{0, 0}, {0, 0}};
  auto keepBest = [](auto& best, const auto& m) {
    if (m > best) best = m;
  };
  for (int round = 0; round < 5; ++round) {
    for (int c = 0; c < 2; ++c) {
      keepBestRates(embree[c], embreeRaysPerSecond(*scene, columns[c]));
      keepBest(path[c], pathTracerRate(*scene, columns[c], spp));
      if (leastUnsupported.empty()) {
        keepBest(least[c], leastPathRate(*scene, columns[c], spp));
        keepBest(leastSimd[c], leastPathRate(*scene, columns[c], spp, true));
      }
      keepBest(spectral[c], pathTracerRate(*scene, columns[c], spp, true));
      keepBest(scalar[c], pathTracerRate(*scene, columns[c], spp, false, false));
      keepBest(trace[c], photonTraceRate(*scene, columns[c], 500000));
    }
  }
  std::printf("| bare Embree incoherent rays (M rays/s) | %.2f | %.2f |\n", embree[0].closest / 1e6, embree[1].closest / 1e6);
  std::printf("| bare Embree occlusion rays, random segments (M rays/s) | %.2f | %.2f |\n", embree[0].occlusion / 1e6,
              embree[1].occlusion / 1e6);
  std::printf("| bare Embree incoherent rays in packets of 8, rtcIntersect8 (M rays/s) | %.2f | %.2f |\n",
              embree[0].packets8 / 1e6, embree[1].packets8 / 1e6);
  std::printf("| bare Embree incoherent rays in packets of 16, rtcIntersect16 (M rays/s) | %.2f | %.2f |\n",
              embree[0].packets16 / 1e6, embree[1].packets16 / 1e6);
  std::printf("| bare Embree occlusion rays in packets of 16, rtcOccluded16 (M rays/s) | %.2f | %.2f |\n",
              embree[0].occlusion16 / 1e6, embree[1].occlusion16 / 1e6);
  std::printf("| path tracer (k samples/s) | %.1f | %.1f |\n", path[0].samplesPerSecond / 1e3, path[1].samplesPerSecond / 1e3);
  std::printf("| path tracer (M rays/s, incl. shadow rays) | %.2f | %.2f |\n", path[0].raysPerSecond / 1e6,
              path[1].raysPerSecond / 1e6);
  std::printf("| path tracer (M shadow rays/s, of those) | %.2f | %.2f |\n", path[0].shadowRaysPerSecond / 1e6,
              path[1].shadowRaysPerSecond / 1e6);
  std::printf("| path tracer / Embree ray rate | %.0f%% | %.0f%% |\n", 100 * path[0].raysPerSecond / embree[0].closest,
              100 * path[1].raysPerSecond / embree[1].closest);
  std::printf("| path tracer / Embree ceiling, each ray kind at its own rate | %.0f%% | %.0f%% |\n",
              100 * path[0].ofCeiling(embree[0]), 100 * path[1].ofCeiling(embree[1]));
  if (leastUnsupported.empty()) {
    std::printf("| least path loop: the same estimator on raw Embree, Lambertian only (k samples/s) | %.1f | %.1f |\n",
                least[0].samplesPerSecond / 1e3, least[1].samplesPerSecond / 1e3);
    auto perSample = [](const PathRate& r) {
      return std::make_pair((r.raysPerSecond - r.shadowRaysPerSecond) / r.samplesPerSecond, r.shadowRaysPerSecond / r.samplesPerSecond);
    };
    const auto [pathClosest, pathShadow] = perSample(path[0]);
    const auto [leastClosest, leastShadow] = perSample(least[0]);
    std::printf("| rays per sample, closest-hit + shadow: path tracer, least path loop | %.2f + %.2f, %.2f + %.2f | |\n",
                pathClosest, pathShadow, leastClosest, leastShadow);
    std::printf("| path tracer / least path loop | %.0f%% | %.0f%% |\n", 100 * path[0].samplesPerSecond / least[0].samplesPerSecond,
                100 * path[1].samplesPerSecond / least[1].samplesPerSecond);
    std::printf("| least path loop in 16 SIMD lanes, wavefront (k samples/s) | %.1f | %.1f |\n",
                leastSimd[0].samplesPerSecond / 1e3, leastSimd[1].samplesPerSecond / 1e3);
    std::printf("| 16 lanes / one path at a time | %.2fx | %.2fx |\n", leastSimd[0].samplesPerSecond / least[0].samplesPerSecond,
                leastSimd[1].samplesPerSecond / least[1].samplesPerSecond);
  } else {
    std::printf("| least path loop | (%s) | |\n", leastUnsupported.c_str());
  }
  // Spectral paths run one at a time: their cost is against RGB paths one at a time.
  std::printf("| path tracer one path at a time, --lanes off (k samples/s) | %.1f | %.1f |\n", scalar[0].samplesPerSecond / 1e3,
              scalar[1].samplesPerSecond / 1e3);
  std::printf("| path tracer in lanes / one path at a time | %.2fx | %.2fx |\n", path[0].samplesPerSecond / scalar[0].samplesPerSecond,
              path[1].samplesPerSecond / scalar[1].samplesPerSecond);
  std::printf("| path tracer, --spectral (k samples/s) | %.1f | %.1f |\n", spectral[0].samplesPerSecond / 1e3,
              spectral[1].samplesPerSecond / 1e3);
  std::printf("| spectral cost: RGB rate / spectral rate, both one path at a time | %.2fx | %.2fx |\n",
              scalar[0].samplesPerSecond / spectral[0].samplesPerSecond, scalar[1].samplesPerSecond / spectral[1].samplesPerSecond);
  std::printf("| photon tracing (M rays/s) | %.2f | %.2f |\n", trace[0].raysPerSecond / 1e6, trace[1].raysPerSecond / 1e6);
  std::printf("| photon tracing (M stored photons/s) | %.2f | %.2f |\n", trace[0].photonsPerSecond / 1e6,
              trace[1].photonsPerSecond / 1e6);
  std::printf("| photon tracing / Embree ray rate | %.0f%% | %.0f%% |\n", 100 * trace[0].raysPerSecond / embree[0].closest,
              100 * trace[1].raysPerSecond / embree[1].closest);

  // A map of about 10 million photons: build time and gathers.
  PhotonTracingOptions o;
  o.globalPaths = uint64_t(10e6 / 1.8);  // ~1.8 photons stored per emitted path in the Cornell box
  o.causticPaths = 0;
  o.threads = all;
  PhotonMaps maps = tracePhotons(*scene, o);
  std::vector<Photon> photons = maps.global.photons();
  double build = bestOf5([&] {
    std::vector<Photon> copy = photons;
    auto t0 = std::chrono::steady_clock::now();
    PhotonMap m;
    m.build(std::move(copy));
    return -seconds(t0);  // best = shortest
  });
  build = -build;
  std::printf("| kd-tree build, %.1f M photons (s) | %.2f | (single-threaded) |\n", photons.size() / 1e6, build);
  std::printf("| kd-tree build per million photons (s) | %.3f | |\n", build / (photons.size() / 1e6));
  GatherRate g1 = gatherRate(*scene, maps.global, 1), gN = gatherRate(*scene, maps.global, all);
  std::printf("| k=50 gathers, pixel order (k/s) | %.1f | %.1f |\n", g1.pixelOrder / 1e3, gN.pixelOrder / 1e3);
  std::printf("| k=50 gathers, random order (k/s) | %.1f | %.1f |\n", g1.randomOrder / 1e3, gN.randomOrder / 1e3);
  std::printf("| memory per photon, map + tree (bytes) | %.1f | |\n", double(maps.global.memoryBytes()) / maps.global.size());

  // The mirror-and-glass Cornell box, where the path tracer is compared with Mitsuba 3's (docs: results/mitsuba.md,
  // Performance): its rates, and the error its image has after 10 s on every thread.
  {
    auto glass = loadGltf(glassScenePath);
    PathRate rate[2];
    EmbreeRates ceiling[2];
    for (int round = 0; round < 5; ++round)
      for (int c = 0; c < 2; ++c) {
        keepBestRates(ceiling[c], embreeRaysPerSecond(*glass, columns[c]));
        keepBest(rate[c], pathTracerRate(*glass, columns[c], spp));
      }
    const auto [relmse, relmseSpp] = equalTimeRelMSE(*glass, all, 256, 10.0);
    std::printf("\n| path tracer on %s (%zu triangles), 256x256 | 1 thread | %d threads |\n|---|---|---|\n",
                std::filesystem::path(glassScenePath).filename().string().c_str(), glass->triangleCount(), all);
    std::printf("| samples/s (M) | %.3f | %.3f |\n", rate[0].samplesPerSecond / 1e6, rate[1].samplesPerSecond / 1e6);
    std::printf("| rays per sample: closest-hit, shadow | %.2f, %.2f | |\n",
                (rate[0].raysPerSecond - rate[0].shadowRaysPerSecond) / rate[0].samplesPerSecond,
                rate[0].shadowRaysPerSecond / rate[0].samplesPerSecond);
    std::printf("| path tracer / Embree ceiling, each ray kind at its own rate | %.0f%% | %.0f%% |\n",
                100 * rate[0].ofCeiling(ceiling[0]), 100 * rate[1].ofCeiling(ceiling[1]));
    std::printf("| relMSE after 10 s (two independent 5 s renders, no reference) | | %.4f (%d spp) |\n", relmse, relmseSpp);
  }

  // Progressive photon mapping at 512² with 1 million photon paths per pass (all threads).
  std::printf("\n| progressive, 512x512, 1M photons/pass, %d threads | passes/s | M photons/s |\n|---|---|---|\n", all);
  for (const char* name : {"ppm", "sppm", "pppm"}) {
    RenderOptions ro;
    ro.width = ro.height = 512;
    ro.threads = all;
    ParamSet params = integratorEntry(name).defaults();
    params.setNumber("passes", 3);
    params.setNumber("photons_per_pass", 1000000);
    auto integrator = makeIntegrator(name, params, ro);
    RenderInfo info;
    integrator->render(*scene, ro, &info);
    std::printf("| %s | %.3f | %.2f |\n", name, info.passes / info.seconds, info.photons / info.seconds / 1e6);
  }

  // Radiosity's solve (meshing, form factors, Gauss-Seidel) at two patch budgets, all threads.
  std::printf("\n| radiosity, %d threads | patches | mesh (s) | form factors (s) | M visibility rays/s | Gauss-Seidel (s) | total (s) | "
              "matrix (MB) |\n|---|---|---|---|---|---|---|---|\n",
              all);
  for (int budget : {2500, 10500}) {
    RenderOptions ro;
    ro.width = ro.height = 16;
    ro.spp = 1;
    ro.threads = all;
    ParamSet params = integratorEntry("radiosity").defaults();
    params.setNumber("patches", budget);
    params.setNumber("spp", 1);
    auto integrator = makeIntegrator("radiosity", params, ro);
    integrator->render(*scene, ro, nullptr);
    auto* radiosity = dynamic_cast<RadiosityIntegrator*>(integrator.get());
    const auto& st = radiosity->stats();
    std::printf("| budget %d | %zu | %.2f | %.2f | %.1f | %.2f | %.2f | %.0f |\n", budget, radiosity->mesh().size(), st.meshSeconds,
                st.formFactorSeconds, st.rays / st.formFactorSeconds / 1e6, st.solveSeconds,
                st.meshSeconds + st.formFactorSeconds + st.solveSeconds, st.matrixBytes / 1e6);
  }
  return 0;
}

namespace {

// This process's resident memory now and at its peak (VmRSS, VmHWM), in bytes.
void residentMemory(uint64_t* now, uint64_t* peak) {
  std::ifstream f("/proc/self/status");
  std::string line;
  *now = *peak = 0;
  while (std::getline(f, line)) {
    if (line.rfind("VmRSS:", 0) == 0) *now = std::stoull(line.substr(6)) * 1024;
    if (line.rfind("VmHWM:", 0) == 0) *peak = std::stoull(line.substr(6)) * 1024;
  }
}

// The file's geometry: the bytes of the elements of every accessor a mesh primitive uses
// (attributes and indices), each accessor counted once.
uint64_t geometryBytes(const std::string& path) {
  // A .glb's JSON chunk (its header's 20 bytes tell where it ends), or the whole .gltf.
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) throw Error(path + ": cannot open");
  const uint64_t size = uint64_t(f.tellg());
  f.seekg(0);
  char header[20] = {};
  f.read(header, 20);
  uint64_t offset = 0, length = size;
  if (f.gcount() == 20 && std::memcmp(header, "glTF", 4) == 0) {
    uint32_t chunk;
    std::memcpy(&chunk, header + 12, 4);
    offset = 20, length = std::min<uint64_t>(chunk, size - 20);
  }
  std::string json(size_t(length), '\0');
  f.clear();
  f.seekg(std::streamoff(offset));
  f.read(json.data(), std::streamsize(length));
  const nlohmann::json doc = nlohmann::json::parse(json);
  std::set<int> used;
  const nlohmann::json meshes = doc.value("meshes", nlohmann::json::array());
  for (const auto& mesh : meshes) {
    const nlohmann::json primitives = mesh.value("primitives", nlohmann::json::array());
    for (const auto& prim : primitives) {
      const nlohmann::json attributes = prim.value("attributes", nlohmann::json::object());
      for (const auto& [name, index] : attributes.items()) used.insert(index.get<int>());
      if (prim.contains("indices")) used.insert(prim["indices"].get<int>());
    }
  }
  uint64_t total = 0;
  for (int i : used) {
    const auto& a = doc["accessors"][size_t(i)];
    const int ct = a["componentType"].get<int>();
    const int size = ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 4;
    const std::string type = a["type"].get<std::string>();
    const int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
    total += a["count"].get<uint64_t>() * size * components;
  }
  return total;
}

}  // namespace

// `photonlab bench --load FILE`: how fast a glTF file loads (parse, meshes, BVH: until the scene
// can be traced) and the memory the load takes at its peak, against the file's geometry.
int runLoadBench(const std::string& path, int repeats, Scene::BvhLayout bvh) {
  const uint64_t geometry = geometryBytes(path);
  double best = 1e30;
  uint64_t worstPeak = 0;
  size_t triangles = 0, stored = 0, paired = 0;
  bool compact = false;
  for (int r = 0; r < repeats; ++r) {
    // Reset the peak (VmHWM) to the present: each load's own peak, over what the process held
    // before it (the libraries, ~125 MB with OpenImageIO's).
    // Free heap pages go back to the system first, so that the load cannot reuse them unseen.
    malloc_trim(0);
    { std::ofstream("/proc/self/clear_refs") << "5"; }
    uint64_t before, peak, now;
    residentMemory(&before, &peak);
    auto t0 = std::chrono::steady_clock::now();
    GltfLoadOptions options;
    options.bvh = bvh;
    std::vector<std::string> warnings;
    auto scene = loadGltf(path, &warnings, options);
    best = std::min(best, seconds(t0));
    residentMemory(&now, &peak);
    worstPeak = std::max(worstPeak, peak - before);
    triangles = scene->triangleCount();
    stored = scene->storedTriangleCount();
    compact = scene->compactBvh();
    paired = scene->pairedTriangleCount();
  }
  std::printf("photonlab bench --load: %s, best of %d\n\n", path.c_str(), repeats);
  std::printf("| measure | value |\n|---|---|\n");
  std::printf("| triangles (stored) | %zu (%zu) |\n", triangles, stored);
  std::printf("| geometry in the file (MB) | %.1f |\n", geometry / 1e6);
  if (compact) std::printf("| BVH | compact, %zu stored triangles paired into quads |\n", paired);
  else std::printf("| BVH | fast |\n");
  std::printf("| load, until the scene can be traced (s) | %.2f |\n", best);
  std::printf("| load rate (M triangles/s) | %.2f |\n", triangles / best / 1e6);
  std::printf("| peak memory of the load (MB) | %.1f |\n", worstPeak / 1e6);
  std::printf("| peak memory / geometry | %.2fx |\n", double(worstPeak) / double(geometry));
  return 0;
}

}  // namespace pl
