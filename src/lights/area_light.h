#pragma once
#include "core/frame.h"
#include "lights/light.h"

namespace pl {

// Diffuse emitter on one triangle: constant radiance Le from its front face (counter-clockwise
// winding), or both faces when two-sided. Power Φ = π·Le·A per emitting face.
// Sampled uniformly by area; converted to solid angle with pdf_ω = r² / (A |cosθ_light|).
class AreaLight final : public Light {
 public:
  AreaLight(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Spectrum& Le, bool twoSided);
  Spectrum power() const override { return kPi * Le_ * area_ * (twoSided_ ? 2.0f : 1.0f); }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  bool isDeltaPosition() const override { return false; }
  const char* name() const override { return "area"; }

  // Radiance leaving the light in direction w (unit, away from the surface), the same at every
  // point.
  Spectrum L(const Vec3& w, const SampledWavelengths& lambda) const {
    float c = glm::dot(frame_.n, w);
    return (c > 0 || (twoSided_ && c < 0)) ? emit(Le_, lambda) : Spectrum(0.0f);
  }
  Spectrum L(const Vec3&, const Vec3& w, const SampledWavelengths& lambda) const override { return L(w, lambda); }
  // Solid-angle density of sampleLi() choosing the point y seen from p.
  float pdfLi(const Vec3& p, const Vec3& y) const override;
  // Uniform by area (1/A), cosine-weighted around the emitting face's normal (|cosθ|/π, halved
  // for each face of a two-sided light).
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  float area() const { return area_; }
  const Vec3& normal() const { return frame_.n; }

 private:
  Vec3 p0_, p1_, p2_;
  Frame frame_;  // around the unit normal frame_.n (counter-clockwise side), for emitted directions
  Spectrum Le_;
  float area_;
  bool twoSided_;
};

}  // namespace pl
