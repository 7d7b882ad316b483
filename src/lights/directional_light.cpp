#include "lights/directional_light.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

void DirectionalLight::preprocess(const Vec3& center, float radius) {
  center_ = center;
  radius_ = std::max(radius, 1e-6f);
  if (powerOverride_ >= 0) E_ = E_ * (powerOverride_ / (kPi * radius_ * radius_));
  powerOverride_ = -1.0f;
}

bool DirectionalLight::sampleLi(const Vec3&, const Vec2&, const SampledWavelengths& lambda, LightSample* s) const {
  s->wi = -direction_;
  s->distance = INFINITY;
  s->Li = emit(E_, lambda);
  s->pdf = 1.0f;
  return true;
}

EmittedRay DirectionalLight::sampleLe(const Vec2& u, const Vec2&, const SampledWavelengths& lambda) const {
  // Uniform on the disc of radius R facing the light, one radius upstream of the scene.
  Frame frame(direction_);
  Vec2 d = sampleConcentricDisc(u) * radius_;  // a point of the disc, in metres
  Vec3 origin = center_ + frame.s * d.x + frame.t * d.y - direction_ * radius_;
  EmittedRay e{Ray{origin, direction_}, emit(E_, lambda) * (kPi * radius_ * radius_)};
  e.pdfPos = 1.0f / (kPi * radius_ * radius_);
  return e;
}

void DirectionalLight::pdfLe(const Ray&, const Vec3&, float* pdfPos, float* pdfDir) const {
  *pdfPos = 1.0f / (kPi * radius_ * radius_);
  *pdfDir = 1.0f;
}

}  // namespace pl
