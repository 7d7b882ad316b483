#pragma once
#include "bsdfs/ggx.h"
#include "bsdfs/layered.h"
#include "image/texture.h"

namespace pl {

// KHR_materials_clearcoat's coat: a clear dielectric layer (η = 1.5, F0 = 0.04) with its own
// GGX roughness, over the material (bsdfs/layered.h):
//   f_coat = weight · F_Schlick(0.04, wo·m) D(m) G1(wo) G1(wi) / (4 cosθo cosθi),
// α = roughness². Its albedo is weight · E(μ), the directional albedo of the metallic-roughness
// dielectric lobe, which is the same lobe (MetallicRoughness::specularAlbedo). Sampled by D(m) cosθm.
// The coat shares the material's shading normal (clearcoatNormalTexture is not read).
class Clearcoat final : public BSDFLayer {
 public:
  // weight: clearcoatFactor × clearcoatTexture's R; roughness: clearcoatRoughnessFactor ×
  // clearcoatRoughnessTexture's G (both linear), in those channels of the two textures.
  Clearcoat(ColorTexture weight, ColorTexture roughness) : weight_(std::move(weight)), roughness_(std::move(roughness)) {}
  Spectrum eval(const Vec3& o, const Vec3& i, const BSDFContext& c) const override;
  float pdf(const Vec3& o, const Vec3& i, const BSDFContext& c) const override;
  Vec3 sample(const Vec3& o, const BSDFContext& c, const Vec2& u) const override;
  float albedo(float mu, const BSDFContext& c) const override;
  const char* name() const override { return "clearcoat"; }

 private:
  struct Point {
    float weight, roughness;
    GGX ggx;
  };
  Point at(const Vec2& uv) const;
  ColorTexture weight_, roughness_;
};

}  // namespace pl
