// Photons in a nanoflann kd-tree, with the radiance estimate of Jensen's photon mapping:
//   L(x, ωo) ≈ Σ_p f(ωo, ωp) Φp K(|x − xp|)
// (no extra cosine: the photon's flux already carries it). Photons that arrived at the other
// side of the surface are rejected inside the search, so they never shrink a k-NN radius.
#pragma once
#include <atomic>
#include <memory>
#include <vector>

#include "core/budget.h"
#include "photon/kernels.h"
#include "photon/photon.h"
#include "scene/scene.h"

namespace pl {

struct Neighbour {
  uint32_t index;
  float d2;
};

// One flag per photon of a map, set by the gathers that find it (from any thread): how many of
// a pass's photons landed near a visible point, the visibility Hachisuka & Jensen (2011) plot.
class PhotonMarks {
 public:
  explicit PhotonMarks(size_t n) : flags_(new std::atomic<uint8_t>[n]), n_(n) {
    for (size_t i = 0; i < n; ++i) flags_[i].store(0, std::memory_order_relaxed);
  }
  void mark(size_t i) { flags_[i].store(1, std::memory_order_relaxed); }
  size_t count() const {
    size_t c = 0;
    for (size_t i = 0; i < n_; ++i) c += flags_[i].load(std::memory_order_relaxed);
    return c;
  }

 private:
  std::unique_ptr<std::atomic<uint8_t>[]> flags_;
  size_t n_;
};

struct GatherStats {
  int photons = 0;   // photons that contributed
  float radius = 0;  // gather radius used
  PhotonMarks* marks = nullptr;  // given: the photons used are marked in it
};

class PhotonMap {
 public:
  PhotonMap();
  ~PhotonMap();
  PhotonMap(PhotonMap&&) noexcept;
  PhotonMap& operator=(PhotonMap&&) noexcept;

  // Takes the photons and builds the kd-tree (single-threaded, nanoflann). With a budget, the
  // sort polls it every 2²⁰ photons and a build longer than the budget's allowed overshoot
  // polls it too (Budget::granularity); when it expires the map is left empty and build()
  // returns false.
  bool build(std::vector<Photon> photons, const Budget* budget = nullptr);
  // The same from the tracer's per-chunk buffers, without concatenating them first: the Morton
  // sort reads them in order and writes the map's own array once.
  bool build(std::vector<std::vector<Photon>> chunks, const Budget* budget = nullptr);
  size_t size() const;
  const std::vector<Photon>& photons() const;
  // Spectral photon maps store CIE XYZ flux (never negative, unlike a single spectral sample's
  // sRGB, which the shared-exponent encoding could not hold); flux() hands back linear sRGB.
  void setFluxIsXYZ(bool xyz) { fluxIsXYZ_ = xyz; }
  // A factor on every photon's flux, known only once the map is traced (adaptive photon
  // tracing's normalisation, photon_tracer.h); 1 otherwise.
  void setFluxScale(float scale) { fluxScale_ = scale; }
  Spectrum flux(const Photon& p) const { return (fluxIsXYZ_ ? xyzFluxToRGB(p.flux()) : p.flux()) * fluxScale_; }
  static Spectrum xyzFluxToRGB(const Vec3& xyz);
  size_t memoryBytes() const;

  // Neighbours of x whose incident direction lies on the side of `n` (dot(wi, n) > 0; pass a
  // zero vector to accept every side) and whose path type is in `accept` (Photon::kAccept*).
  // How many stored photons have a type in `accept` (Photon::kAccept*).
  size_t count(uint8_t accept) const;
  // knn: the k nearest within maxRadius (0 = unbounded), sorted by distance.
  // planeTolerance > 0 (needs a non-zero n): skip photons farther than it from x's tangent plane.
  // bothSides: photons from either side of n (a surface whose BSDF has a smooth transmission lobe: hasSmoothTransmission).
  void knn(const Vec3& x, const Vec3& n, uint8_t accept, int k, float maxRadius, std::vector<Neighbour>* out,
           float planeTolerance = 0.0f, bool bothSides = false) const;
  void withinRadius(const Vec3& x, const Vec3& n, uint8_t accept, float radius, std::vector<Neighbour>* out,
                    float planeTolerance = 0.0f, bool bothSides = false) const;

  // Reflected radiance at a surface point towards woWorld, by the estimator configured in `de`.
  // With k-NN and the uniform kernel, the k-th photon sits on the boundary of the disc it
  // defines: it is dropped and the k − 1 others divided by πr_k² (the unbiased form for a
  // Poisson process). The other kernels vanish on the boundary and need no correction.
  // The same on a path at `lambda`: photons hold RGB flux, so the estimate is made in RGB and, on
  // a spectral path, handed back at its wavelengths (an illuminant-type uplift: the film maps it
  // back to the same RGB).
  Spectrum radiance(const SurfaceHit& hit, const Vec3& woWorld, const SampledWavelengths& lambda,
                    const DensityEstimation& de, uint8_t accept, GatherStats* stats = nullptr) const {
    return spectralEmission(radiance(hit, woWorld, de, accept, stats), lambda);
  }
  // In RGB.
  Spectrum radiance(const SurfaceHit& hit, const Vec3& woWorld, const DensityEstimation& de, uint8_t accept,
                    GatherStats* stats = nullptr) const;
  // Irradiance E = Σ Φp K at x (the same estimator without the BSDF), for tests.
  Spectrum irradiance(const Vec3& x, const Vec3& n, const DensityEstimation& de, uint8_t accept,
                      GatherStats* stats = nullptr) const;

 private:
  bool fluxIsXYZ_ = false;
  float fluxScale_ = 1.0f;
  template <typename Weight>
  Spectrum estimate(const Vec3& x, const Vec3& n, const DensityEstimation& de, uint8_t accept,
                    GatherStats* stats, Weight&& weight, bool bothSides = false) const;
  // The tree owns the photons (nanoflann's adaptor points at them), on the heap so that a
  // PhotonMap can be moved without invalidating that pointer.
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace pl
