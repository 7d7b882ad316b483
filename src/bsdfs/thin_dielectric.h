#pragma once
#include "bsdfs/bsdf.h"
#include "image/texture.h"

namespace pl {

// A smooth thin-walled dielectric (glTF KHR_materials_transmission without a volume, roughness
// 0): a sheet of negligible thickness that reflects by Schlick's Fresnel F(cosθ) with
// F0 = ((η − 1)/(η + 1))², as the specification's single interface does, and lets the rest
// through unrefracted, tinted by the base colour T:
//   reflection   wi = (−wo.x, −wo.y, wo.z),  weight F
//   transmission wi = −wo,                   weight (1 − F) T
// Both lobes are Dirac deltas. The lobe is chosen with probability F : (1 − F) mean(T), so a
// sample's weight is F/P or (1 − F) T/(1 − P). Nothing bends, so radiance and importance are
// transported alike (no 1/η²). Its rough counterpart is MetallicRoughness's transmission lobe.
class ThinDielectric final : public BSDF {
 public:
  ThinDielectric(ColorTexture transmittance, float eta);
  Spectrum eval(const Vec3&, const Vec3&, const BSDFContext&) const override { return Spectrum(0.0f); }
  float pdf(const Vec3&, const Vec3&, const BSDFContext&) const override { return 0.0f; }
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  bool specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const override {
    return scatter(wo, c, 0.0f, lobe, s);
  }
  const char* name() const override { return "thin dielectric"; }
  // Schlick's reflectance at cosθ.
  float reflectance(float cosTheta) const;

 private:
  // sample() with lobe = kSpecular (reflection with probability P), or the one lobe asked for.
  bool scatter(const Vec3& wo, const BSDFContext& c, float uc, BSDFFlags lobe, BSDFSample* s) const;
  ColorTexture transmittance_;
  float F0_;
};

}  // namespace pl
