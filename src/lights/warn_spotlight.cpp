#include "lights/warn_spotlight.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

bool WarnSpotlight::sampleLi(const Vec3& p, const Vec2&, const SampledWavelengths& lambda, LightSample* s) const {
  Vec3 d = position_ - p;
  float r2 = glm::dot(d, d);
  if (r2 <= 0) return false;
  s->distance = std::sqrt(r2);
  s->wi = d / s->distance;
  s->Li = emit(intensity(glm::dot(-s->wi, direction_)), lambda) / r2;
  s->pdf = 1.0f;
  return !isBlack(s->Li);
}

EmittedRay WarnSpotlight::sampleLe(const Vec2&, const Vec2& u, const SampledWavelengths& lambda) const {
  // Importance-sample the lobe exactly: pdf = (s+1)/(2π) cosˢθ, so flux = c cosˢθ / pdf = Φ.
  Vec3 local = samplePowerCosine(u, s_);
  Vec3 dir = Frame(direction_).toWorld(local);
  EmittedRay e{Ray{position_, dir}, emit(power(), lambda)};
  e.pdfDir = directionPdf(local.z);
  return e;
}

float WarnSpotlight::directionPdf(float cosTheta) const {
  return cosTheta > 0 ? (s_ + 1.0f) * kInv2Pi * std::pow(cosTheta, s_) : 0.0f;
}

void WarnSpotlight::pdfLe(const Ray& ray, const Vec3&, float* pdfPos, float* pdfDir) const {
  *pdfPos = 1.0f;
  *pdfDir = directionPdf(glm::dot(ray.d, direction_));
}

}  // namespace pl
