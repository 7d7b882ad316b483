// The BSDF interface. All directions are in the local shading frame (z = shading normal) and
// point away from the surface: wo towards the viewer (or where light leaves), wi towards the
// light. eval() is f(wo, wi) without the cosine; sample() returns the Monte Carlo weight
// f·|cosθi|/pdf so that an estimator multiplies by it directly.
#pragma once
#include "core/common.h"

namespace pl {

// Radiance is transported from lights to eye paths, importance (photons' flux) the other way.
// Refraction compresses radiance by 1/η² but not flux, so the two modes differ there.
enum class TransportMode { Radiance, Importance };

struct BSDFSample {
  Vec3 wi;
  Spectrum weight;   // f·|cosθi| / pdf
  float pdf = 0.0f;  // solid angle; for delta lobes the discrete probability of the lobe
  bool delta = false;
};

class BSDF {
 public:
  virtual ~BSDF() = default;
  virtual Spectrum eval(const Vec3& wo, const Vec3& wi, const Vec2& uv) const = 0;
  virtual float pdf(const Vec3& wo, const Vec3& wi, const Vec2& uv) const = 0;
  // u: 2D sample for the direction, uc: 1D sample for choosing a lobe.
  virtual bool sample(const Vec3& wo, const Vec2& uv, const Vec2& u, float uc, TransportMode mode,
                      BSDFSample* s) const = 0;
  // True when every lobe is a Dirac delta (mirror, smooth glass): eval and pdf are zero, only
  // sample() can find the reflected/refracted direction.
  virtual bool isDelta() const { return false; }
  virtual const char* name() const = 0;
  // Set only by Lambertian (a non-virtual tag, as pbrt-v4 tags its BxDFs): lets the photon
  // tracer, where most hits are diffuse, call Lambertian::sample directly and inline it.
  bool isLambertian() const { return lambertian_; }

 protected:
  bool lambertian_ = false;
};

// Reflection-only BSDFs reflect from both sides: evaluate on the side wo is on.
inline bool flipToUpperHemisphere(Vec3& wo, Vec3& wi) {
  if (wo.z < 0) {
    wo.z = -wo.z;
    wi.z = -wi.z;
  }
  return wo.z > 0 && wi.z > 0;
}

}  // namespace pl
