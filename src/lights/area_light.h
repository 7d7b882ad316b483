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
  bool sampleLi(const Vec3& p, const Vec2& u, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection) const override;
  bool isDelta() const override { return false; }
  const char* name() const override { return "area"; }

  // Radiance leaving the light in direction w (unit, away from the surface).
  Spectrum L(const Vec3& w) const {
    float c = glm::dot(frame_.n, w);
    return (c > 0 || (twoSided_ && c < 0)) ? emit(Le_) : Spectrum(0.0f);
  }
  // Solid-angle density of sampleLi() choosing the point y seen from p.
  float pdfLi(const Vec3& p, const Vec3& y) const;
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
