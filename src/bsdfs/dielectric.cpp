#include "bsdfs/dielectric.h"

#include "optics/optics.h"
#include "spectral/spectral.h"

namespace pl {

Dielectric::Dielectric(float eta, float abbe)
    : BSDF(kSpecularReflection | kSpecularTransmission, BSDFClass::kDielectric), eta_(eta), abbe_(abbe) {
  if (abbe > 0) {
    const double d = 587.56, F = 486.13, C = 656.27;
    double B = (eta - 1.0) / (abbe * (1.0 / (F * F) - 1.0 / (C * C)));
    cauchyB_ = float(B);
    cauchyA_ = float(eta - B / (d * d));
  }
}

bool Dielectric::sample(const Vec3& wo, const BSDFContext& c, const Vec2&, float uc, BSDFSample* s) const {
  return scatter(wo, c, uc, kSpecular, s);
}

bool Dielectric::scatter(const Vec3& wo, const BSDFContext& c, float uc, BSDFFlags lobe, BSDFSample* s) const {
  if (wo.z == 0) return false;
  float eta = eta_;
  Spectrum heroScale(1.0f);
  const SampledWavelengths& lambda = *c.lambda;
  s->terminatesSecondary = false;
  if (cauchyB_ != 0.0f && lambda.spectral) {
    // The index depends on λ: follow the hero wavelength alone from here on (the caller ends the
    // secondary wavelengths). Its value is scaled by 3, the other two dropped, which keeps the
    // film's estimate unbiased.
    eta = this->eta(lambda.lambda.x);
    if (!lambda.heroOnly) heroScale = Spectrum(3.0f, 0.0f, 0.0f);
    s->terminatesSecondary = true;
  }
  float F = fresnelDielectric(wo.z, eta);
  s->delta = true;
  const bool reflects = lobe == kSpecular ? uc < F : lobe == kSpecularReflection;
  if (reflects && !(F > 0)) return false;
  if (reflects) {
    // Reflection chosen with probability F: weight F/F = 1.
    s->wi = Vec3(-wo.x, -wo.y, wo.z);
    s->weight = heroScale;
    s->pdf = F;
    s->eta = 1.0f;
    return true;
  }
  bool entering = wo.z > 0;
  float etaRel = entering ? eta : 1.0f / eta;  // η_t/η_i
  Vec3 n(0, 0, entering ? 1.0f : -1.0f);
  if (!refract(wo, n, etaRel, &s->wi)) return false;  // cannot happen when F < 1
  // Radiance is compressed by (η_i/η_t)² crossing into the denser medium (pbrt §8.2);
  // flux carried by photons is not.
  float scale = c.mode == TransportMode::Radiance ? 1.0f / (etaRel * etaRel) : 1.0f;
  s->weight = scale * heroScale;
  s->pdf = 1.0f - F;
  s->eta = etaRel;
  return true;
}

}  // namespace pl
