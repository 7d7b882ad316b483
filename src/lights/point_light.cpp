#include "lights/point_light.h"

#include "core/sampling.h"

namespace pl {

bool PointLight::sampleLi(const Vec3& p, const Vec2&, const SampledWavelengths& lambda, LightSample* s) const {
  Vec3 d = position_ - p;
  float r2 = glm::dot(d, d);
  if (r2 <= 0) return false;
  s->distance = std::sqrt(r2);
  s->wi = d / s->distance;
  s->Li = emit(I_, lambda) / r2;  // inverse-square law
  s->pdf = 1.0f;
  return true;
}

EmittedRay PointLight::sampleLe(const Vec2&, const Vec2& u, const SampledWavelengths& lambda) const {
  // Uniform directions, pdf 1/4π: flux = I / pdf = 4πI = Φ for every photon.
  EmittedRay e{Ray{position_, sampleUniformSphere(u)}, 4.0f * kPi * emit(I_, lambda)};
  e.pdfDir = kInv4Pi;
  return e;
}

void PointLight::pdfLe(const Ray&, const Vec3&, float* pdfPos, float* pdfDir) const {
  *pdfPos = 1.0f;
  *pdfDir = kInv4Pi;
}

}  // namespace pl
