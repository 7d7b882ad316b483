#pragma once
#include "bsdfs/bsdf.h"
#include "image/texture.h"

namespace pl {

// Perfect specular reflector: wi = 2(N·wo)N − wo, reflectance by Schlick's Fresnel with
// F0 = baseColor (a polished metal; F0 = 1 is an ideal mirror).
class Mirror final : public BSDF {
 public:
  explicit Mirror(ColorTexture F0) : BSDF(kSpecularReflection, BSDFClass::kMirror), F0_(std::move(F0)) {}
  Spectrum eval(const Vec3&, const Vec3&, const BSDFContext&) const override { return Spectrum(0.0f); }
  float pdf(const Vec3&, const Vec3&, const BSDFContext&) const override { return 0.0f; }
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  bool specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const override {
    return lobe == kSpecularReflection && sample(wo, c, Vec2(0.0f), 0.0f, s);
  }
  const char* name() const override { return "mirror"; }
  const ColorTexture& reflectance() const { return F0_; }  // F0

 private:
  ColorTexture F0_;
};

}  // namespace pl
