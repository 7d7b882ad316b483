#include "lights/area_light.h"

#include "core/frame.h"
#include "core/sampling.h"

namespace pl {

AreaLight::AreaLight(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Spectrum& Le, bool twoSided,
                     std::shared_ptr<const EmissionTexture> texture)
    : Light(LightType::kArea), p0_(p0), p1_(p1), p2_(p2), Le_(Le), texture_(std::move(texture)), twoSided_(twoSided) {
  Vec3 c = glm::cross(p1 - p0, p2 - p0);
  float len = glm::length(c);
  area_ = 0.5f * len;
  frame_ = Frame(len > 0 ? c / len : Vec3(0, 0, 1));
  if (texture_) {
    // The texture's mean over the triangle, for the power (light selection, `info`): the
    // midpoint rule on the n² sub-triangles of an n-fold subdivision, n from the triangle's
    // footprint in texels (two samples per texel across, 2 to 64).
    const Image* image = texture_->texture->image();
    const Vec2 e1 = texture_->uv[1] - texture_->uv[0], e2 = texture_->uv[2] - texture_->uv[0];
    const double texels = 0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x) * (image ? double(image->width) * image->height : 1.0);
    const int n = int(std::clamp(2.0 * std::sqrt(2.0 * texels), 2.0, 64.0));
    glm::dvec3 sum(0.0);
    int count = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        // The upward sub-triangle's centroid, and the downward one's beside it.
        sum += glm::dvec3(texture_->texture->evalRGB(uvAt(Vec2((i + 1.0f / 3) / n, (j + 1.0f / 3) / n)))), ++count;
        if (i + j < n - 1) sum += glm::dvec3(texture_->texture->evalRGB(uvAt(Vec2((i + 2.0f / 3) / n, (j + 2.0f / 3) / n)))), ++count;
      }
    Le_ = Spectrum(sum / double(count));
  }
}

Spectrum AreaLight::L(const Vec3& y, const Vec3& w, const SampledWavelengths& lambda) const {
  if (!texture_) return L(Vec2(0.0f), w, lambda);
  // y's barycentrics (b0, b1) by the areas of the sub-triangles opposite p0 and p1.
  const Vec3 c = glm::cross(p1_ - p0_, p2_ - p0_);
  const float inv = 1.0f / glm::dot(c, c);
  const float b0 = glm::dot(glm::cross(p1_ - y, p2_ - y), c) * inv;
  const float b1 = glm::dot(glm::cross(p2_ - y, p0_ - y), c) * inv;
  return L(uvAt(Vec2(b0, b1)), w, lambda);
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
  s->Li = L(uvAt(b), -s->wi, lambda);
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
  EmittedRay e{Ray{y, dir}, radiance(uvAt(b), lambda) * (kPi * area_ * sides)};
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
