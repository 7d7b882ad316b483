#include "photon/photon_map.h"

#include <nanoflann.hpp>

#include "core/memory.h"
#include "spectral/spectral.h"

namespace pl {

namespace {

// nanoflann's view of the photons. Only the tree build reads points through kdtree_get_pt
// (queries use PhotonDistance below). A Guarded cloud polls the build's budget every 2¹⁶ reads
// (a few hundred microseconds of building) and throws BudgetExpired to abandon the build. The
// poll sits in nanoflann's innermost loops, where it keeps GCC from vectorising (docs:
// Performance, Stopping on time), so only builds long enough to matter are guarded (build()).
template <bool Guarded>
struct PhotonCloud {
  const std::vector<Photon>* photons;
  const Budget* budget = nullptr;
  mutable uint32_t reads = 0;
  size_t kdtree_get_point_count() const { return photons->size(); }
  float kdtree_get_pt(size_t i, size_t dim) const {
    if constexpr (Guarded) {
      if ((++reads & 0xffff) == 0 && budget->expired()) throw BudgetExpired();
    }
    return (*photons)[i].position[dim];
  }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const { return false; }
};

// Squared Euclidean distance for the searches, reading photon positions directly (nanoflann's
// L2_Simple_Adaptor would go through kdtree_get_pt and its budget poll).
struct PhotonDistance {
  using ElementType = float;
  using DistanceType = float;
  const std::vector<Photon>& photons;
  template <bool Guarded>
  explicit PhotonDistance(const PhotonCloud<Guarded>& cloud) : photons(*cloud.photons) {}
  float evalMetric(const float* a, uint32_t index, size_t) const {
    const float* p = &photons[index].position[0];
    float dx = a[0] - p[0], dy = a[1] - p[1], dz = a[2] - p[2];
    return dx * dx + dy * dy + dz * dz;
  }
  template <typename U, typename V>
  float accum_dist(const U a, const V b, const size_t) const {
    return (a - b) * (a - b);
  }
};

// Accepts a photon when its path type is accepted, it arrived on the query's side (or either,
// for a surface that transmits), and it lies near the query's tangent plane (when a tolerance
// is given).
struct Filter {
  const std::vector<Photon>& photons;
  Vec3 x, n;
  uint8_t accept;
  float planeTolerance;
  bool bothSides;
  bool operator()(uint32_t i) const {
    const Photon& p = photons[i];
    if (!((accept >> p.type()) & 1)) return false;
    if (n.x == 0 && n.y == 0 && n.z == 0) return true;
    if (planeTolerance > 0 && std::abs(glm::dot(p.p() - x, n)) > planeTolerance) return false;
    return bothSides || glm::dot(p.wi(), n) > 0;
  }
};

// k nearest accepted photons within an initial radius: a sorted array of at most k entries.
class FilteredKnn {
 public:
  FilteredKnn(int k, float maxDist2, const Filter& filter, std::vector<Neighbour>* out)
      : k_(size_t(k)), worst_(maxDist2), filter_(filter), out_(out) {
    out_->clear();
  }
  size_t size() const { return out_->size(); }
  bool full() const { return out_->size() == k_; }
  float worstDist() const { return worst_; }
  bool addPoint(float d2, uint32_t index) {
    if (d2 >= worst_ || !filter_(index)) return true;
    auto& v = *out_;
    if (v.size() == k_) v.pop_back();
    auto it = std::upper_bound(v.begin(), v.end(), d2, [](float d, const Neighbour& nb) { return d < nb.d2; });
    v.insert(it, Neighbour{index, d2});
    if (v.size() == k_) worst_ = v.back().d2;
    return true;
  }

 private:
  size_t k_;
  float worst_;
  const Filter& filter_;
  std::vector<Neighbour>* out_;
};

class FilteredRadius {
 public:
  FilteredRadius(float r2, const Filter& filter, std::vector<Neighbour>* out) : r2_(r2), filter_(filter), out_(out) {
    out_->clear();
  }
  size_t size() const { return out_->size(); }
  bool full() const { return true; }
  float worstDist() const { return r2_; }
  bool addPoint(float d2, uint32_t index) {
    if (d2 < r2_ && filter_(index)) out_->push_back(Neighbour{index, d2});
    return true;
  }

 private:
  float r2_;
  const Filter& filter_;
  std::vector<Neighbour>* out_;
};

}  // namespace

struct PhotonMap::Tree {
  template <bool Guarded>
  using Index = nanoflann::KDTreeSingleIndexAdaptor<PhotonDistance, PhotonCloud<Guarded>, 3, uint32_t>;
  std::vector<Photon> photons;
  PhotonCloud<false> cloud{&photons};
  PhotonCloud<true> guardedCloud{&photons};
  // One of the two, built by build() below (not by nanoflann's constructor, so that an expired
  // budget can abandon it). Leaf size 24: leaves of 20–40 gather faster than 10 (docs: Performance).
  std::unique_ptr<Index<false>> index;
  std::unique_ptr<Index<true>> guardedIndex;
  explicit Tree(std::vector<Photon> p) : photons(std::move(p)) {}

  // Builds the guarded index when `budget` is given, else the plain one; false if abandoned.
  bool build(const Budget* budget) {
    const nanoflann::KDTreeSingleIndexAdaptorParams params(24, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex);
    if (!budget) {
      index = std::make_unique<Index<false>>(3, cloud, params);
      index->buildIndex();
      return true;
    }
    guardedCloud.budget = budget;
    guardedIndex = std::make_unique<Index<true>>(3, guardedCloud, params);
    try {
      guardedIndex->buildIndex();
    } catch (const BudgetExpired&) {
      guardedIndex.reset();
      return false;
    }
    return true;
  }
  template <typename Result>
  void findNeighbors(Result& result, const float* q) const {
    if (index) index->findNeighbors(result, q, nanoflann::SearchParams());
    else guardedIndex->findNeighbors(result, q, nanoflann::SearchParams());
  }
};

static const std::vector<Photon> kNoPhotons;

PhotonMap::PhotonMap() = default;
PhotonMap::~PhotonMap() = default;
PhotonMap::PhotonMap(PhotonMap&&) noexcept = default;
PhotonMap& PhotonMap::operator=(PhotonMap&&) noexcept = default;

namespace {

// 16 bits per axis interleaved into a 48-bit Morton (Z-order) code: 65536 cells per axis are
// far finer than any gather radius.
uint64_t spreadBits(uint64_t v) {
  v &= 0xffff;
  v = (v | v << 16) & 0x0000ff0000ffULL;
  v = (v | v << 8) & 0x00f00f00f00fULL;
  v = (v | v << 4) & 0x0c30c30c30c3ULL;
  v = (v | v << 2) & 0x249249249249ULL;
  return v;
}

// Photons reordered along a Z-order curve, so that the kd-tree build and every gather read
// memory mostly sequentially instead of jumping across the whole map. LSD radix sort in four
// 12-bit passes that move the photons with their keys (a sort of indices followed by a
// random-access permutation would cost as much as the tree build).
// Returns an empty array when the budget expires on the way (checked per chunk and per 2²⁰
// photons of each radix pass).
std::vector<Photon> sortByMortonCode(std::vector<std::vector<Photon>>& chunks, const Budget* budget) {
  auto stop = [budget] { return budget && budget->expired(); };
  // fn(j) for j in [0, n), the budget polled every 2²⁰ elements; false when it expired.
  const size_t block = size_t(1) << 20;
  auto inBlocks = [&](size_t n, auto&& fn) {
    for (size_t begin = 0; begin < n; begin += block) {
      if (stop()) return false;
      for (size_t j = begin, end = std::min(n, begin + block); j < end; ++j) fn(j);
    }
    return true;
  };
  Bounds b;
  size_t n = 0;
  for (const auto& chunk : chunks) {
    n += chunk.size();
    for (const Photon& p : chunk) b.extend(p.p());
  }
  Vec3 scale = 65535.0f / glm::max(b.hi - b.lo, Vec3(1e-20f));
  struct Keyed {
    uint64_t key;
    Photon photon;
  };
  LargeArray<Keyed> a(n), tmp(n);  // first touched below, in loops that poll the budget
  size_t i = 0;
  for (auto& chunk : chunks) {
    if (stop()) return {};
    for (const Photon& p : chunk) {
      Vec3 q = glm::clamp((p.p() - b.lo) * scale, Vec3(0.0f), Vec3(65535.0f));
      a[i++] = {spreadBits(uint64_t(q.x)) | spreadBits(uint64_t(q.y)) << 1 | spreadBits(uint64_t(q.z)) << 2, p};
    }
    std::vector<Photon>().swap(chunk);  // release as we go
  }
  for (int shift = 0; shift < 48; shift += 12) {
    std::vector<size_t> offset(4097, 0);
    if (!inBlocks(n, [&](size_t j) { ++offset[((a[j].key >> shift) & 4095) + 1]; })) return {};
    for (size_t d = 1; d < offset.size(); ++d) offset[d] += offset[d - 1];
    if (!inBlocks(n, [&](size_t j) { tmp[offset[(a[j].key >> shift) & 4095]++] = a[j]; })) return {};
    a.swap(tmp);
  }
  { LargeArray<Keyed>(0).swap(tmp); }
  std::vector<Photon> photons;
  photons.reserve(n);
  if (!inBlocks(n, [&](size_t j) { photons.push_back(a[j].photon); })) return {};
  return photons;
}

}  // namespace

bool PhotonMap::build(std::vector<Photon> photons, const Budget* budget) {
  std::vector<std::vector<Photon>> one;
  one.push_back(std::move(photons));
  return build(std::move(one), budget);
}

bool PhotonMap::build(std::vector<std::vector<Photon>> chunks, const Budget* budget) {
  tree_.reset();
  std::vector<Photon> photons = sortByMortonCode(chunks, budget);
  if (budget && budget->expired()) return false;
  if (photons.empty()) return true;
  auto tree = std::make_unique<Tree>(std::move(photons));
  // Guarded (stoppable) only when the build could outlast the overshoot the budget allows
  // (Budget::granularity), at a conservative 0.2 µs per photon (docs: Performance): smaller
  // maps, such as a progressive pass's, build at full speed and the budget is checked right after.
  const bool guarded = budget && 2e-7 * double(tree->photons.size()) > budget->granularity();
  if (!tree->build(guarded ? budget : nullptr)) return false;  // the partial tree goes with `tree`
  if (budget && budget->expired()) return false;
  tree_ = std::move(tree);
  return true;
}

size_t PhotonMap::size() const { return tree_ ? tree_->photons.size() : 0; }
const std::vector<Photon>& PhotonMap::photons() const { return tree_ ? tree_->photons : kNoPhotons; }

size_t PhotonMap::memoryBytes() const {
  // Photons plus the tree's index permutation and nodes (about one node per leaf pair).
  size_t n = size();
  return n * sizeof(Photon) + n * sizeof(uint32_t) + (n / 12 + 1) * 64;
}

void PhotonMap::knn(const Vec3& x, const Vec3& n, uint8_t accept, int k, float maxRadius,
                    std::vector<Neighbour>* out, float planeTolerance, bool bothSides) const {
  out->clear();
  if (!tree_ || k <= 0) return;
  Filter filter{tree_->photons, x, n, accept, planeTolerance, bothSides};
  FilteredKnn result(k, maxRadius > 0 ? maxRadius * maxRadius : INFINITY, filter, out);
  float q[3] = {x.x, x.y, x.z};
  tree_->findNeighbors(result, q);
}

void PhotonMap::withinRadius(const Vec3& x, const Vec3& n, uint8_t accept, float radius,
                             std::vector<Neighbour>* out, float planeTolerance, bool bothSides) const {
  out->clear();
  if (!tree_ || radius <= 0) return;
  Filter filter{tree_->photons, x, n, accept, planeTolerance, bothSides};
  FilteredRadius result(radius * radius, filter, out);
  float q[3] = {x.x, x.y, x.z};
  tree_->findNeighbors(result, q);
}

template <typename Weight>
Spectrum PhotonMap::estimate(const Vec3& x, const Vec3& n, const DensityEstimation& de, uint8_t accept,
                             GatherStats* stats, Weight&& weight, bool bothSides) const {
  thread_local std::vector<Neighbour> neighbours;  // reused: no allocation per gather
  float r2;
  size_t used;
  if (de.radius > 0) {
    withinRadius(x, n, accept, de.radius, &neighbours, de.planeTolerance, bothSides);
    r2 = de.radius * de.radius;
    used = neighbours.size();
  } else {
    knn(x, n, accept, de.k, de.maxRadius, &neighbours, de.planeTolerance, bothSides);
    used = neighbours.size();
    if (used == size_t(de.k)) {
      r2 = neighbours.back().d2;  // the k-th photon defines the disc
      if (de.kernel == Kernel::Uniform) --used;  // ... and lies on its boundary: k − 1 inside
    } else {
      // Fewer than k: bounded by maxRadius, or the map has fewer than k accepted photons.
      r2 = de.maxRadius > 0 ? de.maxRadius * de.maxRadius : (used ? neighbours.back().d2 : 0.0f);
    }
  }
  Spectrum sum(0.0f);
  for (size_t i = 0; i < used; ++i) {
    const Photon& p = tree_->photons[neighbours[i].index];
    sum += weight(p) * flux(p) * kernelWeight(de.kernel, neighbours[i].d2, r2);
  }
  if (stats) {
    stats->photons = int(used);
    stats->radius = std::sqrt(r2);
    if (stats->marks)
      for (size_t i = 0; i < used; ++i) stats->marks->mark(neighbours[i].index);
  }
  return sum;
}

size_t PhotonMap::count(uint8_t accept) const {
  size_t n = 0;
  for (const Photon& p : photons()) n += (accept >> p.type()) & 1;
  return n;
}

Spectrum PhotonMap::xyzFluxToRGB(const Vec3& xyz) { return spectralXYZToRGB(xyz); }

Spectrum PhotonMap::radiance(const SurfaceHit& hit, const Vec3& woWorld, const DensityEstimation& de, uint8_t accept,
                             GatherStats* stats) const {
  Vec3 n = glm::dot(hit.ng, woWorld) >= 0 ? hit.ng : -hit.ng;
  Vec3 wo = hit.shading.toLocal(woWorld);
  const BSDFContext bc = bsdfContext(hit);
  // Photons from the other side count where the BSDF transmits: through a thin translucent wall.
  const bool bothSides = hasSmoothTransmission(hit.bsdf->flags());
  if (!hit.shadingDiffers())
    return estimate(hit.p, n, de, accept, stats,
                    [&](const Photon& p) { return hit.bsdf->eval(wo, hit.shading.toLocal(p.wi()), bc); }, bothSides);
  const Vec3 ngLocal = hit.shading.toLocal(hit.ng);
  return estimate(hit.p, n, de, accept, stats, [&](const Photon& p) {
    Vec3 wi = hit.shading.toLocal(p.wi());
    return sidesAgree(hit, woWorld, p.wi(), wo, wi) ? hit.bsdf->eval(wo, wi, bc) * densityShadingCorrection(wi, ngLocal)
                                                    : Spectrum(0.0f);
  }, bothSides);
}

Spectrum PhotonMap::irradiance(const Vec3& x, const Vec3& n, const DensityEstimation& de, uint8_t accept,
                               GatherStats* stats) const {
  return estimate(x, n, de, accept, stats, [](const Photon&) { return Spectrum(1.0f); });
}

}  // namespace pl
