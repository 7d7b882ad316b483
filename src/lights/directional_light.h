#pragma once
#include "lights/light.h"

namespace pl {

// Distant light: irradiance E (W/m²) on a surface facing it. Its power is what crosses the
// scene's bounding disc, Φ = E·πR² (so `power` in extras sets E = Φ/(πR²)).
class DirectionalLight final : public Light {
 public:
  DirectionalLight(const Vec3& direction, const Spectrum& irradiance, float powerOverride = -1.0f)
      : Light(LightType::kDeltaDirection), direction_(glm::normalize(direction)), E_(irradiance), powerOverride_(powerOverride) {}
  void preprocess(const Vec3& center, float radius) override;
  Spectrum power() const override { return E_ * (kPi * radius_ * radius_); }
  bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const override;
  EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const override;
  void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const override;
  const char* name() const override { return "directional"; }

 private:
  Vec3 direction_;
  Spectrum E_;
  float powerOverride_;
  Vec3 center_{0.0f};
  float radius_ = 1.0f;
};

}  // namespace pl
