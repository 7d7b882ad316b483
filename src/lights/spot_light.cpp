#include "lights/spot_light.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

SpotLight::SpotLight(const Vec3& position, const Vec3& direction, const Spectrum& intensity, float innerAngle,
                     float outerAngle)
    : Light(LightType::kDeltaPosition), position_(position), direction_(glm::normalize(direction)), I_(intensity),
      cosInner_(std::cos(innerAngle)), cosOuter_(std::cos(outerAngle)) {}

// ∫ a(cosθ)² dω over the sphere, divided by 2π: the flat part (1 − cosθi) plus the quadratic
// ramp ∫_{cosθo}^{cosθi} ((μ − cosθo)/(cosθi − cosθo))² dμ = (cosθi − cosθo)/3.
float SpotLight::solidAngleFactor(float cosInner, float cosOuter) {
  return (1.0f - cosInner) + (cosInner - cosOuter) / 3.0f;
}

Spectrum SpotLight::intensityForPower(const Spectrum& power, float innerAngle, float outerAngle) {
  return power / (2.0f * kPi * solidAngleFactor(std::cos(innerAngle), std::cos(outerAngle)));
}

float SpotLight::falloff(float cosTheta) const {
  // The spec guards the division the same way (max(0.001, ...)).
  float a = (cosTheta - cosOuter_) / std::max(1e-3f, cosInner_ - cosOuter_);
  a = std::clamp(a, 0.0f, 1.0f);
  return a * a;
}

Spectrum SpotLight::power() const { return I_ * (2.0f * kPi * solidAngleFactor(cosInner_, cosOuter_)); }

bool SpotLight::sampleLi(const Vec3& p, const Vec2&, const SampledWavelengths& lambda, LightSample* s) const {
  Vec3 d = position_ - p;
  float r2 = glm::dot(d, d);
  if (r2 <= 0) return false;
  s->distance = std::sqrt(r2);
  s->wi = d / s->distance;
  float a = falloff(glm::dot(-s->wi, direction_));
  if (a <= 0) return false;
  s->Li = emit(I_, lambda) * a / r2;
  s->pdf = 1.0f;
  return true;
}

EmittedRay SpotLight::sampleLe(const Vec2&, const Vec2& u, const SampledWavelengths& lambda) const {
  // Uniform in the outer cone, pdf 1/(2π(1 − cosθo)); flux = I(ω)/pdf.
  Vec3 local = sampleUniformCone(u, cosOuter_);
  float pdf = 1.0f / (2.0f * kPi * (1.0f - cosOuter_));
  Vec3 dir = Frame(direction_).toWorld(local);
  EmittedRay e{Ray{position_, dir}, emit(I_, lambda) * falloff(local.z) / pdf};
  e.pdfDir = pdf;
  return e;
}

void SpotLight::pdfLe(const Ray& ray, const Vec3&, float* pdfPos, float* pdfDir) const {
  *pdfPos = 1.0f;
  *pdfDir = glm::dot(ray.d, direction_) >= cosOuter_ ? 1.0f / (2.0f * kPi * (1.0f - cosOuter_)) : 0.0f;
}

}  // namespace pl
