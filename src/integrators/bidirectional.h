// Bidirectional estimators in one class, as the "Implementing Vertex Connection and Merging"
// technical report (Georgiev 2012) lays them out:
//   bdpt  Veach's bidirectional path tracer (Veach & Guibas 1995): vertex connection only;
//   bpm   bidirectional photon mapping (Vorba 2011): vertex merging only, MIS over merge depths;
//   vcm   vertex connection and merging (Georgiev, Křivánek, Davidovič & Slusallek 2012): both.
// See bidirectional.cpp for the algorithm, top to bottom.
#pragma once
#include <string>
#include <vector>

#include "render/integrator.h"

namespace pl {

struct BidirectionalOptions {
  bool connect = true;  // vertex connection: s = 0, 1, t = 1 and every s, t ≥ 2 connection
  bool merge = false;   // vertex merging: a density estimate at every diffuse or glossy camera vertex
  int maxDepth = 16;    // bounces: a path has at most maxDepth + 1 segments, as the path tracer's
  float radius = 0.0f;  // initial merge radius r₁ (m)
  float alpha = 0.75f;  // r_i = r₁ · i^((α−1)/2)
  // Merging at x₁, the first vertex after the light (the light vertex y₁, a "direct photon"):
  // with connections on, next-event estimation and light tracing already carry that light, so
  // vcm may leave this merge out of its techniques (and out of every weight's denominator).
  bool directMerges = true;
  // The MIS heuristic for every pdf ratio: the power heuristic, β = 2 (Veach 1997 §9.2.4), or
  // the balance heuristic, β = 1 (SmallVCM's default, and pbrt-v3's bdpt).
  bool balanceHeuristic = false;
  // Each subpath's first random numbers from Owen-scrambled Sobol' points over the iterations
  // (core/sampler.h) instead of an independent stream.
  bool sobol = false;
  // Whether merging at the light vertex y_length (x_length of the path) is one of the techniques.
  bool mergesAt(int lightLength) const { return merge && (lightLength >= 2 || directMerges); }
  // Debugging the estimator (bdpt): one image per technique (s, t), weighted (strategies); or
  // one technique alone, unweighted (onlyS, onlyT ≥ 0), which must converge to the paths of
  // length s + t − 1 on its own.
  bool strategies = false;
  int onlyS = -1, onlyT = -1;
};

// The default initial merge radius r₁, in pixel footprints at the median visible distance.
// One where merges carry direct light (bpm, which merges at every vertex, and vcm with direct
// merges): its blur is then the image's, and one pixel keeps it below the pixel (as SmallVCM's
// 0.3% of the scene radius is at 512² in its Cornell box). Three where they carry only indirect
// light (vcm's default), which is smooth enough for a wider kernel: on SmallVCM's two scenes at
// 512², 20 s, relMSE falls from 1 to 3 footprints (0.0098 to 0.0068 under the point light,
// 0.0159 to 0.0068 under the sun) and rises again from 4 (docs: explanation/bidirectional.md,
// Radius).
inline float mergeFootprints(bool directMerges) { return directMerges ? 1.0f : 3.0f; }

class VertexConnectionMerging final : public Integrator {
 public:
  VertexConnectionMerging(const BidirectionalOptions& options, std::string name)
      : o_(options), name_(std::move(name)) {}
  ImageRGB render(const Scene& scene, const RenderOptions& options, RenderInfo* info) override;
  const char* name() const override { return name_.c_str(); }
  std::vector<NamedImage> extraImages() const override { return strategyImages_; }

  // Techniques are numbered by path depth k = s + t − 2 (bounces), then s = 0 … k + 1.
  static int strategyIndex(int s, int t) {
    const int k = s + t - 2;
    return k * (k + 3) / 2 + s;
  }
  static int strategyCount(int maxDepth) { return strategyIndex(0, maxDepth + 3); }

 private:
  struct Iteration;
  struct SubPath;
  struct LightVertex;
  class Tracer;
  BidirectionalOptions o_;
  std::string name_;
  std::vector<NamedImage> strategyImages_;
};

}  // namespace pl
