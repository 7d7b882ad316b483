// Pass 1 of photon mapping (Jensen 1996): photons leave the lights in proportion to their
// power, scatter by BSDF sampling with Russian roulette, and are stored at every non-specular
// hit. Counts are *emitted paths*, not stored photons: each photon carries Φ_light/(pmf · N),
// so the stored flux is an unbiased estimate of the light arriving at the surfaces.
#pragma once
#include "core/rng.h"
#include "photon/hash_grid.h"
#include "photon/photon_map.h"

namespace pl {

// Emission aimed at what the camera sees (--photon-target view). A light at infinity (a
// sky, the sun) emits over the disc covering the whole scene, so a model in view that is small
// against the scene receives few of its photons; a large area light spreads its photons over
// its whole hemisphere. With a target, a fraction q of an area light's photons leave towards the
// target sphere (retargetAreaEmission), and a fraction q of the photons from lights at infinity
// start on the disc covering the target sphere instead (the region the camera sees), the rest
// on the scene's disc; each photon's flux is divided by the mixture's area density
//   p(y) = q·1[y ∈ D_T]/(π r_T²) + (1 − q)·1[y ∈ D_S]/(π R²)
// over the plane of origins (one-sample MIS, balance heuristic: Veach 1997, §9.2.4), so the map
// stays unbiased everywhere, the part out of view included.
struct EmissionTarget {
  Vec3 center{0.0f};
  float radius = 0.0f;    // 0: no target, uniform emission
  float fraction = 0.5f;  // q
  bool areaLights = false;  // area lights aimed too (--aim-area-lights on)
  bool active() const { return radius > 0 && fraction > 0; }
};

// What the camera sees, as the photons' visibility function V of robust adaptive photon tracing
// (Hachisuka & Jensen 2011): a photon path is visible when one of the photons it stores lies
// inside the gather sphere of one of the visible points a pass gathers at.
class PhotonVisibility {
 public:
  struct Sphere {
    Vec3 p;
    float r2;  // the point's squared gather radius
  };
  explicit PhotonVisibility(const std::vector<Sphere>& spheres);
  bool contains(const Vec3& x) const;

 private:
  HashGrid<Sphere> grid_;  // cells from the largest radius; each sphere's own radius is tested
};

// Robust adaptive photon tracing (Hachisuka & Jensen 2011): photon paths as points u of the
// primary sample space [0,1)^∞ (Kelemen et al. 2002), sampled by a Markov chain whose stationary
// density is V(u)/V_c, V_c = ∫V. Each iteration draws a uniform u (the uniform tracer's own path);
// if it is visible the chain takes it (replica exchange with the uniform chain), otherwise
// the chain proposes its state moved by up to ±d per coordinate (wrapping around) and keeps it
// if visible. d is fixed within a trace, so that every state is a sample of V/V_c; the caller
// adapts it between traces towards the acceptance rate 0.234 (Andrieu & Thoms 2008). (A d
// adapted within the chain depends on its past: it shrinks where proposals fail and keeps the
// chain there, so the states are no longer samples of V/V_c.) The
// state's photons are stored every iteration; the map's flux scale V̂_c·N/N_chain, with V̂_c the
// uniform draws' visible fraction, makes it estimate what the uniform map does, where
// the camera sees. Each chunk of 4096 iterations is a chain of its own, started at its first
// visible uniform path (a rejection sample of V/V_c: no burn-in), so the map is the same
// whatever the thread count.
struct AdaptiveChainStats {
  uint64_t uniform = 0, visible = 0;  // uniform paths drawn, and those visible
  uint64_t samples = 0;               // iterations with a chain state (its photons stored)
  uint64_t mutations = 0, accepted = 0;
  void add(const AdaptiveChainStats& o) {
    uniform += o.uniform, visible += o.visible, samples += o.samples, mutations += o.mutations, accepted += o.accepted;
  }
  double visibleFraction() const { return uniform ? double(visible) / double(uniform) : 0.0; }
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
  // Given: the global map's paths come from the adaptive chain towards this visibility (its
  // `globalPaths` iterations each draw a uniform path and may draw a mutation).
  const PhotonVisibility* adaptive = nullptr;
  float mutationSize = 0.1f;  // the adaptive chain's d
};

struct PhotonMaps {
  // Global map: every photon stored at a diffuse or glossy surface, typed kDirect for paths
  // L D, kCaustic for L S+ D, kIndirect otherwise. Caustic map: only L S+ D, from its own
  // emission.
  PhotonMap global, caustic;
  bool complete = true;  // false: the budget expired (or an interrupt came) before the maps were built
  uint64_t rays = 0;  // rays traced, for benchmarks
  AdaptiveChainStats chain;  // with adaptive sampling
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

// Aims a ray emitted by an area light at EmissionTarget's sphere: with probability q its
// direction is drawn uniformly in the cone from its origin around the sphere (when the origin
// lies outside it), otherwise kept as the light drew it. The flux is multiplied by the light's
// own direction density over the mixture's,
//   p(ω) = q·1[ω ∈ cone]/Ω_cone + (1 − q)·p_light(ω)
// (one-sample MIS, balance heuristic, as retargetEmission), which is exact for emission that
// does not depend on direction (Lambertian, as every area light here). Draws a 1D and a 2D number.
void retargetAreaEmission(const Light& light, const EmissionTarget& target, float uPick, const Vec2& uCone, EmittedRay* e);

PhotonMaps tracePhotons(const Scene& scene, const PhotonTracingOptions& options);

}  // namespace pl
