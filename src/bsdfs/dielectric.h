#pragma once
#include "bsdfs/bsdf.h"

namespace pl {

// Smooth dielectric interface (glass, water): reflects with the exact Fresnel probability F and
// refracts by Snell's law with 1 − F; total internal reflection past the critical angle.
// The shading normal points to the outside medium (index 1); eta = η_inside/η_outside.
//
// Dispersion (KHR_materials_dispersion, dispersion = 20/V_d): with an Abbe number V_d the index
// follows Cauchy's n(λ) = A + B/λ², fitted to n(λ_d) = eta at the d line (587.56 nm) and
// V_d = (n_d − 1)/(n_F − n_C) with the F (486.13 nm) and C (656.27 nm) lines. It acts in spectral
// mode only: the path keeps its hero wavelength (spectral/spectral.h); in RGB mode n = eta.
class Dielectric final : public BSDF {
 public:
  explicit Dielectric(float eta, float abbe = 0.0f);
  Spectrum eval(const Vec3&, const Vec3&, const BSDFContext&) const override { return Spectrum(0.0f); }
  float pdf(const Vec3&, const Vec3&, const BSDFContext&) const override { return 0.0f; }
  bool sample(const Vec3& wo, const BSDFContext& c, const Vec2& u, float uc, BSDFSample* s) const override;
  bool specularLobe(const Vec3& wo, const BSDFContext& c, BSDFFlags lobe, BSDFSample* s) const override {
    return scatter(wo, c, 0.0f, lobe, s);
  }
  const char* name() const override { return "dielectric"; }
  float eta() const { return eta_; }
  float abbe() const { return abbe_; }
  float eta(float lambdaNm) const { return cauchyB_ == 0.0f ? eta_ : cauchyA_ + cauchyB_ / (lambdaNm * lambdaNm); }

 private:
  // sample() with lobe = kSpecular (reflection with probability F), or the one lobe asked for.
  bool scatter(const Vec3& wo, const BSDFContext& c, float uc, BSDFFlags lobe, BSDFSample* s) const;
  float eta_, abbe_;
  float cauchyA_ = 0.0f, cauchyB_ = 0.0f;  // n(λ) = A + B/λ², λ in nm
};

}  // namespace pl
