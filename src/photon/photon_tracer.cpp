#include "photon/photon_tracer.h"

#include <atomic>
#include <chrono>

#include "core/frame.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/roulette.h"
#include "core/sampling.h"
#include "spectral/spectral.h"
#include "transport/light_walk.h"

namespace pl {

namespace {

constexpr uint64_t kGlobalStream = 0x67bd, kCausticStream = 0xca57, kChainStream = 0xada9;

// Photon path `index`'s own stream of random numbers, for the map `stream` (global or caustic).
Rng photonStream(uint64_t seed, uint64_t stream, uint64_t index) {
  return Rng::hashed(mix64(seed ^ (stream << 32) ^ stream), index);
}

}  // namespace

// A photon's emission from `draws`: its wavelengths (1D), the light and its ray (emitLight), and
// with a target the retargeting (1D, 2D). E[flux] = total power / count.
template <class Draws>
EmittedRay emitPhotonFrom(const Scene& scene, Draws& draws, uint64_t count, bool spectral, SampledWavelengths* lambda,
                          const EmissionTarget* target) {
  *lambda = spectral ? SampledWavelengths::sample(draws.get1D()) : SampledWavelengths();
  LightEmission emitted = emitLight(scene, draws, *lambda);
  if (!emitted.light) return emitted.e;
  if (target && (emitted.light->isInfinite() || emitted.light->isDeltaDirection())) {
    const float uPick = draws.get1D();
    retargetEmission(scene, *target, uPick, draws.get2D(), &emitted.e);
  } else if (target && target->areaLights && !emitted.light->isDelta()) {  // an area light
    const float uPick = draws.get1D();
    retargetAreaEmission(*emitted.light, *target, uPick, draws.get2D(), &emitted.e);
  }
  emitted.e.flux *= 1.0f / (emitted.pick * float(count));  // one division, not three
  return emitted.e;
}

namespace {

// Traces one photon path (transport/light_walk.h) from its emitted ray, every further random
// number from `draws`, appending what it stores. In caustic mode the path ends at the first
// non-specular hit and is stored only if it went through at least one specular bounce.
template <class Draws>
[[gnu::flatten]] void tracePath(const Scene& scene, const PhotonTracingOptions& o, const EmittedRay& e, SampledWavelengths& lambda,
                                Draws& draws, bool causticMode, std::vector<Photon>* out) {
  if (isBlack(e.flux) || !isFinite(e.flux)) return;
  struct Walker {
    const PhotonTracingOptions& o;
    const SampledWavelengths& lambda;
    Draws& draws;
    bool causticMode;
    std::vector<Photon>* out;
    Spectrum flux;
    bool onlySpecular = true;
    // What a stored photon carries: in spectral mode the XYZ of its wavelengths' values (the map
    // converts to linear sRGB when it reads them), so that gathers are the same in both modes.
    Spectrum stored() const { return o.spectral ? spectralToXYZ(flux, lambda.lambda) : flux; }
    void attenuate(const Spectrum& transmittance) { flux *= transmittance; }
    bool vertex(const SurfaceHit& hit, const Vec3& wo, int length) {
      if (!hit.bsdf->isSpecular()) {
        // kDirect at the first hit, kCaustic after specular bounces only, kIndirect otherwise;
        // in integer arithmetic, since length == 1 is unpredictable.
        bool first = length == 1;
        auto type = Photon::Type(first * Photon::kDirect + (!first & onlySpecular) * Photon::kCaustic);
        if (causticMode) {
          if (type == Photon::kCaustic) out->push_back(Photon(hit.p, wo, stored(), type, draws.get1D()));
          return false;
        }
        const float dither = draws.get1D();
        if ((o.store >> type) & 1) out->push_back(Photon(hit.p, wo, stored(), type, dither));
        onlySpecular = false;
      }
      return length <= o.maxDepth;  // maxDepth bounces: photons at up to maxDepth + 1 hits
    }
    bool scattered(const SurfaceHit&, const LightScatter& s, int, Draws& d) {
      // Russian roulette by albedo (core/roulette.h), at every bounce.
      const float q = roulette::albedo(maxComponent(s.bs.weight));
      if (!roulette::survives(q, [&] { return d.get1D(); })) return false;
      flux *= s.bs.weight * (1.0f / q);
      return isFinite(flux);  // a non-finite BSDF weight ends the path: it never reaches a map
    }
  } walker{o, lambda, draws, causticMode, out, e.flux};
  walkLightPath(scene, e.ray, draws, lambda, ShadingCheck::kWhereNormalsDiffer, walker);
}

// Photon path `index` of `count` from its own stream (seed, map, index).
void tracePath(const Scene& scene, const PhotonTracingOptions& o, uint64_t index, uint64_t count, bool causticMode,
               std::vector<Photon>* out) {
  Rng rng(0);
  SampledWavelengths lambda;
  EmittedRay e = emitPhoton(scene, o.seed, index, count, causticMode ? kCausticStream : kGlobalStream, &rng, o.spectral, &lambda,
                            o.target.active() ? &o.target : nullptr);
  StreamDraws draws{rng};
  tracePath(scene, o, e, lambda, draws, causticMode, out);
}

// A photon path's random numbers as a point u of the primary sample space, drawn lazily
// (Kelemen et al. 2002): fresh from `rng`, or, for a proposal, the chain state's coordinate moved
// by up to ±size and wrapped into [0, 1) (the state's coordinates the proposal does not reach are
// dropped: V and the path do not depend on them, so they stay uniform). `u` records them. Drawn
// from an empty base, the path is the uniform tracer's, number for number (StreamDraws' order).
struct PrimarySample {
  Rng& rng;
  const std::vector<float>* base = nullptr;
  float size = 0.0f;
  std::vector<float> u;
  float get1D() {
    float x = rng.uniform();
    const size_t k = u.size();
    if (base && k < base->size()) {
      x = (*base)[k] + size * (2.0f * x - 1.0f);
      x -= std::floor(x);
      if (x >= 1.0f) x = 0.0f;  // −ε wraps to 1 − ε, which may round to 1
    }
    u.push_back(x);
    return x;
  }
  Vec2 get2D() {
    const float y = get1D();
    return Vec2(get1D(), y);
  }
};

// Iterations [begin, end) of the adaptive chain (PhotonVisibility, AdaptiveChainStats): appends
// the state's photons at every iteration that has a state.
void traceChain(const Scene& scene, const PhotonTracingOptions& o, uint64_t begin, uint64_t end, uint64_t count,
                std::vector<Photon>* out, AdaptiveChainStats* st) {
  const PhotonVisibility& visibility = *o.adaptive;
  const EmissionTarget* target = o.target.active() ? &o.target : nullptr;
  Rng chainRng = photonStream(o.seed, kChainStream, begin);
  std::vector<float> state;
  std::vector<Photon> statePhotons, trial;
  bool hasState = false;
  const float size = o.mutationSize;  // fixed within the chain: its kernel leaves V/V_c invariant
  auto trace = [&](PrimarySample& u) {  // V(u): does a stored photon land in a visible point's sphere
    trial.clear();
    SampledWavelengths lambda;
    const EmittedRay e = emitPhotonFrom(scene, u, count, o.spectral, &lambda, target);
    tracePath(scene, o, e, lambda, u, false, &trial);
    for (const Photon& ph : trial)
      if (visibility.contains(ph.p())) return true;
    return false;
  };
  for (uint64_t i = begin; i < end; ++i) {
    Rng rng = photonStream(o.seed, kGlobalStream, i);
    PrimarySample uniform{rng};
    ++st->uniform;
    if (trace(uniform)) {  // replica exchange: the uniform chain's state is visible, the chains swap
      ++st->visible;
      state.swap(uniform.u);
      statePhotons.swap(trial);
      hasState = true;
    } else if (hasState) {
      PrimarySample proposal{chainRng, &state, size};
      const bool accepted = trace(proposal);
      ++st->mutations;
      if (accepted) {
        ++st->accepted;
        state.swap(proposal.u);
        statePhotons.swap(trial);
      }
    }
    if (hasState) {
      out->insert(out->end(), statePhotons.begin(), statePhotons.end());
      ++st->samples;
    }
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
  // Buffers are allocated by this thread, before the workers trace into them: allocated by the
  // workers, they came from glibc's per-thread arenas, whose growth and trimming (mprotect,
  // madvise) serialise with the other thread's page faults. They are allocated a wave at a time
  // (256 chunks per thread), not all at once: each is an mmap of its own, and reserving (and
  // freeing) a large map's buffers up front would run past a budget (docs: Performance).
  const int threads = resolveThreads(o.threads);
  const size_t wave = 256 * size_t(threads);
  std::atomic<bool> stopped{false};
  const bool adaptive = o.adaptive && !causticMode;
  std::vector<AdaptiveChainStats> chainStats(adaptive ? chunks : 0);
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
      if (adaptive)
        traceChain(scene, o, c * chunkSize, end, count, &photons, &chainStats[c]);
      else
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
  if (adaptive) {
    for (const AdaptiveChainStats& c : chainStats) stats->chain.add(c);
    const AdaptiveChainStats& c = stats->chain;
    // Φ = V̂_c·(1/N_chain)·Σ f(u_j) over the chain, each photon stored with f/count.
    if (c.samples) map.setFluxScale(float(c.visibleFraction() * double(count) / double(c.samples)));
  }
  stats->buildSeconds += since(t1);
  return map;
}

}  // namespace

PhotonVisibility::PhotonVisibility(const std::vector<Sphere>& spheres) {
  float r2 = 0.0f;
  for (const Sphere& s : spheres) r2 = std::max(r2, s.r2);
  // No sphere with a radius: an empty grid, in which nothing is visible.
  grid_.build(r2 > 0 ? spheres : std::vector<Sphere>(), std::sqrt(r2));
}

bool PhotonVisibility::contains(const Vec3& x) const {
  bool inside = false;
  grid_.query(x, [&](const Sphere& s) {
    const Vec3 d = s.p - x;
    inside |= glm::dot(d, d) <= s.r2;
  });
  return inside;
}

void retargetEmission(const Scene& scene, const EmissionTarget& target, float uPick, const Vec2& uDisc, EmittedRay* e) {
  // The lights at infinity emit from the plane one scene radius R before the scene's centre c,
  // perpendicular to the travel direction w, over the disc of radius R around c − wR
  // (lights/environment_light.cpp, directional_light.cpp; both preprocessed with these c, R).
  const Vec3 w = e->ray.d;
  const Vec3 c = scene.bounds().center();
  const float R = std::max(scene.bounds().radius(), 1e-3f);
  const Vec3 sceneDisc = c - w * R;
  const Vec3 targetDisc = target.center - w * glm::dot(target.center - sceneDisc, w);  // projected onto the plane
  const float q = target.fraction, r = target.radius;
  Vec3 y = e->ray.o;
  if (uPick < q) {
    const Frame frame(w);
    const Vec2 d = sampleConcentricDisc(uDisc) * r;
    y = targetDisc + frame.s * d.x + frame.t * d.y;
  }
  auto inside = [](const Vec3& p, const Vec3& centre, float radius) {
    const Vec3 v = p - centre;
    return glm::dot(v, v) <= radius * radius * 1.0001f;  // the light's own samples lie on the rim up to rounding
  };
  const float pdf = (inside(y, targetDisc, r) ? q / (kPi * r * r) : 0.0f) + (inside(y, sceneDisc, R) ? (1 - q) / (kPi * R * R) : 0.0f);
  // pdf > 0: y was drawn from one of the two discs.
  e->flux *= (1.0f / (kPi * R * R)) / pdf;
  e->ray.o = y;
  e->pdfPos = pdf;
}

void retargetAreaEmission(const Light& light, const EmissionTarget& target, float uPick, const Vec2& uCone, EmittedRay* e) {
  const Vec3 y = e->ray.o, toCentre = target.center - y;
  const float d2 = glm::dot(toCentre, toCentre), r2 = target.radius * target.radius;
  if (!(d2 > r2)) return;  // inside the target sphere: every direction may reach it; no cone
  const float sin2 = r2 / d2, cosMax = std::sqrt(std::max(0.0f, 1.0f - sin2));
  const float solidAngle = 2.0f * kPi * sin2 / (1.0f + cosMax);  // 2π(1 − cosθmax), without cancellation
  const Frame cone(toCentre / std::sqrt(d2));
  const float q = target.fraction;
  Vec3 w = e->ray.d;
  if (uPick < q) w = cone.toWorld(sampleUniformCone(uCone, cosMax));
  float pdfPos, pdfDir;
  light.pdfLe(Ray{y, w}, e->n, &pdfPos, &pdfDir);
  const float pdf = (glm::dot(w, cone.n) >= cosMax ? q / solidAngle : 0.0f) + (1 - q) * pdfDir;
  // The light's flux is Le·cosθ/(p_A·p_light(ω)) for its own ω; for any ω it emits towards,
  // Le·cosθ/(p_A·p(ω)) = flux·p_light(ω)/p(ω). A direction it does not emit towards carries nothing.
  e->flux = pdfDir > 0 && pdf > 0 ? e->flux * (pdfDir / pdf) : Spectrum(0.0f);
  e->ray.d = w;
  e->pdfDir = pdf;
}

EmittedRay emitPhoton(const Scene& scene, uint64_t seed, uint64_t index, uint64_t count, uint64_t stream, Rng* rng,
                      bool spectral, SampledWavelengths* lambda, const EmissionTarget* target) {
  *rng = photonStream(seed, stream, index);
  SampledWavelengths own;
  StreamDraws draws{*rng};
  return emitPhotonFrom(scene, draws, count, spectral, lambda ? lambda : &own, target);
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
