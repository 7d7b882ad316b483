#pragma once
#include "bsdfs/bsdf.h"
#include "image/texture.h"

namespace pl {

// Ideal diffuse reflector, f = ρ/π; sampled by cosine-weighted hemisphere, so weight = ρ.
class Lambertian final : public BSDF {
 public:
  explicit Lambertian(ColorTexture albedo) : BSDF(kDiffuseReflection, BSDFClass::kLambertian), albedo_(std::move(albedo)) {}
  Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  BSDFEval evaluate(const Vec3& wo, const Vec3& wi, const BSDFContext& c, bool reverse) const override;
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  const char* name() const override { return "lambertian"; }
  const ColorTexture& albedo() const { return albedo_; }

 private:
  ColorTexture albedo_;
};

}  // namespace pl
