// A directional distribution over the whole sphere as a quadtree on the square (Müller, Gross,
// Novák 2017, "Practical Path Guiding", §3: the "D-tree"). Directions map to [0, 1)² by the
// cylindrical equal-area map
//   u = (cosθ + 1)/2,  v = φ/2π   (θ, φ of the world axes, z up),
// whose Jacobian is constant: dω = 4π du dv. So a density p□ on the square is p□/4π per steradian,
// and a quadtree whose cells hold energies samples a piecewise-constant density: a cell at depth d
// with energy e out of a total E has p□ = 4^d · e/E.
//
// Two forms share the node layout:
//   DirectionalQuadtree   the sampling form: each node holds its quadrants' probabilities given
//                         the node (so a density is a product along one path from the root,
//                         with no sums to form), plus the energies they came from;
//   QuadtreeRecorder      the training form: the same tree shape with integer energies. Each
//                         thread adds to its own copy, and the copies are summed when the
//                         iteration ends. Integer addition is associative, so the sums, and
//                         every tree refined from them, are the same bits whatever the thread
//                         count or whichever thread recorded what.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/common.h"
#include "core/sampling.h"

namespace pl {

// atan2(y, x) in [0, 2π), to ~2e-7 relative: Cephes' atanf polynomial after reducing the ratio
// to [0, tan π/8], faster than libm's atan2f; this map runs three times per guided vertex.
inline float azimuth(float y, float x) {
  float ax = std::abs(x), ay = std::abs(y);
  float hi = std::max(ax, ay), lo = std::min(ax, ay);
  float t = hi > 0 ? lo / hi : 0.0f;  // in [0, 1]
  float base = 0.0f;
  if (t > 0.4142135623f) base = kPi / 4, t = (t - 1) / (t + 1);
  float z = t * t;
  float a = base + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * t + t);
  if (ay > ax) a = kPi / 2 - a;  // the angle from the x axis in the first quadrant
  if (x < 0) a = kPi - a;
  if (y < 0) a = 2 * kPi - a;
  return a;
}

inline Vec2 sphereToSquare(const Vec3& w) {
  float cosTheta = std::clamp(w.z, -1.0f, 1.0f);
  float phi = azimuth(w.y, w.x);
  return Vec2(std::min((cosTheta + 1) * 0.5f, 0x1.fffffep-1f), std::min(phi * kInv2Pi, 0x1.fffffep-1f));
}

inline Vec3 squareToSphere(const Vec2& p) {
  float cosTheta = 2 * p.x - 1;
  float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
  Vec2 sc = sinCos2Pi(p.y);  // (sin 2πv, cos 2πv)
  return Vec3(sinTheta * sc.y, sinTheta * sc.x, cosTheta);
}

// One weighted direction, for building a quadtree from a set of samples (photons).
struct WeightedDirection {
  Vec2 square;    // sphereToSquare(ω)
  float weight;   // ≥ 0
};

class DirectionalQuadtree {
 public:
  // A node splits its square into quadrants 0..3: index = (u ≥ ½) + 2·(v ≥ ½). A quadrant is a
  // leaf cell when its child is 0 (node 0 is the root, never anyone's child).
  struct Node {
    float probability[4] = {0, 0, 0, 0};  // of each quadrant, given the node; they sum to 1
    uint32_t child[4] = {0, 0, 0, 0};
  };

  DirectionalQuadtree() : nodes_(1), energy_(4, 0.0f) {}
  // From a tree shape and the energy of every quadrant of every node (4 per node; an interior
  // quadrant's energy is the sum of its subtree's).
  DirectionalQuadtree(std::vector<Node> shape, std::vector<float> energy);

  // Built from weighted directions: a cell is split while it holds more than `threshold` of
  // the total weight and more than `minCount` directions, down to `maxDepth` (1 = the root's
  // four quadrants only). Jensen's photon histograms (1995) made adaptive.
  static DirectionalQuadtree fromDirections(std::vector<WeightedDirection> directions, float threshold, int minCount,
                                            int maxDepth);

  // What turns the density into incident radiance, for decisions such as Russian roulette
  // (0: not known). A tree learned from radiance records (L_i/p each) has pdf ∝ L_i and scale
  // ∫ L_i dω: L_i(ω) ≈ scale · pdf(ω). A tree built from photons' flux has pdf ∝ L_i·|cosθ| and
  // scale E, the irradiance: L_i(ω) ≈ E · pdf(ω)/|cosθ| (cosineWeighted()).
  float radianceScale() const { return scale_; }
  bool cosineWeighted() const { return cosineWeighted_; }
  void setRadianceScale(float scale, bool cosineWeighted) { scale_ = scale, cosineWeighted_ = cosineWeighted; }

  // No energy anywhere: nothing to sample (callers fall back to the BSDF alone).
  bool empty() const { return !(total_ > 0); }
  float total() const { return total_; }
  // Density per steradian of direction w (world, unit).
  float pdf(const Vec3& w) const { return empty() ? 0.0f : pdfSquare(sphereToSquare(w)) * kInv4Pi; }
  // Density on the square (integrates to 1 over [0, 1)²).
  float pdfSquare(Vec2 p) const;
  // A direction with density pdf(), which it also returns; u uniform in [0, 1)². Not for an
  // empty tree.
  Vec3 sample(Vec2 u, float* pdf) const {
    float p;
    Vec3 w = squareToSphere(sampleSquare(u, &p));
    *pdf = p * kInv4Pi;
    return w;
  }
  Vec2 sampleSquare(Vec2 u, float* pdfSquare) const;

  const std::vector<Node>& nodes() const { return nodes_; }
  // Asks the cache for the first nodes (the root and the first levels below it, stored first):
  // a descent's first loads, issued before other work so their latency hides behind it.
  void prefetch() const {
    const char* p = reinterpret_cast<const char*>(nodes_.data());
    const size_t bytes = std::min<size_t>(nodes_.size() * sizeof(Node), 512);
    for (size_t at = 0; at < bytes; at += 64) __builtin_prefetch(p + at);
  }
  // Quadrant q of node n's energy (an interior quadrant's: its subtree's).
  float energy(size_t n, int q) const { return energy_[4 * n + size_t(q)]; }
  int depth() const;
  size_t leafCells() const;

 private:
  std::vector<Node> nodes_;
  std::vector<float> energy_;
  float total_ = 0.0f, scale_ = 0.0f;
  bool cosineWeighted_ = false;
};

// The training form: a tree shape and an integer energy per leaf cell, one copy per thread.
// record(…, thread) may run on every thread at once, each with its own index; finish() and the
// refining constructor run after all records are in.
class QuadtreeRecorder {
 public:
  // One root with four leaf cells.
  explicit QuadtreeRecorder(int threads = 1);
  // The shape of `from`, refined (Müller et al. 2017, §5.2): a cell holding more than
  // `threshold` of `from`'s energy is split (its energy shared equally among its quadrants for
  // the decisions below it), a cell's subtree is kept while its energy stays above it, and the
  // rest is collapsed; at most `maxDepth` levels. Energies start at zero.
  QuadtreeRecorder(const DirectionalQuadtree& from, float threshold, int maxDepth, int threads);

  // Adds `units` (a non-negative integer energy) to the leaf cell holding direction p.
  void record(Vec2 p, uint64_t units, int thread);
  // The energies so far as a sampling tree, each unit worth `unitValue`.
  DirectionalQuadtree finish(double unitValue) const;
  // Directions recorded (all threads), and the count a spatial split leaves each half.
  uint64_t records() const;
  void setRecords(uint64_t n);

 private:
  std::vector<DirectionalQuadtree::Node> shape_;  // probabilities unused: the units are below
  int threads_ = 1;
  std::vector<uint64_t> units_;    // threads × 4 per node
  std::vector<uint64_t> records_;  // per thread, 8 apart (a cache line each)
};

}  // namespace pl
