#pragma once
#include <memory>

#include "core/frame.h"
#include "lights/light.h"
#include "image/texture.h"

namespace pl {

// An emissive texture over one triangle (glTF emissiveTexture × emissiveFactor): radiance
// Le(uv), the texture coordinates at the triangle's corners.
struct EmissionTexture {
  std::shared_ptr<const ColorTexture> texture;
  Vec2 uv[3];
};

// Diffuse emitter on one triangle: radiance Le from its front face (counter-clockwise winding),
// or both faces when two-sided; Le constant, or read from an emissive texture at each point.
// Power Φ = π·∫Le dA per emitting face (π·Le·A for a constant one; for a texture, π·A times its
// mean over the triangle, by quadrature: meanRadiance()). Sampled uniformly by area, converted
// to solid angle with pdf_ω = r² / (A |cosθ_light|); a textured light's photons and shadow rays
// carry the texel's Le at the point they draw, so the estimate is exact whatever the quadrature.
class AreaLight final : public Light {
 public:
  AreaLight(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Spectrum& Le, bool twoSided,
            std::shared_ptr<const EmissionTexture> texture = nullptr);
  Spectrum power() const override { return kPi * Le_ * area_ * (twoSided_ ? 2.0f : 1.0f); }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  const char* name() const override { return "area"; }

  // Radiance leaving the light in direction w (unit, away from the surface) at the point whose
  // texture coordinates are uv (a hit's: SurfaceHit::uv; unused without a texture).
  Spectrum L(const Vec2& uv, const Vec3& w, const SampledWavelengths& lambda) const {
    float c = glm::dot(frame_.n, w);
    return (c > 0 || (twoSided_ && c < 0)) ? radiance(uv, lambda) : Spectrum(0.0f);
  }
  // The same at the light's point y.
  Spectrum L(const Vec3& y, const Vec3& w, const SampledWavelengths& lambda) const override;
  // Le at texture coordinates uv, whatever the direction.
  Spectrum radiance(const Vec2& uv, const SampledWavelengths& lambda) const {
    if (!texture_) return emit(Le_, lambda);
    Spectrum rgb = texture_->texture->evalRGB(uv);
    return lambda.spectral ? spectralEmission(rgb, lambda) : rgb;
  }
  // Le averaged over the triangle: the constant one, or a textured one's by quadrature.
  const Spectrum& meanRadiance() const { return Le_; }
  bool textured() const { return texture_ != nullptr; }
  // Solid-angle density of sampleLi() choosing the point y seen from p.
  float pdfLi(const Vec3& p, const Vec3& y) const override;
  // Uniform by area (1/A), cosine-weighted around the emitting face's normal (|cosθ|/π, halved
  // for each face of a two-sided light).
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  float area() const { return area_; }
  const Vec3& normal() const { return frame_.n; }
  // Its corners (y = b0 p0 + b1 p1 + (1 − b0 − b1) p2 in sampleLi) and whether both faces emit.
  const Vec3& corner(int i) const { return i == 0 ? p0_ : i == 1 ? p1_ : p2_; }
  bool twoSided() const { return twoSided_; }

 private:
  // Texture coordinates at barycentrics (b0, b1) (y = b0 p0 + b1 p1 + (1 − b0 − b1) p2).
  Vec2 uvAt(const Vec2& b) const {
    return texture_ ? b.x * texture_->uv[0] + b.y * texture_->uv[1] + (1 - b.x - b.y) * texture_->uv[2] : Vec2(0.0f);
  }
  Vec3 p0_, p1_, p2_;
  Frame frame_;  // around the unit normal frame_.n (counter-clockwise side), for emitted directions
  Spectrum Le_;  // the constant radiance, or the texture's mean over the triangle
  std::shared_ptr<const EmissionTexture> texture_;
  float area_;
  bool twoSided_;
};

}  // namespace pl
