// The photon guide (Jensen 1995, "Importance driven path tracing using the photon map"): the
// photon map already knows where light arrives from. Before each iteration a fresh photon map
// is traced (the photon tracer and kd-tree of photon mapping), twice as many paths as the last;
// the cached points are the leaves of a spatial binary tree split until each holds at most k
// photons, and each leaf's distribution is an adaptive quadtree (DirectionalQuadtree::
// fromDirections) of the incident directions of the k photons nearest its photons' centroid,
// each weighted by its flux's luminance. A photon's flux is ∝ L_i·|cos θ|·dω·dA, so a
// distribution built from flux follows the incident radiance times the cosine: the product a
// diffuse surface scatters, which is what Jensen's histograms sample.
#include <cmath>

#include "core/parallel.h"
#include "guiding/guide.h"
#include "guiding/spatial_tree.h"
#include "photon/photon_tracer.h"

namespace pl {

namespace {

class PhotonGuide final : public Guide {
 public:
  PhotonGuide(const Scene& scene, const GuideOptions& o) : options_(o) {}

  void prepare(const Scene& scene, int iteration, int, bool, uint64_t seed, int threads, const Budget& budget) override {
    PhotonTracingOptions po;
    // Doubling for three iterations (8× the first map), then refreshed at that size: a photon
    // map's memory grows with it, while a guide's quality saturates long before a render's end.
    po.globalPaths = options_.photons << std::min(iteration, 3);
    po.causticPaths = 0;
    po.seed = mix64(seed ^ 0x9a1de5ULL) + uint64_t(iteration);  // a map of its own per iteration
    po.threads = threads;
    po.maxDepth = options_.maxDepth;
    po.spectral = options_.spectral;
    po.budget = &budget;
    PhotonMaps maps = tracePhotons(scene, po);
    photons_ = maps.global.size();
    if (!maps.complete) return;  // the budget ended: the render stops too
    build(scene, maps.global, threads, budget);
  }

  GuideLookup at(const Vec3& p, const Vec3&) const override {
    if (leaves_.empty()) return {&empty_, 0};
    uint32_t leaf = tree_.leafAt(p);
    return {&leaves_[leaf], leaf};
  }

  std::string describe() const override {
    size_t cells = 0;
    for (const auto& l : leaves_) cells += l.empty() ? 0 : l.leafCells();
    return std::to_string(photons_) + " photons, " + std::to_string(tree_.leaves()) + " cached points, " +
           std::to_string(cells) + " directional cells";
  }

 private:
  void build(const Scene& scene, const PhotonMap& map, int threads, const Budget& budget) {
    const auto& photons = map.photons();
    const size_t k = size_t(options_.photonsPerDistribution);
    tree_ = SpatialBinaryTree(scene.bounds().lo, scene.bounds().hi);
    // Split leaves until each holds at most 4k photons (a cached point per few distributions'
    // worth of photons: finer cells cost more to build than they gain). The photons' indices are partitioned by
    // the split plane along with the cells, so the whole build is O(n log n).
    std::vector<std::vector<uint32_t>> members(1);
    members[0].resize(photons.size());
    for (uint32_t i = 0; i < photons.size(); ++i) members[0][i] = i;
    struct Cell {
      uint32_t node;
      Vec3 lo, hi;
    };
    std::vector<Cell> work(1);
    work[0].node = 0;
    tree_.cell(0, &work[0].lo, &work[0].hi);
    while (!work.empty()) {
      Cell c = work.back();
      work.pop_back();
      uint32_t slot = tree_.nodes()[c.node].payload;
      if (members[slot].size() <= 4 * k || tree_.nodes()[c.node].depth >= 60) continue;
      const int axis = tree_.nodes()[c.node].axis;
      const float mid = 0.5f * (c.lo[axis] + c.hi[axis]);
      auto [a, b] = tree_.split(c.node);
      std::vector<uint32_t> left, right;
      for (uint32_t i : members[slot]) (photons[i].position[axis] < mid ? left : right).push_back(i);
      members[slot] = std::move(left);
      members.push_back(std::move(right));
      tree_.setPayload(a, slot);
      tree_.setPayload(b, uint32_t(members.size() - 1));
      Cell ca = c, cb = c;
      ca.node = a, ca.hi[axis] = mid;
      cb.node = b, cb.lo[axis] = mid;
      work.push_back(ca);
      work.push_back(cb);
    }
    // One distribution per leaf, from the k nearest photons to the centroid of its own (none
    // where it holds none: there the BSDF samples alone). Leaves are independent: built in
    // parallel, each the same whatever the thread that built it.
    leaves_.assign(members.size(), DirectionalQuadtree());
    parallelFor(members.size(), threads, [&](size_t slot, int) {
      if (members[slot].empty() || budget.expired()) return;
      Vec3 centroid(0.0f);
      for (uint32_t i : members[slot]) centroid += photons[i].p();
      centroid /= float(members[slot].size());
      std::vector<Neighbour> found;
      map.knn(centroid, Vec3(0.0f), Photon::kAcceptAll, int(k), 0.0f, &found);
      std::vector<WeightedDirection> directions;
      directions.reserve(found.size());
      for (const Neighbour& nb : found) {
        const Photon& ph = photons[nb.index];
        float w = std::max(0.0f, luminance(map.flux(ph)));
        if (w > 0) directions.push_back({sphereToSquare(ph.wi()), w});
      }
      // Split cells with over 2% of the weight while they hold more than 8 photons: a cell's
      // density is then an average over at least a few photons, not one photon's spike.
      leaves_[slot] = DirectionalQuadtree::fromDirections(std::move(directions), 0.02f, 8, 10);
      // Irradiance from the same photons, E = ΣΦ/(πr²), r the k-th photon's distance (the
      // constant-kernel estimate; only Russian roulette reads it).
      if (!found.empty() && found.back().d2 > 0) {
        double flux = 0;
        for (const Neighbour& nb : found) flux += std::max(0.0f, luminance(map.flux(photons[nb.index])));
        leaves_[slot].setRadianceScale(float(flux / (kPi * found.back().d2)), true);
      }
    });
  }

  GuideOptions options_;
  SpatialBinaryTree tree_;
  std::vector<DirectionalQuadtree> leaves_;
  DirectionalQuadtree empty_;
  size_t photons_ = 0;
};

}  // namespace

std::unique_ptr<Guide> makePhotonGuide(const Scene& scene, const GuideOptions& options) {
  return std::make_unique<PhotonGuide>(scene, options);
}

}  // namespace pl
