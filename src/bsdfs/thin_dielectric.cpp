#include "bsdfs/thin_dielectric.h"

namespace pl {

ThinDielectric::ThinDielectric(ColorTexture transmittance, float eta)
    : BSDF(kSpecularReflection | kSpecularTransmission), transmittance_(std::move(transmittance)) {
  const float r = (eta - 1) / (eta + 1);
  F0_ = r * r;
}

float ThinDielectric::reflectance(float cosTheta) const {
  float m = std::clamp(1.0f - std::abs(cosTheta), 0.0f, 1.0f);
  return F0_ + (1 - F0_) * (m * m) * (m * m) * m;
}

bool ThinDielectric::sample(const Vec3& wo, const BSDFContext& c, const Vec2&, float uc, BSDFSample* s) const {
  return scatter(wo, c, uc, kSpecular, s);
}

bool ThinDielectric::scatter(const Vec3& wo, const BSDFContext& c, float uc, BSDFFlags lobe, BSDFSample* s) const {
  if (wo.z == 0) return false;
  const float F = reflectance(wo.z);
  const Spectrum T = transmittance_.eval(c.uv, *c.lambda, c.color) * (1 - F);
  const float through = (T.r + T.g + T.b) / 3;
  const float P = F + through > 0 ? F / (F + through) : 1.0f;  // of reflecting
  s->delta = true;
  s->eta = 1.0f;
  const bool reflects = lobe == kSpecular ? uc < P : lobe == kSpecularReflection;
  if (!(reflects ? P > 0 : P < 1)) return false;  // the lobe asked for has probability zero
  if (reflects) {
    s->wi = Vec3(-wo.x, -wo.y, wo.z);
    s->weight = Spectrum(F / P);
    s->pdf = P;
  } else {
    s->wi = -wo;
    s->weight = T / (1 - P);
    s->pdf = 1 - P;
  }
  return true;
}

}  // namespace pl
