// Warps from the unit square to the domains light transport integrates over, with their
// densities. Each pdf is with respect to the measure named in its comment.
#pragma once
#include <vector>
#include "core/common.h"

namespace pl {

// Cosine-weighted hemisphere around +z (Malley's method, polar map); pdf = cosθ/π (solid angle).
Vec3 sampleCosineHemisphere(const Vec2& u);
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
Vec2 sampleUniformTriangle(const Vec2& u);

// Build (u, v) in the hemisphere's (cosθ, φ) from a direction: for histogram tests.
inline float sphericalPhi(const Vec3& v) {
  float p = std::atan2(v.y, v.x);
  return p < 0 ? p + 2 * kPi : p;
}

// Piecewise-constant 1D distribution over n items (light selection by power).
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<float>& weights);
  // Index with probability weight/total; `u` is remapped to [0,1) for reuse.
  size_t sample(float u, float* pmf = nullptr, float* uRemapped = nullptr) const;
  float pmf(size_t i) const { return total_ > 0 ? float(weights_[i] / total_) : 0.0f; }
  size_t size() const { return weights_.size(); }
  double total() const { return total_; }

 private:
  std::vector<double> weights_, cdf_;
  double total_ = 0.0;
};

}  // namespace pl
