#pragma once
#include "bsdfs/bsdf.h"

namespace pl {

// Energy-conserving modified Phong BRDF (Lafortune & Willems 1994):
//   f(wo, wi) = kd/π + ks·(n+2)/(2π)·cosⁿα,   α = angle between wi and the mirror direction of wo.
// Reciprocal, and its albedo is ≤ kd + ks ≤ 1 (the loader checks kd + ks ≤ 1 per channel).
// Sampled as a mixture: the cosine lobe with probability avg(kd)/(avg(kd)+avg(ks)), otherwise
// cosⁿα around the mirror direction.
class Phong final : public BSDF {
 public:
  Phong(const Spectrum& kd, const Spectrum& ks, float exponent);
  Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  BSDFEval evaluate(const Vec3& wo, const Vec3& wi, const BSDFContext& c, bool reverse) const override;
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  const char* name() const override { return "phong"; }

 private:
  Spectrum kd_, ks_;
  float n_, diffuseProbability_;
};

}  // namespace pl
