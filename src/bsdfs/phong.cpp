#include "bsdfs/phong.h"

#include "core/frame.h"
#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

Phong::Phong(const Spectrum& kd, const Spectrum& ks, float exponent) : kd_(kd), ks_(ks), n_(exponent) {
  float d = average(kd), sp = average(ks);
  diffuseProbability_ = d + sp > 0 ? d / (d + sp) : 1.0f;
}

static float cosAlpha(const Vec3& wo, const Vec3& wi) {
  return glm::dot(reflect(wo, Vec3(0, 0, 1)), wi);
}

Spectrum Phong::eval(const Vec3& wo, const Vec3& wi, const BSDFContext&) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return Spectrum(0.0f);
  float ca = cosAlpha(o, i);
  float lobe = ca > 0 ? (n_ + 2) * kInv2Pi * std::pow(ca, n_) : 0.0f;
  return kd_ * kInvPi + ks_ * lobe;
}

float Phong::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext&) const {
  Vec3 o = wo, i = wi;
  if (!flipToUpperHemisphere(o, i)) return 0.0f;
  return diffuseProbability_ * pdfCosineHemisphere(i) +
         (1 - diffuseProbability_) * pdfPowerCosine(cosAlpha(o, i), n_);
}

bool Phong::sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const {
  Vec3 o;
  if (!upperHemisphere(wo, &o)) return false;
  Vec3 wi;
  if (uc < diffuseProbability_) {
    wi = sampleCosineHemisphere(u);
  } else {
    Frame lobe(reflect(o, Vec3(0, 0, 1)));
    wi = lobe.toWorld(samplePowerCosine(u, n_));
    if (wi.z <= 0) return false;  // the lobe dips below the horizon: no contribution
  }
  return finishReflectionSample(wo, wi, pdf(o, wi, c), [&] { return eval(o, wi, c); }, s);
}

}  // namespace pl
