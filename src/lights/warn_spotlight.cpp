#include "lights/warn_spotlight.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

bool WarnSpotlight::sampleLi(const Vec3& p, const Vec2&, LightSample* s) const {
  Vec3 d = position_ - p;
  float r2 = glm::dot(d, d);
  if (r2 <= 0) return false;
  s->distance = std::sqrt(r2);
  s->wi = d / s->distance;
  s->Li = emit(intensity(glm::dot(-s->wi, direction_))) / r2;
  s->pdf = 1.0f;
  return !isBlack(s->Li);
}

EmittedRay WarnSpotlight::sampleLe(const Vec2&, const Vec2& u) const {
  // Importance-sample the lobe exactly: pdf = (s+1)/(2π) cosˢθ, so flux = c cosˢθ / pdf = Φ.
  Vec3 local = samplePowerCosine(u, s_);
  Vec3 dir = Frame(direction_).toWorld(local);
  return {Ray{position_, dir}, emit(power())};
}

}  // namespace pl
