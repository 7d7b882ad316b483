// Warps from the unit square to the domains light transport integrates over, with their
// densities. Each pdf is with respect to the measure named in its comment.
#pragma once
#include <vector>
#include "core/common.h"

namespace pl {

// (sin 2πu, cos 2πu) for u in [0, 1): the azimuth of every direction sampled below, faster than
// libm's sincosf (docs: Performance). It reduces to an eighth of a turn, x = 2π(u − q/4) in
// [−π/4, π/4], and evaluates Cephes' minimax polynomials there (absolute error < 2e-7, tested
// against libm), then rotates by q quarter turns.
inline Vec2 sinCos2Pi(float u) {
  float t = 4.0f * u;
  int q = int(t + 0.5f);  // nearest quarter turn (t ≥ 0)
  float x = (t - float(q)) * (kPi / 2), x2 = x * x;
  float s = x + x * x2 * (-1.6666654611e-1f + x2 * (8.3321608736e-3f + x2 * -1.9515295891e-4f));
  float c = 1.0f - 0.5f * x2 + x2 * x2 * (4.166664568298827e-2f + x2 * (-1.388731625493765e-3f + x2 * 2.443315711809948e-5f));
  // sin(x + qπ/2), cos(x + qπ/2): odd q swaps the pair, q = 1, 2 negate sin and q = 2, 3 cos.
  // q is random: branch-free selects (common.h).
  bool odd = q & 1;
  return Vec2(negateIf(q & 2, select(odd, c, s)), negateIf((q + 1) & 2, select(odd, s, c)));
}

// Cosine-weighted hemisphere around +z (Malley's method, polar map); pdf = cosθ/π (solid angle).
PL_HOT_INLINE Vec3 sampleCosineHemisphere(const Vec2& u) {
  // Malley's method with the polar map r = √u₁, φ = 2πu₂: branch-free. (The concentric map
  // only helps stratified samples; with independent ones its data-dependent branch cost
  // measurable time in photon tracing.)
  float r = std::sqrt(u.x);
  Vec2 sc = sinCos2Pi(u.y);
  return Vec3(r * sc.y, r * sc.x, std::sqrt(std::max(0.0f, 1.0f - u.x)));
}
inline float pdfCosineHemisphere(const Vec3& v) { return v.z > 0 ? v.z * kInvPi : 0.0f; }

// Uniform direction on the unit sphere; pdf = 1/4π.
Vec3 sampleUniformSphere(const Vec2& u);

// Uniform direction in the cone cosθ ≥ cosThetaMax around +z; pdf = 1/(2π(1−cosθmax)).
Vec3 sampleUniformCone(const Vec2& u, float cosThetaMax);

// Direction around +z with pdf ∝ cosⁿθ over the hemisphere: cosθ = u^(1/(n+1)),
// pdf = (n+1)/(2π) cosⁿθ (solid angle). Used by the Warn spotlight and the Phong lobe.
Vec3 samplePowerCosine(const Vec2& u, float n);
inline float pdfPowerCosine(float cosTheta, float n) {
  return cosTheta > 0 ? (n + 1.0f) * kInv2Pi * std::pow(cosTheta, n) : 0.0f;
}

// Uniform point on the unit disc (concentric map, Shirley & Chiu 1997).
Vec2 sampleConcentricDisc(const Vec2& u);

// Uniform barycentrics (b0, b1) on a triangle; pdf = 1/area.
PL_HOT_INLINE Vec2 sampleUniformTriangle(const Vec2& u) {
  // Heitz 2019, "A low-distortion map between triangle and square".
  // Both halves are computed and one selected: u.x < u.y is a coin flip, and a branch on it
  // mispredicts half the time (common.h, select).
  bool lower = u.x < u.y;
  float h0 = u.x / 2, h1 = u.y / 2;
  return Vec2(select(lower, h0, u.x - h1), select(lower, u.y - h0, h1));
}

// Build (u, v) in the hemisphere's (cosθ, φ) from a direction: for histogram tests.
inline float sphericalPhi(const Vec3& v) {
  float p = std::atan2(v.y, v.x);
  return p < 0 ? p + 2 * kPi : p;
}

// Discrete distribution over n items by Walker's alias method (Vose's construction): light
// selection by power, once per photon and per shadow ray. Sampling is O(1) and branch-free:
// u·n picks a bin, the fractional part picks the bin's own item (probability q) or its alias.
class AliasTable {
 public:
  AliasTable() = default;
  explicit AliasTable(const std::vector<float>& weights);
  // Index i with probability weight_i/total (never a zero-weight item), and that probability.
  // With no positive weight, any index with pmf 0: callers check total() first.
  size_t sample(float u, float* pmf = nullptr) const;
  float pmf(size_t i) const { return pmf_[i]; }
  size_t size() const { return bins_.size(); }
  double total() const { return total_; }

 private:
  struct Bin {
    double q;        // probability of keeping this bin's own item
    uint32_t alias;  // the item taken otherwise
  };
  std::vector<Bin> bins_;
  std::vector<float> pmf_;  // weight/total
  double total_ = 0.0;
};

// Piecewise-constant density on [0, 1) with n equal cells of weights w_i: p(x) = n·w_i/Σw in
// cell i. sample() inverts the cdf continuously: it returns the cell and the position within it
// (uniform there), so that a 2D distribution built of these keeps its samples stratified.
class PiecewiseConstant1D {
 public:
  PiecewiseConstant1D() = default;
  explicit PiecewiseConstant1D(const std::vector<float>& weights);
  // Cell i with probability w_i/Σw (never a zero-weight cell), and u's position in it, in [0, 1).
  size_t sample(float u, float* offset, float* pmf = nullptr) const;
  float pmf(size_t i) const { return total_ > 0 ? float(weights_[i] / total_) : 0.0f; }
  size_t size() const { return weights_.size(); }
  double total() const { return total_; }

 private:
  std::vector<double> weights_, cdf_;  // cdf_: n + 1 values, 0 ... 1
  double total_ = 0.0;
};

}  // namespace pl
