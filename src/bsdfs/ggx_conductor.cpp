#include "bsdfs/ggx_conductor.h"

#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

Spectrum GGXConductor::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return Spectrum(0.0f);
  Vec3 m = glm::normalize(o + i);
  Spectrum F = fresnelSchlick(F0_.eval(c.uv, *c.lambda, c.color), glm::dot(o, m));
  return F * (ggx_.D(m) * ggx_.G1(o) * ggx_.G1(i) / (4.0f * o.z * i.z));
}

float GGXConductor::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext&) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return 0.0f;
  return ggx_.pdfReflection(o, i);
}

bool GGXConductor::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float, BSDFSample* s) const {
  Vec3 o;
  if (!upperHemisphere(wo, &o)) return false;
  Vec3 wi = reflect(o, ggx_.sampleNormal(u));
  if (wi.z <= 0) return false;
  return finishReflectionSample(wo, wi, pdf(o, wi, c), [&] { return eval(o, wi, c); }, s);
}

}  // namespace pl
