// Pass 1 of photon mapping (Jensen 1996): photons leave the lights in proportion to their
// power, scatter by BSDF sampling with Russian roulette, and are stored at every non-specular
// hit. Counts are *emitted paths*, not stored photons: each photon carries Φ_light/(pmf · N),
// so the stored flux is an unbiased estimate of the light arriving at the surfaces.
#pragma once
#include "core/rng.h"
#include "photon/photon_map.h"

namespace pl {

// Emission aimed at what the camera sees (--photon-target view). A light at infinity (a
// sky, the sun) emits over the disc covering the whole scene, so a model in view that is small
// against the scene receives few of its photons. With a target, a fraction q of such photons
// start on the disc covering the target sphere instead (the region the camera sees), the rest
// on the scene's disc; each photon's flux is divided by the mixture's area density
//   p(y) = q·1[y ∈ D_T]/(π r_T²) + (1 − q)·1[y ∈ D_S]/(π R²)
// over the plane of origins (one-sample MIS, balance heuristic: Veach 1997, §9.2.4), so the map
// stays unbiased everywhere, the part out of view included.
struct EmissionTarget {
  Vec3 center{0.0f};
  float radius = 0.0f;    // 0: no target, uniform emission
  float fraction = 0.5f;  // q
  bool active() const { return radius > 0 && fraction > 0; }
};

struct PhotonTracingOptions {
  uint64_t globalPaths = 200000;   // emitted paths for the global map (--photons)
  uint64_t causticPaths = 200000;  // emitted paths for the caustic map (--caustic-photons)
  uint64_t seed = 1;
  int threads = 0;
  int maxDepth = 64;
  // Photons carry wavelengths (spectral/spectral.h) while they are traced, and are stored with
  // the linear-sRGB value of their flux: gathers stay in RGB.
  bool spectral = false;
  // Polled between chunks of 4096 paths and inside the kd-tree build: when it expires the maps
  // are left incomplete (PhotonMaps::complete = false) and empty.
  const Budget* budget = nullptr;
  EmissionTarget target;  // for lights at infinity only
  // The path types stored (Photon::kAccept*): an estimator that never gathers a type (sppm's
  // and pppm's direct photons: their direct light is MIS) keeps its map and kd-tree smaller.
  // The paths and their random draws are the same whatever is stored.
  uint8_t store = Photon::kAcceptAll;
};

struct PhotonMaps {
  // Global map: every photon stored at a diffuse or glossy surface, typed kDirect for paths
  // L D, kCaustic for L S+ D, kIndirect otherwise. Caustic map: only L S+ D, from its own
  // emission.
  PhotonMap global, caustic;
  bool complete = true;  // false: the budget expired (or an interrupt came) before the maps were built
  uint64_t rays = 0;  // rays traced, for benchmarks
  double traceSeconds = 0, buildSeconds = 0;
};

// Emits photon path `index` of `count` (for tests and the tracer): E[flux] = total power / count.
// With `spectral`, the photon's wavelengths come first from its stream (into *lambda).
EmittedRay emitPhoton(const Scene& scene, uint64_t seed, uint64_t index, uint64_t count, uint64_t stream, Rng* rng,
                      bool spectral = false, SampledWavelengths* lambda = nullptr, const EmissionTarget* target = nullptr);

// Moves the origin of a ray emitted by a light at infinity (origin on the scene's disc, travel
// direction e->ray.d) to a sample of EmissionTarget's mixture and reweights its flux. Draws a
// 1D and a 2D number.
void retargetEmission(const Scene& scene, const EmissionTarget& target, float uPick, const Vec2& uDisc, EmittedRay* e);

PhotonMaps tracePhotons(const Scene& scene, const PhotonTracingOptions& options);

}  // namespace pl
