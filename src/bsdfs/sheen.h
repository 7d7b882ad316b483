#pragma once
#include "bsdfs/layered.h"
#include "image/texture.h"

namespace pl {

// KHR_materials_sheen: back-scattering fibres (cloth, velvet) as a layer over the material
// (bsdfs/layered.h), the specification's "Charlie" lobe (Estevez and Kulla 2017) with
// Ashikhmin's visibility (Neubelt and Pettineo 2013), α = sheenRoughness²:
//   D(m) = (2 + 1/α) sin^(1/α)θm / (2π),   V = 1 / (4 (cosθi + cosθo − cosθi cosθo)),
//   f_sheen = sheenColor · D(m) V / max(1, E(μo), E(μi)).
// E(μ) = ∫ D V cosθi dωi, tabulated once over (μ, roughness): near grazing and for small α the
// unscaled lobe reflects more than it receives (E > 1), and dividing by the larger of the two
// directions' E (never by less than 1) bounds the albedo by 1 while keeping f symmetric.
// Its albedo is then at most max(sheenColor) · min(1, E(μ)). Sampled by the cosine lobe.
class Sheen final : public BSDFLayer {
 public:
  // color: sheenColorFactor × sheenColorTexture (sRGB); roughness: sheenRoughnessFactor ×
  // sheenRoughnessTexture's alpha channel.
  Sheen(ColorTexture color, AlphaTexture roughness) : color_(std::move(color)), roughness_(std::move(roughness)) {}
  Spectrum eval(const Vec3& o, const Vec3& i, const BSDFContext& c) const override;
  float pdf(const Vec3& o, const Vec3& i, const BSDFContext& c) const override;
  Vec3 sample(const Vec3& o, const BSDFContext& c, const Vec2& u) const override;
  float albedo(float mu, const BSDFContext& c) const override;
  const char* name() const override { return "sheen"; }

  // The unscaled lobe's directional albedo E(μ) at a roughness, from the table (for tests).
  static float lobeAlbedo(float cosTheta, float roughness);
  // The Charlie distribution's narrowest α (sheenRoughness 0.07, as Filament clamps it): below
  // it sin^(1/α) underflows over most of the sphere.
  static constexpr float kMinAlpha = 0.07f * 0.07f;

 private:
  float roughness(const Vec2& uv) const;
  ColorTexture color_;
  AlphaTexture roughness_;
};

}  // namespace pl
