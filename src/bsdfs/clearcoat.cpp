#include "bsdfs/clearcoat.h"

#include <algorithm>

#include "bsdfs/metallic_roughness.h"
#include "optics/optics.h"

namespace pl {

Clearcoat::Point Clearcoat::at(const Vec2& uv) const {
  const float weight = std::clamp(weight_.evalRGB(uv).r, 0.0f, 1.0f);
  const float roughness = std::clamp(roughness_.evalRGB(uv).g, 0.0f, 1.0f);
  return {weight, roughness, GGX{std::max(roughness * roughness, MetallicRoughness::kMinAlpha)}};
}

Spectrum Clearcoat::eval(const Vec3& o, const Vec3& i, const BSDFContext& c) const {
  const Point p = at(c.uv);
  if (p.weight <= 0) return Spectrum(0.0f);
  const Vec3 m = glm::normalize(o + i);
  const float microfacet = p.ggx.D(m) * p.ggx.G1(o) * p.ggx.G1(i) / (4.0f * o.z * i.z);
  return Spectrum(p.weight * fresnelSchlick(kDielectricF0, glm::dot(o, m)) * microfacet);
}

float Clearcoat::pdf(const Vec3& o, const Vec3& i, const BSDFContext& c) const { return at(c.uv).ggx.pdfReflection(o, i); }

Vec3 Clearcoat::sample(const Vec3& o, const BSDFContext& c, const Vec2& u) const { return reflect(o, at(c.uv).ggx.sampleNormal(u)); }

float Clearcoat::albedo(float mu, const BSDFContext& c) const {
  const Point p = at(c.uv);
  return p.weight > 0 ? p.weight * MetallicRoughness::specularAlbedo(mu, p.roughness) : 0.0f;
}

}  // namespace pl
