#include "bsdfs/phong.h"

#include "core/frame.h"
#include "core/sampling.h"
#include "optics/optics.h"

namespace pl {

Phong::Phong(const Spectrum& kd, const Spectrum& ks, float exponent)
    : BSDF(kDiffuseReflection | kGlossyReflection), kd_(kd), ks_(ks), n_(exponent) {
  float d = average(kd), sp = average(ks);
  diffuseProbability_ = d + sp > 0 ? d / (d + sp) : 1.0f;
}

static float cosAlpha(const Vec3& wo, const Vec3& wi) {
  return glm::dot(reflect(wo, Vec3(0, 0, 1)), wi);
}

Spectrum Phong::eval(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const { return evaluate(wo, wi, c, false).f; }

float Phong::pdf(const Vec3& wo, const Vec3& wi, const BSDFContext& c) const { return evaluate(wo, wi, c, false).pdf; }

BSDFEval Phong::evaluate(const Vec3& wo, const Vec3& wi, const BSDFContext&, bool reverse) const {
  // f = kd/π + ks (n+2)/(2π) cosⁿα (modified Phong, energy-normalised), sampled as the diffuse
  // lobe (cosine) or the specular one ((n+1)/(2π) cosⁿα) in proportion to mean kd and ks. f and
  // both densities share cosⁿα, and cos α is symmetric in wo and wi (the reflection about z only
  // negates x and y): one powf for all three.
  Vec3 o = wo, i = wi;
  BSDFEval e;
  if (!flipToUpperHemisphere(o, i)) return e;
  const float ca = cosAlpha(o, i);
  const float power = ca > 0 ? std::pow(ca, n_) : 0.0f;
  const float lobe = ca > 0 ? (n_ + 2) * kInv2Pi * power : 0.0f;
  const float lobePdf = ca > 0 ? (n_ + 1.0f) * kInv2Pi * power : 0.0f;  // pdfPowerCosine
  e.f = kd_ * kInvPi + ks_ * lobe;
  e.pdf = diffuseProbability_ * pdfCosineHemisphere(i) + (1 - diffuseProbability_) * lobePdf;
  if (reverse) e.pdfReverse = diffuseProbability_ * pdfCosineHemisphere(o) + (1 - diffuseProbability_) * lobePdf;
  return e;
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
  const BSDFEval e = evaluate(o, wi, c, false);
  return finishReflectionSample(wo, wi, e.pdf, [&] { return e.f; }, s);
}

}  // namespace pl
