#include "bsdfs/lambertian.h"

#include "core/sampling.h"

namespace pl {

Spectrum Lambertian::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return Spectrum(0.0f);
  return albedo_.eval(c.uv, *c.lambda, c.color) * kInvPi;
}

float Lambertian::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return 0.0f;
  return pdfCosineHemisphere(i);
}

BSDFEval Lambertian::evaluate(const Vec3& wo, const Vec3& wi, const BSDFContext& c, bool reverse) const {
  // Both directions on one side (strictly) or nothing, whichever way it is asked; then each
  // density is the cosine of the direction sampled (|z| is the flipped z of eval and pdf).
  Vec3 o = wo, i = wi;
  BSDFEval e;
  if (!flipToUpperHemisphere(o, i)) return e;
  e.f = albedo_.eval(c.uv, *c.lambda, c.color) * kInvPi;
  e.pdf = i.z * kInvPi;
  if (reverse) e.pdfReverse = o.z * kInvPi;
  return e;
}

bool Lambertian::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float, BSDFSample* s) const {
  if (wo.z == 0) return false;
  Vec3 wi = sampleCosineHemisphere(u);
  s->pdf = pdfCosineHemisphere(wi);
  if (s->pdf <= 0) return false;
  if (wo.z < 0) wi.z = -wi.z;
  s->wi = wi;
  s->weight = albedo_.eval(c.uv, *c.lambda, c.color);  // (ρ/π)·cosθ / (cosθ/π)
  s->delta = false;
  return true;
}

}  // namespace pl
