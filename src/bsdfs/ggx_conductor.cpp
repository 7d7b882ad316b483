#include "bsdfs/ggx_conductor.h"

#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

float GGXConductor::D(const Vec3& m) const {
  if (m.z <= 0) return 0.0f;
  float a2 = alpha_ * alpha_;
  float d = m.z * m.z * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

float GGXConductor::G1(const Vec3& v) const {
  float cos2 = v.z * v.z;
  if (cos2 <= 0) return 0.0f;
  float tan2 = std::max(0.0f, 1.0f - cos2) / cos2;
  return 2.0f / (1.0f + std::sqrt(1.0f + alpha_ * alpha_ * tan2));
}

Spectrum GGXConductor::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return Spectrum(0.0f);
  Vec3 m = glm::normalize(o + i);
  Spectrum F = fresnelSchlick(F0_.eval(c.uv, *c.lambda), glm::dot(o, m));
  return F * (D(m) * G1(o) * G1(i) / (4.0f * o.z * i.z));
}

float GGXConductor::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext&) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return 0.0f;
  Vec3 m = glm::normalize(o + i);
  // pdf_m = D(m) cosθm, and the reflection Jacobian dωm/dωi = 1 / (4 |wo·m|).
  return D(m) * m.z / (4.0f * std::abs(glm::dot(o, m)));
}

bool GGXConductor::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float, BSDFSample* s) const {
  Vec3 o = wo;
  if (o.z == 0) return false;
  if (o.z < 0) o.z = -o.z;
  // Invert the CDF of D(m) cosθm: tan²θm = α² u / (1 − u).
  float tan2 = alpha_ * alpha_ * u.x / (1.0f - u.x);
  float cosThetaM = 1.0f / std::sqrt(1.0f + tan2);
  float sinThetaM = std::sqrt(std::max(0.0f, 1.0f - cosThetaM * cosThetaM));
  Vec2 sc = sinCos2Pi(u.y);
  Vec3 m(sinThetaM * sc.y, sinThetaM * sc.x, cosThetaM);
  Vec3 wi = reflect(o, m);
  if (wi.z <= 0) return false;
  s->pdf = pdf(o, wi, c);
  if (s->pdf <= 0) return false;
  s->weight = eval(o, wi, c) * wi.z / s->pdf;
  if (wo.z < 0) wi.z = -wi.z;
  s->wi = wi;
  s->delta = false;
  return true;
}

}  // namespace pl
