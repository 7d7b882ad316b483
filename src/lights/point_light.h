#pragma once
#include "lights/light.h"

namespace pl {

// Isotropic point light: radiant intensity I (W/sr), power Φ = 4πI, E = I cosθ / r².
class PointLight final : public Light {
 public:
  PointLight(const Vec3& position, const Spectrum& intensity) : Light(LightType::kDeltaPosition), position_(position), I_(intensity) {}
  static Spectrum intensityForPower(const Spectrum& power) { return power * kInv4Pi; }
  Spectrum power() const override { return 4.0f * kPi * I_; }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  const char* name() const override { return "point"; }

 private:
  Vec3 position_;
  Spectrum I_;
};

}  // namespace pl
