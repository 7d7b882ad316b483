#pragma once
#include "lights/light.h"

namespace pl {

// KHR_lights_punctual spot light: I(θ) = I·a(cosθ)², a = clamp((cosθ − cosθo)/(cosθi − cosθo), 0, 1)
// (the spec's reference falloff, smooth between the inner and outer cone angles).
// Power Φ = I·2π[(1 − cosθi) + (cosθi − cosθo)/3].
class SpotLight final : public Light {
 public:
  SpotLight(const Vec3& position, const Vec3& direction, const Spectrum& intensity, float innerAngle,
            float outerAngle);
  // The intensity I that makes the total flux Φ.
  static Spectrum intensityForPower(const Spectrum& power, float innerAngle, float outerAngle);
  static float solidAngleFactor(float cosInner, float cosOuter);
  float falloff(float cosTheta) const;
  Spectrum power() const override;
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  const char* name() const override { return "spot"; }

 private:
  Vec3 position_, direction_;
  Spectrum I_;
  float cosInner_, cosOuter_;
};

}  // namespace pl
