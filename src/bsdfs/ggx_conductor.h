#pragma once
#include "bsdfs/bsdf.h"
#include "bsdfs/ggx.h"
#include "image/texture.h"

namespace pl {

// Rough metal: Cook–Torrance microfacet BRDF with the GGX distribution (Walter et al. 2007),
//   f = F(wo·m) D(m) G(wo, wi) / (4 cosθo cosθi),  m = normalize(wo + wi),
// with the GGX distribution and separable Smith G of bsdfs/ggx.h, Schlick F with F0 = baseColor.
// α = roughness² (glTF's perceptual roughness). Sampled by D(m) cosθm.
class GGXConductor final : public BSDF {
 public:
  GGXConductor(ColorTexture F0, float alpha) : BSDF(kGlossyReflection), F0_(std::move(F0)), ggx_{std::max(alpha, 1e-4f)} {}
  Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  const char* name() const override { return "ggx"; }

 private:
  ColorTexture F0_;
  GGX ggx_;
};

}  // namespace pl
