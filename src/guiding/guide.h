// What a guided path tracer asks of a guide: a directional distribution of incident light at a
// point. Two guides exist, each in its own file:
//   SDTreeGuide   learned from the render's own paths (Müller, Gross, Novák 2017);
//   PhotonGuide   built from photons' incident directions (Jensen 1995).
// The integrator (integrators/guided.cpp) renders in iterations; before iteration k it calls
// prepare(k), which gives the guide its distribution for that iteration: the SD-tree refines
// what iteration k − 1 recorded, the photon guide traces a fresh photon map.
#pragma once
#include <memory>
#include <string>

#include "core/budget.h"
#include "guiding/directional_quadtree.h"
#include "scene/scene.h"

namespace pl {

// The guide at one point: its distribution (empty() where nothing is known) and which cached
// distribution it is, for recording into the same one without looking it up again.
struct GuideLookup {
  const DirectionalQuadtree* distribution;
  uint32_t leaf;
};

class Guide {
 public:
  virtual ~Guide() = default;
  // Before iteration k (0, 1, 2, ...). `samples` is the iteration's samples per pixel and
  // `last` says that nothing will be recorded after it. Deterministic for a seed, polls the budget.
  virtual void prepare(const Scene& scene, int iteration, int samples, bool last, uint64_t seed, int threads,
                       const Budget& budget) = 0;
  // The distribution of light arriving at p on the side of the surface that `side` (the
  // geometric normal turned towards where the path came from) points to.
  virtual GuideLookup at(const Vec3& p, const Vec3& side) const = 0;
  // Whether this iteration's paths should record() what they found.
  virtual bool learns() const { return false; }
  // One estimate of incident radiance at the point `at` found leaf for, from direction wi
  // (world), divided by the density the direction was sampled with: L_i(x, ωi)/p(ωi) ≥ 0, the
  // Monte Carlo estimate of the energy of the directional cell holding ωi. Every thread calls it
  // at once, each with its own index (< the `threads` prepare() was given).
  virtual void record(uint32_t leaf, const Vec3& wi, float radianceOverPdf, int thread) {}
  // For the render's notes: the size of the distribution ("412 leaves, 38k cells").
  virtual std::string describe() const = 0;
};

// Which of six sides a surface point faces: the dominant axis of its normal and that axis'
// sign (0: +x, 1: −x, 2: +y, ...). A spatial cell keeps one distribution per side, so that the
// two faces of a wall or a door in one cell (light on one side, shadow on the other) never
// share one: a distribution learned on the lit face would send half the unlit face's
// directions into the wall.
inline int sideOf(const Vec3& n) {
  Vec3 a = glm::abs(n);
  int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  return 2 * axis + (n[axis] < 0);
}
constexpr int kSides = 6;

struct GuideOptions {
  // sdtree: a leaf splits when one iteration recorded more than c·√spp directions in it (spp:
  // the iteration's); Müller et al.'s c = 12000. It counts records, so it holds at any image
  // size: each directional tree is learned from at least that many.
  double spatialThreshold = 12000;
  // sdtree: a distribution guides only once learned from at least this many records.
  double minRecords = 1000;
  float directionalThreshold = 0.01f;  // ρ: a cell with more than this share of the energy splits
  int directionalDepth = 20;
  // photons: emitted photon paths for the first iteration's map (doubling with each iteration),
  // and the nearest photons each distribution is built from.
  uint64_t photons = 100000;
  int photonsPerDistribution = 256;
  int maxDepth = 64;
  bool spectral = false;
};

std::unique_ptr<Guide> makeSDTreeGuide(const Scene& scene, const GuideOptions& options);  // guiding/sd_tree.cpp
std::unique_ptr<Guide> makePhotonGuide(const Scene& scene, const GuideOptions& options);  // guiding/photon_guide.cpp

}  // namespace pl
