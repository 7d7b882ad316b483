#pragma once
#include "bsdfs/bsdf.h"

namespace pl {

// Smooth dielectric interface (glass, water): reflects with the exact Fresnel probability F and
// refracts by Snell's law with 1 − F; total internal reflection past the critical angle.
// The shading normal points to the outside medium (index 1); eta = η_inside/η_outside.
class Dielectric final : public BSDF {
 public:
  explicit Dielectric(float eta) : eta_(eta) {}
  Spectrum eval(const Vec3&, const Vec3&, const Vec2&) const override { return Spectrum(0.0f); }
  float pdf(const Vec3&, const Vec3&, const Vec2&) const override { return 0.0f; }
  bool sample(const Vec3& wo, const Vec2& uv, const Vec2& u, float uc, TransportMode mode,
              BSDFSample* s) const override;
  bool isDelta() const override { return true; }
  const char* name() const override { return "dielectric"; }
  float eta() const { return eta_; }

 private:
  float eta_;
};

}  // namespace pl
