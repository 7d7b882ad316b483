#pragma once
#include "lights/light.h"

namespace pl {

// Warn spotlight (Warn 1983): I(θ) = c·cosˢθ for θ < 90°, with c = (s+1)Φ/2π so that
// ∫ I dω = c·2π/(s+1) = Φ. The cosˢ lobe is its falloff; cone angles are not used.
class WarnSpotlight final : public Light {
 public:
  WarnSpotlight(const Vec3& position, const Vec3& direction, const Spectrum& c, float exponent)
      : Light(LightType::kDeltaPosition), position_(position), direction_(glm::normalize(direction)), c_(c), s_(exponent) {}
  static Spectrum cForPower(const Spectrum& power, float exponent) {
    return (exponent + 1.0f) * power * kInv2Pi;
  }
  Spectrum intensity(float cosTheta) const { return cosTheta > 0 ? c_ * std::pow(cosTheta, s_) : Spectrum(0.0f); }
  Spectrum power() const override { return c_ * (2.0f * kPi / (s_ + 1.0f)); }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  const char* name() const override { return "warn"; }
  // sampleLe()'s density of a direction at angle θ from the axis: (s+1)/(2π) cosˢθ.
  float directionPdf(float cosTheta) const;

 private:
  Vec3 position_, direction_;
  Spectrum c_;
  float s_;
};

}  // namespace pl
