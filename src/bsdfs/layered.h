// A reflecting layer over a base BSDF: glTF's clearcoat and sheen (KHR_materials_clearcoat,
// KHR_materials_sheen), each a BSDFLayer in its own file (bsdfs/clearcoat.h, bsdfs/sheen.h).
#pragma once
#include <memory>
#include <string>

#include "bsdfs/bsdf.h"

namespace pl {

// The layer's own reflection lobe. o (and i) in the shading frame, on the upper side (z > 0).
class BSDFLayer {
 public:
  virtual ~BSDFLayer() = default;
  virtual Spectrum eval(const Vec3& o, const Vec3& i, const BSDFContext& c) const = 0;
  virtual float pdf(const Vec3& o, const Vec3& i, const BSDFContext& c) const = 0;
  // A direction drawn with density pdf(o, ·); below the surface when the draw fails.
  virtual Vec3 sample(const Vec3& o, const BSDFContext& c, const Vec2& u) const = 0;
  // a(μ): a bound, in every channel, on the lobe's directional albedo ∫ f cosθi dωi at cosθo = μ.
  virtual float albedo(float mu, const BSDFContext& c) const = 0;
  virtual const char* name() const = 0;
};

// f(wo, wi) = f_layer(wo, wi) + f_base(wo, wi) · min(1 − a(μo), 1 − a(μi)): the glTF
// specification's albedo scaling (KHR_materials_sheen, §"Albedo-scaling technique"; Kulla and
// Conty 2017), the base seen through what the layer does not reflect. The min is symmetric, so
// f stays reciprocal, and the albedo at wo is at most a(μo) + (1 − a(μo)) × the base's ≤ 1:
// energy conserving when the base is. Light the layer would reflect back into the base is lost
// rather than scattered again: darker than a physical layer (docs: reference/gltf.md).
// Sampled by one-sample MIS: the layer's lobe with probability a(μo), its share of the albedo,
// so both lobes' weights stay near their albedos. A base's delta lobes (a mirror under a coat)
// are scaled the same way, min(1 − a(μo), 1 − a(μi)) at their one direction.
class Layered final : public BSDF {
 public:
  Layered(std::unique_ptr<BSDF> base, std::unique_ptr<BSDFLayer> layer);
  Spectrum eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const override;
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  bool specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const override;
  const char* name() const override { return name_.c_str(); }
  const BSDF& base() const { return *base_; }
  const BSDFLayer& layer() const { return *layer_; }

 private:
  // min(1 − a(μo), 1 − a(μi)), what the base keeps.
  float baseWeight(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const;
  std::unique_ptr<BSDF> base_;
  std::unique_ptr<BSDFLayer> layer_;
  std::string name_;
};

}  // namespace pl
