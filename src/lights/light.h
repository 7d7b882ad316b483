// The light interface. Every light knows its power Φ (W, per RGB channel), can sample a
// direction towards a shading point (next-event estimation) and can sample an emitted ray whose
// flux has expectation Φ (photon tracing, light tracing), with the densities of both so that
// bidirectional methods can weigh one strategy against another.
#pragma once
#include "core/common.h"
#include "spectral/spectral.h"

namespace pl {

struct LightSample {
  Vec3 wi;                    // unit, from the shading point towards the light
  float distance = INFINITY;  // to the sampled light point; INFINITY for directional lights
  // Incident radiance for area lights; I(−wi)/r² (or E) for delta lights, so that the estimate
  // of the reflected radiance is always f·Li·|cosθ|/pdf.
  Spectrum Li;
  float pdf = 0.0f;  // solid angle for area lights, 1 for delta lights
};

// One photon leaving the light: E[flux] = Φ over the light's sampling.
struct EmittedRay {
  Ray ray;
  Spectrum flux;        // Le·|cosθ| / (pdfPos·pdfDir) (I/pdfDir, E/pdfPos for delta lights)
  Vec3 n{0.0f};         // surface normal at the origin (area lights; 0 for the others)
  float pdfPos = 1.0f;  // area density of the origin; 1 for a delta position
  float pdfDir = 1.0f;  // solid-angle density of the direction; 1 for a delta direction
};

// What kind of emitter a light is (pbrt-v4's LightType): integrators ask this, never the class.
enum class LightType : uint8_t {
  kDeltaPosition,   // at one point (point and spot lights): no ray finds it
  kDeltaDirection,  // from one direction (directional light): no ray finds it
  kArea,            // an emitting surface: rays hit it, next-event estimation samples it
  kInfinite,        // the environment: at infinity in every direction, found by rays that leave the scene
};

class Light {
 public:
  explicit Light(LightType type) : type_(type) {}
  virtual ~Light() = default;
  // Colour temperature in kelvin (glTF extras.photonlab.temperature), 0 = none. The loader sets
  // the RGB colour to the blackbody's; in spectral mode emit() uses Planck's law itself.
  float temperature = 0.0f;
  // The equal-energy illuminant E instead of D65 as the light's spectrum (extras.photonlab.illuminant = "E").
  bool equalEnergy = false;
  virtual Spectrum power() const = 0;
  virtual bool sampleLi(const Vec3& p, const Vec2& u, const SampledWavelengths& lambda, LightSample* s) const = 0;
  virtual EmittedRay sampleLe(const Vec2& uPosition, const Vec2& uDirection, const SampledWavelengths& lambda) const = 0;
  // Solid-angle density, seen from p, of sampleLi() choosing the light point y; 0 for delta
  // lights (no ray finds them).
  virtual float pdfLi(const Vec3& p, const Vec3& y) const { return 0.0f; }
  // The densities with which sampleLe() would emit `ray` from its origin (normal n there).
  virtual void pdfLe(const Ray& ray, const Vec3& n, float* pdfPos, float* pdfDir) const = 0;
  // Radiance leaving the light's point y in direction w (unit); 0 for delta lights.
  virtual Spectrum L(const Vec3& y, const Vec3& w, const SampledWavelengths& lambda) const { return Spectrum(0.0f); }
  LightType type() const { return type_; }
  bool isDeltaPosition() const { return type_ == LightType::kDeltaPosition; }
  bool isDeltaDirection() const { return type_ == LightType::kDeltaDirection; }
  bool isDelta() const { return isDeltaPosition() || isDeltaDirection(); }
  // The environment emits through the scene's bounding disc (lights/environment_light.h).
  bool isInfinite() const { return type_ == LightType::kInfinite; }
  // Lights that need the scene's extent (directional) are told it once loading is done.
  virtual void preprocess(const Vec3& sceneCenter, float sceneRadius) {}
  virtual const char* name() const = 0;

 protected:
  // Emission as the path needs it: the RGB value, or in spectral mode (spectral/spectral.h) the
  // values at the path's wavelengths. Every light passes one fixed colour times a scalar
  // (I·c, Le·c, ...), so its spectrum per unit of that scalar is tabulated once: per unit of
  // luminance for the fixed shapes (blackbody, E), per unit of the largest component otherwise.
  PL_HOT_INLINE Spectrum emit(const Spectrum& rgb, const SampledWavelengths& lambda) const {
    return lambda.spectral ? emitSpectral(rgb, lambda) : rgb;
  }

 private:
  LightType type_;
  Spectrum emitSpectral(const Spectrum& rgb, const SampledWavelengths& lambda) const {
    float scale = temperature > 0 || equalEnergy ? luminance(rgb) : maxComponent(rgb);
    if (!(scale > 0.0f)) return Spectrum(0.0f);
    const auto& table = emission_.get([&](LazySpectrum::Table& t) {
      if (temperature > 0) blackbodyTable(temperature, &t);
      else if (equalEnergy) equalEnergyTable(&t);
      else emissionTable(rgb / scale, &t);
    });
    return scale * LazySpectrum::at(table, lambda.lambda);
  }
  LazySpectrum emission_;
};

}  // namespace pl
