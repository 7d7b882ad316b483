#include "lights/area_light.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

AreaLight::AreaLight(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Spectrum& Le, bool twoSided)
    : p0_(p0), p1_(p1), p2_(p2), Le_(Le), twoSided_(twoSided) {
  Vec3 c = glm::cross(p1 - p0, p2 - p0);
  float len = glm::length(c);
  area_ = 0.5f * len;
  frame_ = Frame(len > 0 ? c / len : Vec3(0, 0, 1));
}

bool AreaLight::sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const {
  if (area_ <= 0) return false;
  Vec2 b = sampleUniformTriangle(u);
  Vec3 y = b.x * p0_ + b.y * p1_ + (1 - b.x - b.y) * p2_;
  Vec3 d = y - p;
  float r2 = glm::dot(d, d);
  if (r2 <= 0) return false;
  s->distance = std::sqrt(r2);
  s->wi = d / s->distance;
  float cosLight = glm::dot(frame_.n, -s->wi);
  s->Li = L(-s->wi, lambda);
  if (cosLight == 0 || isBlack(s->Li)) return false;
  s->pdf = r2 / (area_ * std::abs(cosLight));
  return true;
}

float AreaLight::pdfLi(const Vec3& p, const Vec3& y) const {
  Vec3 d = y - p;
  float r2 = glm::dot(d, d);
  float cosLight = std::abs(glm::dot(frame_.n, d)) / std::sqrt(r2);
  return cosLight > 0 && area_ > 0 ? r2 / (area_ * cosLight) : 0.0f;
}

EmittedRay AreaLight::sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const {
  Vec2 b = sampleUniformTriangle(uPosition);
  Vec3 y = b.x * p0_ + b.y * p1_ + (1 - b.x - b.y) * p2_;
  Vec2 u = uDirection;
  bool back = false;
  float sides = 1.0f;
  if (twoSided_) {  // pick a face with probability 1/2, reusing the sample (branch-free: a coin flip)
    sides = 2.0f;
    back = u.x >= 0.5f;
    u.x = std::min(2.0f * u.x - select(back, 1.0f, 0.0f), 0.99999994f);
  }
  Vec3 local = sampleCosineHemisphere(u);  // cosine-weighted around n, or around −n for the back face
  local.z = negateIf(back, local.z);
  Vec3 dir = frame_.toWorld(local);
  // flux = Le cosθ / (pdf_A · pdf_ω) = Le cosθ · A · π / cosθ (× 2 faces) = Φ.
  EmittedRay e{Ray{y, dir}, emit(Le_, lambda) * (kPi * area_ * sides)};
  e.n = frame_.n;
  e.pdfPos = 1.0f / area_;
  e.pdfDir = std::abs(local.z) * kInvPi / sides;
  return e;
}

void AreaLight::pdfLe(const Ray& ray, const Vec3&, float* pdfPos, float* pdfDir) const {
  float c = glm::dot(frame_.n, ray.d);
  bool emits = c > 0 || (twoSided_ && c < 0);
  *pdfPos = area_ > 0 ? 1.0f / area_ : 0.0f;
  *pdfDir = emits ? std::abs(c) * kInvPi / (twoSided_ ? 2.0f : 1.0f) : 0.0f;
}

}  // namespace pl
