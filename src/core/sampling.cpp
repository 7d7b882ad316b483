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

AliasTable::AliasTable(const std::vector<float>& weights) {
  size_t n = weights.size();
  bins_.resize(n);
  pmf_.assign(n, 0.0f);
  std::vector<double> w(n);
  for (size_t i = 0; i < n; ++i) w[i] = std::max(0.0, double(weights[i]));  // also maps NaN to 0
  for (double x : w) total_ += x;
  if (n == 0 || !(total_ > 0)) {
    for (size_t i = 0; i < n; ++i) bins_[i] = {1.0, uint32_t(i)};
    total_ = 0.0;
    return;
  }
  // Vose: each bin holds mass 1 in units of total/n. A bin below 1 ("small") is topped up by
  // one item above 1 ("large"), which keeps the rest of its mass for later bins.
  std::vector<double> p(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    pmf_[i] = float(w[i] / total_);
    p[i] = w[i] / total_ * double(n);
    (p[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    uint32_t s = small.back(), l = large.back();
    small.pop_back();
    bins_[s] = {p[s], l};
    p[l] -= 1.0 - p[s];
    if (p[l] < 1.0) large.pop_back(), small.push_back(l);
  }
  // What is left holds mass 1 up to rounding.
  for (uint32_t i : large) bins_[i] = {1.0, i};
  for (uint32_t i : small) bins_[i] = {1.0, i};
  // A zero-weight item must never come out, whatever the rounding above did.
  uint32_t heaviest = uint32_t(std::max_element(w.begin(), w.end()) - w.begin());
  for (size_t i = 0; i < n; ++i)
    if (w[i] == 0.0) bins_[i] = {0.0, w[bins_[i].alias] > 0 ? bins_[i].alias : heaviest};
}

size_t AliasTable::sample(float u, float* pmfOut) const {
  // In double, x = u·n is exact (24-bit u, n < 2²⁹), so every bin and its split get exactly
  // their share of u.
  double x = double(u) * double(bins_.size());
  size_t i = std::min(size_t(x), bins_.size() - 1);
  const Bin& bin = bins_[i];
  size_t k = x - double(i) < bin.q ? i : bin.alias;
  if (pmfOut) *pmfOut = pmf_[k];
  return k;
}

PiecewiseConstant1D::PiecewiseConstant1D(const std::vector<float>& weights) {
  const size_t n = weights.size();
  weights_.resize(n);
  cdf_.assign(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) {
    weights_[i] = std::max(0.0, double(weights[i]));  // also maps NaN to 0
    cdf_[i + 1] = cdf_[i] + weights_[i];
  }
  total_ = cdf_[n];
  if (!(total_ > 0)) {
    total_ = 0.0;
    return;
  }
  for (double& c : cdf_) c /= total_;
  cdf_[n] = 1.0;
}

size_t PiecewiseConstant1D::sample(float u, float* offset, float* pmf) const {
  // The last cell whose cdf is ≤ u, skipping zero-weight cells (their cdf equals the next's).
  const size_t n = weights_.size();
  if (n == 0 || !(total_ > 0)) {
    if (offset) *offset = 0.0f;
    if (pmf) *pmf = 0.0f;
    return 0;
  }
  size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), double(u)) - cdf_.begin());
  i = std::min(std::max<size_t>(i, 1), n) - 1;
  while (weights_[i] <= 0 && i + 1 < n) ++i;  // u exactly on a boundary before empty cells
  while (weights_[i] <= 0 && i > 0) --i;
  double width = cdf_[i + 1] - cdf_[i];
  double t = width > 0 ? (double(u) - cdf_[i]) / width : 0.5;
  if (offset) *offset = float(std::min(std::max(t, 0.0), 0.99999994));
  if (pmf) *pmf = float(weights_[i] / total_);
  return i;
}

}  // namespace pl
