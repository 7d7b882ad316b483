#pragma once
#include "bsdfs/bsdf.h"
#include "bsdfs/ggx.h"
#include "image/texture.h"

namespace pl {

// glTF 2.0's metallic-roughness material (specification, Appendix B), made energy conserving:
//   f = (1 − metallic) f_dielectric + metallic f_metal,
//   f_metal      = F_Schlick(baseColor, wo·m) D G / (4 cosθo cosθi),
//   f_dielectric = F_Schlick(0.04, wo·m) D G / (4 cosθo cosθi)
//                + (baseColor/π) (1 − E(cosθo)) (1 − E(cosθi)) / (1 − E_avg),
// GGX D and Smith G with α = roughness² (bsdfs/ggx.h), m = normalize(wo + wi). The
// specification's fresnel_mix weights the diffuse base by 1 − F(wo·m), which reflects more than
// it receives near grazing (albedo up to ≈1.3 for white); here the base is weighted by what the
// specular layer leaves, E(μ) = ∫ f_spec cosθi dωi being that layer's directional albedo
// (Kelemen and Szirmay-Kalos 2001; Kulla and Conty 2017). Then the dielectric's albedo is
// exactly E(μo) + ρ (1 − E(μo)) ≤ 1, and f stays reciprocal. E is tabulated once over (μ,
// roughness) by quadrature and read piecewise linearly; E_avg = 2∫E(μ) μ dμ of that same
// piecewise-linear E, so the normalisation is exact for the table that is read.
//
// Thin-walled transmission (KHR_materials_transmission without a volume): a fraction t of the
// diffuse base is replaced by light that passes through the surface unrefracted, the specular
// layer's lobe mirrored to the other side and weighted by what that layer lets through,
//   f_t(wo, wi) = (1 − metallic) t baseColor (1 − F_Schlick(0.04, wo·m')) D(m') G1(wo) G1(wi') / (4 |cosθo| |cosθi|),
// wi' = wi mirrored through the surface plane, m' = normalize(wo + wi'). Reflection and
// transmission then share one GGX lobe whose F and 1 − F sum to 1: a white thin wall's albedo
// is the F = 1 lobe's, ≤ 1, and f_t is reciprocal (m' is the same both ways round).
//
// Textures: baseColorTexture (sRGB) and metallicRoughnessTexture (linear: G = roughness,
// B = metallic), each times its factor; transmissionTexture's R times transmissionFactor.
// Sampled by one-sample MIS between the GGX lobe (D(m) cosθm), the cosine lobe and the mirrored
// GGX lobe, chosen by their estimated albedos at wo.
class MetallicRoughness final : public BSDF {
 public:
  // metallicRoughness: factor (1, roughness, metallic) × the linear texture, if any;
  // transmission: factor t (in every channel) × the linear texture's R, if any.
  MetallicRoughness(ColorTexture baseColor, ColorTexture metallicRoughness, ColorTexture transmission = ColorTexture(Spectrum(0.0f)))
      : BSDF(transmission.factor().r > 0 ? kDiffuseReflection | kGlossyReflection | kGlossyTransmission
                                           : kDiffuseReflection | kGlossyReflection),
        baseColor_(std::move(baseColor)), metallicRoughness_(std::move(metallicRoughness)), transmission_(std::move(transmission)),
        transmits_(transmission_.factor().r > 0) {}
  Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  const char* name() const override { return transmits_ ? "metallic-roughness, thin-walled transmission" : "metallic-roughness"; }

  // The dielectric specular layer's directional albedo E(μ) at a roughness, and its cosine-
  // weighted mean E_avg (exposed for tests).
  static float specularAlbedo(float cosTheta, float roughness);
  static float specularAlbedoAverage(float roughness);
  // Below this α (roughness 0.03) the lobe is held at this width: sharp but not a delta.
  static constexpr float kMinAlpha = 1e-3f;

 private:
  struct Point {  // the material at one surface point
    GGX ggx;
    float roughness, metallic, transmission;
  };
  Point at(const Vec2& uv) const;
  // f(o, i) at p, o in the upper hemisphere, i in it (reflection) or below (transmission).
  Spectrum f(const Point& p, const Vec3& o, const Vec3& i, const BSDFContext& c) const;
  // The lobes' shares of the sampling at wo: specular reflection, diffuse, transmission.
  struct LobeProbabilities {
    float specular, diffuse, transmission;
  };
  LobeProbabilities lobeProbabilities(const Point& p, const BSDFContext& c, float cosThetaO) const;
  float pdf(const Point& p, const LobeProbabilities& lobes, const Vec3& o, const Vec3& i) const;

  ColorTexture baseColor_, metallicRoughness_, transmission_;
  bool transmits_;
};

}  // namespace pl
