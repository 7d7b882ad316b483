// Pass 1 of photon mapping (Jensen 1996): photons leave the lights in proportion to their
// power, scatter by BSDF sampling with Russian roulette, and are stored at every non-specular
// hit. Counts are *emitted paths*, not stored photons: each photon carries Φ_light/(pmf · N),
// so the stored flux is an unbiased estimate of the light arriving at the surfaces.
#pragma once
#include "core/rng.h"
#include "photon/photon_map.h"

namespace pl {

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
                      bool spectral = false, SampledWavelengths* lambda = nullptr);

PhotonMaps tracePhotons(const Scene& scene, const PhotonTracingOptions& options);

}  // namespace pl
