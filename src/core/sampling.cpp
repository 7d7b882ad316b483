#include "core/sampling.h"

#include <algorithm>

namespace pl {

Vec2 sampleConcentricDisc(const Vec2& u) {
  Vec2 o = 2.0f * u - Vec2(1.0f);
  if (o.x == 0 && o.y == 0) return Vec2(0);
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) {
    r = o.x;
    theta = (kPi / 4) * (o.y / o.x);
  } else {
    r = o.y;
    theta = kPi / 2 - (kPi / 4) * (o.x / o.y);
  }
  return r * Vec2(std::cos(theta), std::sin(theta));
}

Vec3 sampleCosineHemisphere(const Vec2& u) {
  // Malley's method with the polar map r = √u₁, φ = 2πu₂: branch-free. (The concentric map
  // only helps stratified samples; with independent ones its data-dependent branch cost
  // measurable time in photon tracing.)
  float r = std::sqrt(u.x);
  Vec2 sc = sinCos2Pi(u.y);
  return Vec3(r * sc.y, r * sc.x, std::sqrt(std::max(0.0f, 1.0f - u.x)));
}

Vec3 sampleUniformSphere(const Vec2& u) {
  float z = 1.0f - 2.0f * u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  Vec2 sc = sinCos2Pi(u.y);
  return Vec3(r * sc.y, r * sc.x, z);
}

Vec3 sampleUniformCone(const Vec2& u, float cosThetaMax) {
  float cosTheta = 1.0f - u.x * (1.0f - cosThetaMax);
  float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  Vec2 sc = sinCos2Pi(u.y);
  return Vec3(sinTheta * sc.y, sinTheta * sc.x, cosTheta);
}

Vec3 samplePowerCosine(const Vec2& u, float n) {
  // Invert the CDF of cosθ: P(cosθ > μ) = 1 − μ^(n+1).
  float cosTheta = std::pow(1.0f - u.x, 1.0f / (n + 1.0f));
  float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  Vec2 sc = sinCos2Pi(u.y);
  return Vec3(sinTheta * sc.y, sinTheta * sc.x, cosTheta);
}

Vec2 sampleUniformTriangle(const Vec2& u) {
  // Heitz 2019, "A low-distortion map between triangle and square".
  // Both halves are computed and one selected: u.x < u.y is a coin flip, and a branch on it
  // mispredicts half the time (common.h, select).
  bool lower = u.x < u.y;
  float h0 = u.x / 2, h1 = u.y / 2;
  return Vec2(select(lower, h0, u.x - h1), select(lower, u.y - h0, h1));
}

Distribution1D::Distribution1D(const std::vector<float>& weights) {
  weights_.assign(weights.begin(), weights.end());
  cdf_.resize(weights_.size());
  double sum = 0;
  for (size_t i = 0; i < weights_.size(); ++i) {
    sum += std::max(0.0, weights_[i]);
    cdf_[i] = sum;
  }
  total_ = sum;
  pmf_.resize(weights_.size());
  for (size_t i = 0; i < weights_.size(); ++i) pmf_[i] = sum > 0 ? float(std::max(0.0, weights_[i]) / sum) : 0.0f;
}

size_t Distribution1D::sample(float u, float* pmfOut, float* uRemapped) const {
  double target = double(u) * total_;
  // Index of the first cdf entry above the target. Scenes have a handful of lights (a quad is
  // two): counting is branch-free there, where a binary search mispredicts on every photon.
  size_t i = 0;
  if (cdf_.size() <= 16) {
    for (double c : cdf_) i += c <= target;
  } else {
    i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin());
  }
  i = std::min(i, cdf_.size() - 1);
  while (i > 0 && weights_[i] <= 0) --i;  // never return a zero-weight item
  double lo = i ? cdf_[i - 1] : 0.0;
  if (pmfOut) *pmfOut = pmf_[i];
  if (uRemapped) *uRemapped = float(std::min((target - lo) / weights_[i], 0.99999994));
  return i;
}

}  // namespace pl
