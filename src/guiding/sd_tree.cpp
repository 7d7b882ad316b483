// The SD-tree guide (Müller, Gross, Novák 2017, "Practical Path Guiding for Efficient
// Light-Transport Simulation"): a spatial binary tree whose leaves each hold a directional
// quadtree of incident radiance, learned from the render's own paths in iterations of doubling
// sample counts. Iteration k samples with the distribution learned from iteration k − 1 and
// records into a fresh tree of the refined shape; between iterations
//   1. a spatial leaf that received more than c·√(spp_k) records splits in two (both halves
//      keep a copy of its directional trees and half its count), until none is over (§5.1);
//   2. each directional tree's recorded energies become its sampling distribution, and the
//      next recording tree is that distribution's shape refined: cells with more than ρ = 1% of
//      the energy split, the rest collapse (§5.2).
// Unlike the paper, a leaf holds one directional tree per side a surface can face (guide.h,
// sideOf): in a leaf wider than a door is thick, one shared tree learned on the lit face sends
// the shadowed face's directions into the door (docs: explanation/guiding.md).
//
// Records are integer energy units (QuadtreeRecorder): threads add them in any order and the
// sums are the same bits, so the learned distributions, and the image, do not depend on the
// thread count. The unit is 2⁻²⁸ of the scene's radiance scale L₀ = Φ/(4π²R²) (the radiance of
// its bounding sphere were the lights' whole power Φ leaving it uniformly); a single record is
// capped at 2¹⁶ L₀. Both only shape the guide, never the estimate: a sampling density that is
// not exactly proportional to the incident radiance still gives an unbiased image.
#include <cmath>

#include "guiding/guide.h"
#include "guiding/spatial_tree.h"

namespace pl {

namespace {

class SDTreeGuide final : public Guide {
 public:
  SDTreeGuide(const Scene& scene, const GuideOptions& o) : options_(o), tree_(scene.bounds().lo, scene.bounds().hi) {
    leaves_.emplace_back();
    const float R = std::max(scene.bounds().radius(), 1e-6f);
    const double power = average(scene.totalPower());
    const double radianceScale = power > 0 ? power / (4 * double(kPi) * kPi * R * R) : 1.0;  // L₀
    unit_ = radianceScale * 0x1p-28;
    cap_ = uint64_t(1) << 44;
  }

  void prepare(const Scene&, int iteration, int samples, bool last, uint64_t, int threads, const Budget&) override {
    learns_ = !last;
    threads_ = threads;
    if (iteration > 0) refine(lastSamples_);
    else
      for (auto& b : leaves_[0].building) b = QuadtreeRecorder(threads_);
    lastSamples_ = samples;
  }

  GuideLookup at(const Vec3& p, const Vec3& n) const override {
    uint32_t leaf = tree_.leafAt(p);
    int side = sideOf(n);
    const Leaf& l = leaves_[leaf];
    // A distribution learned from too few records is noise: there the BSDF samples alone.
    const bool learned = double(l.learnedFrom[side]) >= options_.minRecords;
    return {learned ? &l.sampling[side] : &empty_, uint32_t(kSides * leaf + side)};
  }
  bool learns() const override { return learns_; }

  void record(uint32_t leaf, const Vec3& wi, float radianceOverPdf, int thread) override {
    if (!(radianceOverPdf >= 0) || !std::isfinite(radianceOverPdf)) return;
    double units = std::min(double(radianceOverPdf) / unit_, double(cap_));
    leaves_[leaf / kSides].building[leaf % kSides].record(sphereToSquare(wi), uint64_t(std::llround(units)), thread);
  }

  std::string describe() const override {
    size_t cells = 0;
    for (const Leaf& l : leaves_)
      for (const auto& d : l.sampling) cells += d.empty() ? 0 : d.leafCells();
    return std::to_string(tree_.leaves()) + " spatial leaves, " + std::to_string(cells) + " directional cells";
  }

 private:
  // Per side (sideOf): what this iteration samples with, and what it records into.
  struct Leaf {
    DirectionalQuadtree sampling[kSides];
    QuadtreeRecorder building[kSides];
    uint64_t learnedFrom[kSides] = {0, 0, 0, 0, 0, 0};  // records behind each sampling tree
    uint64_t records() const {
      uint64_t n = 0;
      for (const auto& b : building) n += b.records();
      return n;
    }
  };

  void refine(int samples) {
    // 1. Spatial: split crowded leaves. The threshold grows as √spp so that, as samples double,
    // spatial and directional resolution both grow (§5.1).
    const double threshold = options_.spatialThreshold * std::sqrt(double(std::max(samples, 1)));
    std::vector<uint32_t> work;
    for (uint32_t n = 0; n < tree_.nodes().size(); ++n)
      if (tree_.nodes()[n].isLeaf()) work.push_back(n);
    while (!work.empty()) {
      uint32_t n = work.back();
      work.pop_back();
      uint32_t payload = tree_.nodes()[n].payload;
      if (double(leaves_[payload].records()) <= threshold || tree_.nodes()[n].depth >= 60) continue;
      auto [a, b] = tree_.split(n);
      for (auto& side : leaves_[payload].building) side.setRecords(side.records() / 2);
      leaves_.push_back(leaves_[payload]);  // the other half: a copy, directional tree included
      tree_.setPayload(a, payload);
      tree_.setPayload(b, uint32_t(leaves_.size() - 1));
      work.push_back(a);
      work.push_back(b);
    }
    // 2. Directional: what was recorded becomes the distribution; the recording tree is its
    // refined shape, empty.
    for (Leaf& leaf : leaves_)
      for (int side = 0; side < kSides; ++side) {
        leaf.learnedFrom[side] = leaf.building[side].records();
        leaf.sampling[side] = leaf.building[side].finish(unit_);
        leaf.building[side] =
            QuadtreeRecorder(leaf.sampling[side], options_.directionalThreshold, options_.directionalDepth, threads_);
      }
  }

  GuideOptions options_;
  SpatialBinaryTree tree_;
  std::vector<Leaf> leaves_;
  DirectionalQuadtree empty_;
  double unit_ = 1;  // radiance/pdf per integer energy unit
  uint64_t cap_ = 0;
  int lastSamples_ = 1, threads_ = 1;
  bool learns_ = true;
};

}  // namespace

std::unique_ptr<Guide> makeSDTreeGuide(const Scene& scene, const GuideOptions& options) {
  return std::make_unique<SDTreeGuide>(scene, options);
}

}  // namespace pl
